# Ctrl-C during a long render raises KeyboardInterrupt promptly: a real SIGINT from a timer
# thread, while the main thread waits in rvr.render with the GIL released.
import os
import signal
import threading
import time

import pytest

import rvr

# Seconds from the signal to the exception, at most: the module looks at signals every 20 ms.
PROMPT = 0.5


def test_sigint_raises_keyboard_interrupt_promptly():
    # Full mode with many samples on one thread: seconds of work, far more than the delay.
    scene = rvr.Scene("builtin:cornell", width=240, height=180, spp=32)
    sent = []

    def interrupt():
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(0.3, interrupt)
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        rvr.render(scene, "raytrace", mode="full", threads=1)
    raised = time.monotonic()
    timer.join()
    assert sent and raised - sent[0] < PROMPT
    # The module still renders afterwards.
    r = rvr.render(rvr.Scene("builtin:cornell", width=8, height=8), "raytrace", threads=1)
    assert r.color.shape == (8, 8, 3)
