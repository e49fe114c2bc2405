"""``stereodepth demo``'s own parts (the demo itself runs in tests/test_install.py, small, and in ``make demo``):
its default build and the command it names for the thesis's build."""

import argparse

from stereodepth import cmd_demo


def _parse(*argv):
    parser = argparse.ArgumentParser()
    cmd_demo.add_arguments(parser)
    return parser.parse_args(argv)


def test_the_demo_shows_the_ddr2_build_and_names_the_thesis_build():
    assert _parse().memory == "ddr2"
    assert _parse(*cmd_demo.THESIS_COMMAND.split()[4:]).memory == "bram"
