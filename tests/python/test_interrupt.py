# Ctrl-C during a long render raises KeyboardInterrupt promptly and stops the render: a real
# SIGINT from a timer thread, while the main thread waits in rvr.render with the GIL released.
import os
import signal
import threading
import time

import pytest

import rvr

# Seconds from the signal to the exception, at most, in an optimised build: the module looks at
# signals every 20 ms, and the cancelled tracer stops at the end of the tiles it is drawing, which
# take budget_scale times longer under the sanitizers.
PROMPT = 0.5


def os_threads():
    # Every thread of this process, Python's or not (the render runs on a C++ thread).
    return len(os.listdir("/proc/self/task"))


def os_threads_settled(at_most, seconds=0.2):
    # A joined Python thread (the timer) may take a moment to leave the kernel's list; a render
    # still running would stay in it for seconds.
    end = time.monotonic() + seconds
    while os_threads() > at_most and time.monotonic() < end:
        time.sleep(0.01)
    return os_threads()


def test_sigint_cancels_the_render_and_raises_keyboard_interrupt_promptly(budget_scale):
    # Full mode with many samples on one thread: seconds of work, far more than the delay.
    scene = rvr.Scene("builtin:cornell", width=240, height=180, spp=32)
    # A small render first, so that any thread kept between renders already exists.
    rvr.render(rvr.Scene("builtin:cornell", width=8, height=8), "raytrace", threads=1)
    threads_before = os_threads()
    sent = []

    def interrupt():
        sent.append(time.monotonic())
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(0.3, interrupt)
    timer.start()
    started = time.monotonic()
    with pytest.raises(KeyboardInterrupt):
        rvr.render(scene, "raytrace", mode="full", threads=1)
    raised = time.monotonic()
    timer.join()
    assert sent and raised - sent[0] < PROMPT * budget_scale
    # The render stopped: no render thread is left, in the module's count or the process's.
    assert rvr._running_renders() == 0
    assert os_threads_settled(threads_before) == threads_before
    # And it did stop part way: the same render to its end takes far longer than it ran.
    full_start = time.monotonic()
    rvr.render(scene, "raytrace", mode="full", threads=1)
    assert time.monotonic() - full_start > 2 * (raised - started)
    # The module still renders afterwards.
    r = rvr.render(rvr.Scene("builtin:cornell", width=8, height=8), "raytrace", threads=1)
    assert r.color.shape == (8, 8, 3)
