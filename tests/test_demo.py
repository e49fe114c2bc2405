"""``stereodepth demo``'s own parts (the demo itself runs in tests/test_install.py, small, and in ``make demo``):
its default build, the command it names for the thesis's build, the second process its waveform step runs in."""

import argparse
import os

import pytest

from stereodepth import cmd_demo


def _parse(*argv):
    parser = argparse.ArgumentParser()
    cmd_demo.add_arguments(parser)
    return parser.parse_args(argv)


def test_the_demo_shows_the_ddr2_build_and_names_the_thesis_build():
    assert _parse().memory == "ddr2"
    assert _parse(*cmd_demo.THESIS_COMMAND.split()[4:]).memory == "bram"


def _pid_and(value):
    return os.getpid(), value


def _fails():
    raise ValueError("bad frame")


def test_background_returns_its_value_from_another_process():
    pid, value = cmd_demo.Background(_pid_and, 7).result()
    assert value == 7 and pid != os.getpid()


def test_background_hands_an_error_back():
    with pytest.raises(RuntimeError, match="ValueError: bad frame"):
        cmd_demo.Background(_fails).result()


def test_background_stop_ends_the_process():
    import time
    job = cmd_demo.Background(time.sleep, 30)
    job.stop()
    assert not job.proc.is_alive()
