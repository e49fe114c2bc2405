"""The system's DDR2 build (``memory="ddr2"``: the frames in the frame store behind MIG, docs/frame_store.md):
its ports, its parameter checks, and the small whole-system run on Amaranth's simulator with the MIG model
(sim/testbench/system/testbench.py), whose display frame must equal the golden frame bit for bit."""

from dataclasses import replace

import numpy as np
import pytest

from golden.stereo_pair import load_default_pair
from hdl.config import DesignConfig
from hdl.mig_user import MIGUserSignature
from hdl.store_windows import check_store_windows
from hdl.system import StereoDepthSystem
from sim import UserError
from sim.system.backends import Amaranth, Verilator
from sim.system.run import simulate, still_pair
from sim.testbench.system.setup import SystemSetup

DISPARITY, RECTIFICATION = 2, 1


def test_ddr2_build_has_the_mig_port_and_the_default_has_none():
    ddr2 = StereoDepthSystem(**DesignConfig.small(memory="ddr2").top_kwargs())
    assert ddr2.signature.members["mig"].signature == MIGUserSignature()
    assert "mig" not in StereoDepthSystem(**DesignConfig.small().top_kwargs()).signature.members
    with pytest.raises(ValueError, match="memory must be one of"):
        StereoDepthSystem(**DesignConfig.small(memory="sram").top_kwargs())


def test_windows_need_a_line_between_the_panels_and_the_maps():
    layout = DesignConfig.small().layout
    assert check_store_windows(layout) == layout.region("left").y1
    panels_end = layout.region("left").y1
    touching = replace(layout, regions=tuple(replace(r, y0=panels_end) if r.source in ("disparity", "depth") else r
                                             for r in layout.regions))
    with pytest.raises(ValueError, match="must start below the panels"):
        check_store_windows(touching)


def test_ddr2_runs_on_the_amaranth_python_route_only():
    setup = SystemSetup.small(memory="ddr2")
    left, right = load_default_pair(setup.geometry.width, setup.geometry.height)
    for backend in (Verilator(), Amaranth("replay")):
        with pytest.raises(UserError, match="DDR2"):
            backend.require(setup, still_pair(left, right, setup))


@pytest.mark.slow
def test_end_to_end_ddr2_amaranth():
    """The small DDR2 build end to end (Python sensor models, the MIG model in ``mem`` at 125 MHz, its checker
    stopping the run on any violation): the display frame equals the golden frame, no row withheld."""
    setup = SystemSetup.small(disparity=DISPARITY, rectification=RECTIFICATION, memory="ddr2")
    left, right = load_default_pair(setup.geometry.width, setup.geometry.height)
    result = simulate(setup, still_pair(left, right, setup), Amaranth("python"))
    assert not result.sink.violations, result.sink.violations[:5]
    assert result.frame is not None and result.ok, result.verdict
    assert result.verdict["withheld_rows"] == [0]
    assert result.mismatched_pixels == 0
    np.testing.assert_array_equal(result.frame, result.golden)
