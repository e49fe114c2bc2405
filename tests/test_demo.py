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


def test_the_demo_runs_the_800_build_and_says_what_its_frame_shows():
    """``--build 800`` is taken; the summary of a run with the maps in the store names what the frame shown holds
    (its images and whole map the pair's), the ring build's what its map comes from."""
    from stereodepth.cmd_run import shown_lines
    assert _parse("--build", "800").build == "800"
    verdict = {"chosen": 5, "display_frames": 6, "policy": "whole", "withheld_rows": [0] * 6}
    assert "images and whole depth map are the captured pair's" in shown_lines(dict(verdict, maps="store"))[0]
    ring = shown_lines(dict(verdict, maps="ring", withheld_rows=[3, 0, 0, 0, 0, 0]))[0]
    assert "depth map comes from complete camera frames (depth rows withheld at a tear before it" in ring
