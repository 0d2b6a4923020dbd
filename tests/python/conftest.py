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


@pytest.fixture(scope="session")
def budget_scale():
    """RVR_TEST_BUDGET_SCALE: 4 under the sanitizers, whose frames run several times slower, so
    any wall-time bound a test sets on rendering work is this many times longer there."""
    return float(os.environ.get("RVR_TEST_BUDGET_SCALE", "1"))


@pytest.fixture(scope="session")
def study_budget(budget_scale):
    """The budget in seconds to give a study that must measure some point: `seconds` times
    budget_scale (the command line stops a worker still busy at the budget's end and drops its
    run, and a study in this process starts no step that would end past it)."""

    def budget(seconds):
        return seconds * budget_scale

    return budget
