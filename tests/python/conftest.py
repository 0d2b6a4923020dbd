# What the module's tests share: the rvr program (RVR_BINARY, for the command line's answers to
# hold the module to) and a way to run it. ctest sets RVR_BINARY and PYTHONPATH (build/python).
import os
import subprocess

import pytest


@pytest.fixture(scope="session")
def rvr_binary():
    path = os.environ.get("RVR_BINARY")
    assert path and os.path.exists(path), "RVR_BINARY must name the rvr program"
    return path


@pytest.fixture(scope="session")
def run_cli(rvr_binary):
    def run(*args):
        return subprocess.run([rvr_binary, *args], capture_output=True, text=True, timeout=300)

    return run
