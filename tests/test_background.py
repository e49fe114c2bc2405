"""Background: a function run in a second process (the demo's waveform step runs in one), its value or its error
handed back, the process ended on request."""

import os

import pytest

from sim.runners.background import Background


def _pid_and(value):
    return os.getpid(), value


def _fails():
    raise ValueError("bad frame")


def test_background_returns_its_value_from_another_process():
    pid, value = Background(_pid_and, 7).result()
    assert value == 7 and pid != os.getpid()


def test_background_hands_an_error_back():
    with pytest.raises(RuntimeError, match="ValueError: bad frame"):
        Background(_fails).result()


def test_background_stop_ends_the_process():
    import time
    job = Background(time.sleep, 30)
    job.stop()
    assert not job.proc.is_alive()
