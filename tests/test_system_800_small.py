"""The 800 x 600 build at the small size (``SystemSetup.small_800``: the small preset's 64 x 48 sensors averaged 2 x 2
into 32 x 24 8-bit buffers, D = 16 with ``DEPTH_800``'s options and paths, the frames and the depth maps in the DDR2 with
the MIG model, half-size camera panels beside 1:1 maps on the small screen, the 8-bit difference thresholds): the
same structure as ``SystemSetup.full_800`` (default run, no simulation), and the whole system on every backend --
the Verilator C++ testbench, Amaranth's simulator, cocotb on Verilator and on Icarus -- whose frame shown (the
first with the run's pair's images and whole map) equals the golden frame bit for bit, no display read refused
(slow; the full-size run is tests/test_system.py::test_end_to_end_full_size_800)."""

from argparse import Namespace
from dataclasses import fields

import numpy as np
import pytest
from amaranth.hdl import Fragment

from golden.stereo_pair import load_default_pair
from hdl.config import DesignConfig
from hdl.stereo_display import check_display
from hdl.system import StereoDepthSystem
from sim.system import Amaranth, Cocotb, Verilator, simulate, still_pair
from sim.testbench.system.setup import DESIGN_FIELDS, PRESETS, SystemSetup
from spec.depth import SMALL_DEPTH

#: Twice the small preset's shift (tests/test_system.py): the buffer pixels are half the size.
DISPARITY, RECTIFICATION = 4, 1


def test_small_800_is_the_800_builds_structure_at_the_small_size():
    """``small_800`` differs from ``full_800`` only in sizes: the averaging capture (scale, grey bits), the engine
    (paths, pixels, penalties, thresholds; D twice the small engine's as DEPTH_800's is twice DEPTH's), the DDR2 with
    the maps in the store, the panels at half size beside 1:1 maps, the 8-bit thresholds; a map takes more than one
    display frame (three at full size, two here). Its checks pass, the whole system elaborates from it, its setup goes
    through JSON, and ``--small --build 800`` names it on the command line."""
    small, full = DesignConfig.small_800(), DesignConfig.full_800()
    for name in ("scale", "grey_bits", "downscale"):
        assert getattr(small.geometry, name) == getattr(full.geometry, name)
    assert (small.geometry.width, small.geometry.height) == (64, 48) == (DesignConfig.small().geometry.width,
                                                                           DesignConfig.small().geometry.height)
    sizes = ("disparities", "lanes")
    assert all(getattr(small.depth, f.name) == getattr(full.depth, f.name)
               for f in fields(small.depth) if f.name not in sizes)
    assert (small.depth.disparities, small.depth.lanes) == (2 * SMALL_DEPTH.disparities, SMALL_DEPTH.lanes)
    assert (small.memory, small.maps, small.thresholds) == (full.memory, full.maps, full.thresholds)
    assert [(r.source, r.scale, r.shrink) for r in small.layout.regions] == \
        [(r.source, r.scale, r.shrink) for r in full.layout.regions]
    assert (small.timing, small.i2c_hz) == (DesignConfig.small().timing, DesignConfig.small().i2c_hz)
    setup = SystemSetup.small_800(disparity=DISPARITY, rectification=RECTIFICATION)
    assert (setup.preset, setup.small_size) == ("small_800", True)
    assert all(getattr(setup, name) == getattr(small, name) for name in DESIGN_FIELDS)
    assert (setup.map_frames, SystemSetup.full_800().map_frames) == (2, 3)
    assert check_display(setup.timing, setup.geometry, setup.layout, config=setup.depth,
                         thresholds=setup.thresholds, memory="ddr2", maps="store") == setup.layout
    assert Fragment.get(StereoDepthSystem(**setup.board_kwargs()), None) is not None     # the whole hierarchy
    assert "small_800" in PRESETS and SystemSetup.from_spec(setup.to_spec()) == setup
    from stereodepth.cmd_run import make_setup
    from stereodepth.design_args import design_of
    assert make_setup(True, DISPARITY, RECTIFICATION, build="800") == setup
    assert design_of(Namespace(build="800", small=True, memory=None, maps=None)) == small


def _run(backend):
    setup = SystemSetup.small_800(disparity=DISPARITY, rectification=RECTIFICATION)
    left, right = load_default_pair(setup.geometry.width, setup.geometry.height)
    return simulate(setup, still_pair(left, right, setup), backend)


def _check(result):
    """The frame shown equals the golden frame; the first display frame shows the map of the pair before the run's
    (not its golden frame); no display read refused, no MIG protocol violation."""
    assert result.status["violations"] == [] and "mig_violation" not in result.status
    assert result.status["display_missed"] == 0
    assert result.verdict["chosen"] >= 1 and result.ok, result.verdict
    assert result.frames[0].verdict["mismatched_pixels"] > 0
    assert result.mismatched_pixels == 0
    np.testing.assert_array_equal(result.frame, result.golden)


@pytest.mark.slow
def test_end_to_end_small_800_verilator():
    """On the Verilator C++ testbench (a build of about a minute, then about a second)."""
    _check(_run(Verilator()))


@pytest.mark.slow
def test_small_800_frame_sequence_verilator():
    """Three camera frames of the moving card on Verilator (the build the still run made; about a second): every
    display frame shows one pair's images and difference map -- every row of the half-size panels from a camera
    frame -- with one pair's whole depth map, or no map before the first (a map takes two display frames) --
    measured (p, q): (-1, None), (0, -1), (0, -1), (1, 0), (1, 0), (2, 1), (2, 1), (2, 2) -- the settled frame the
    last pair's with its map, no display read refused."""
    from sim.testbed.sequence import moving_card
    setup = SystemSetup.small_800()
    result = simulate(setup, moving_card(setup, 3), Verilator())
    verdict, status = result.verdict, result.status
    assert status["violations"] == [] and status["display_missed"] == 0, status
    assert verdict["image_rows_from_camera_frames"] and verdict["display_frames_from_whole_pairs"], verdict
    assert verdict["ok"] and verdict["pairs_shown"][0] == (-1, None) and verdict["pairs_shown"][-1] == (2, 2)
    assert all(q in (p, p - 1) for p, q in verdict["pairs_shown"][1:]), verdict["pairs_shown"]


@pytest.mark.slow
def test_end_to_end_small_800_amaranth():
    """On Amaranth's simulator (the sensor models in Python, the MIG model's checker stopping the run on any
    violation)."""
    result = _run(Amaranth("python"))
    assert not result.sink.violations, result.sink.violations[:5]
    _check(result)


@pytest.mark.slow
def test_end_to_end_small_800_cocotb(simulator, tmp_path):
    """Through cocotb along the in-simulator route, on Verilator and on Icarus."""
    from sim.testbench.system.cocotb_routes import ROUTES
    _check(_run(Cocotb(simulator, ROUTES["in_simulator"](), out_dir=tmp_path)))
