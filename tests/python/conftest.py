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
def study_budget():
    """The budget in seconds to give a study that must measure some point: `seconds` times
    RVR_TEST_BUDGET_SCALE (4 under the sanitizers, whose frames run several times slower: the
    command line stops a worker still busy at the budget's end and drops its run, and a study in
    this process starts no step that would end past it)."""
    scale = float(os.environ.get("RVR_TEST_BUDGET_SCALE", "1"))

    def budget(seconds):
        return seconds * scale

    return budget
