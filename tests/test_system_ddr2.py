"""The system's DDR2 build (``memory="ddr2"``: the frames in the frame store behind MIG, docs/frame_store.md):
its ports, its parameter checks, and the small whole-system run with the MIG model
(sim/testbench/system/testbench.py) on Amaranth's simulator and on the Verilator C++ testbench, whose display
frame must equal the golden frame bit for bit, and whose model's violation stops the run with its message."""

import json
from dataclasses import replace

import numpy as np
import pytest

from golden.stereo_pair import load_default_pair
from hdl.config import DesignConfig
from hdl.mig_user import MIGUserSignature
from hdl.store_windows import check_store_windows
from hdl.system import StereoDepthSystem, SystemParameters
from sim import SimulationFailed, UserError
from sim.models.mig import INIT_CLOCKS, MESSAGES, READ_LATENCY_RANGE, MIGProtocolViolation, Violation, \
    draw_latency, violation_message
from sim.system.backends import Amaranth, Cocotb, Verilator
from sim.system.run import simulate, still_pair
from sim.system.verdict import Judge
from sim.testbed.sequence import moving_card
from sim.testbench.system.run_verilator import VerilatorRun
from sim.testbench.system.setup import SystemSetup
from spec.layout import DisplayLayout

DISPARITY, RECTIFICATION = 2, 1


def test_ddr2_build_has_the_mig_port_and_the_default_has_none():
    ddr2 = StereoDepthSystem(**DesignConfig.small(memory="ddr2").top_kwargs())
    assert ddr2.signature.members["mig"].signature == MIGUserSignature()
    assert "mig" not in StereoDepthSystem(**DesignConfig.small().top_kwargs()).signature.members
    with pytest.raises(ValueError, match="memory must be one of"):
        StereoDepthSystem(**DesignConfig.small(memory="sram").top_kwargs())


def half_size_panels(setup):
    """The small screen with the camera panels at half size (``shrink`` 2: their windows read every second row) and
    the maps at 2x where :meth:`DisplayLayout.centred` puts them (the 1:1 maps of ``full_maps`` need lines longer
    than the small mode's for the engine to keep up)."""
    centred = DisplayLayout.centred(setup.timing, setup.geometry, setup.depth)
    return replace(centred, regions=tuple(replace(r, shrink=2) if r.source in ("left", "right") else r
                                          for r in centred.regions))


def test_windows_take_half_size_panels_but_not_a_half_size_difference_map():
    layout = half_size_panels(SystemSetup.small())
    assert check_store_windows(layout) == layout.region("left").y1
    shrunk_map = replace(layout, regions=tuple(replace(r, shrink=2) if r.source == "disparity" else r
                                               for r in layout.regions))
    with pytest.raises(ValueError, match="difference map at 1/2 size skips buffer rows"):
        check_store_windows(shrunk_map)


def test_windows_need_a_line_between_the_panels_and_the_maps():
    layout = DesignConfig.small().layout
    assert check_store_windows(layout) == layout.region("left").y1
    panels_end = layout.region("left").y1
    touching = replace(layout, regions=tuple(replace(r, y0=panels_end) if r.source in ("disparity", "depth") else r
                                             for r in layout.regions))
    with pytest.raises(ValueError, match="must start below the panels"):
        check_store_windows(touching)


def test_every_backend_takes_the_ddr2_build_but_the_amaranth_replay_route(tmp_path):
    setup = SystemSetup.small(memory="ddr2")
    pair = still_pair(*load_default_pair(setup.geometry.width, setup.geometry.height), setup)
    for backend in (Verilator(), Amaranth("python"), Cocotb("verilator", out_dir=tmp_path),
                    Cocotb("icarus", out_dir=tmp_path)):
        backend.require(setup, pair)
    with pytest.raises(UserError, match="DDR2"):
        Amaranth("replay").require(setup, pair)


class _Pins:
    """The C++ testbench as the DDR2 driver uses it, without a build: ports, clocks and cameras noted."""

    def __init__(self, *args, **kwargs):
        self.values, self.clocks, self.now_ps = {}, {}, 0

    def __getitem__(self, port):
        return self.values.get(port, 0)

    def __setitem__(self, port, value):
        self.values[port] = value

    def bind_clock(self, clock, port, half_ps):
        self.clocks[clock] = (port, half_ps, None)

    def start_clock(self, clock, first_rise_ps):
        port, half, _ = self.clocks[clock]
        self.clocks[clock] = (port, half, first_rise_ps)

    def bind_camera(self, *args):
        pass

    def bind_recorder(self, *args):
        pass


@pytest.fixture
def unbuilt_run(monkeypatch):
    """A Verilator driver of the small DDR2 build over :class:`_Pins` (no Verilator build: the driver's own logic)."""
    from sim.testbench.system import run_verilator
    monkeypatch.setattr(run_verilator, "build", lambda setup: None)
    monkeypatch.setattr(run_verilator, "CTestbench", _Pins)
    setup = SystemSetup.small(memory="ddr2")
    return run_verilator.VerilatorRun(setup, still_pair(*load_default_pair(setup.geometry.width,
                                                                           setup.geometry.height), setup))


def test_verilator_driver_clocks_mem_sets_the_latency_and_stops_on_a_violation(unbuilt_run):
    """The DDR2 build's part of the Verilator driver: ``mem`` clocked at 8 ns from power-up, the drawn read latency
    set then, the violation code watched, and a code other than 0 stopping the run with the table's message."""
    run, h = unbuilt_run, unbuilt_run.h
    assert h.clocks["mem"][:2] == (("clocks", "mem"), 4000)
    assert ("memory", "violation", "code") in run._status_ports()
    run.button(True)
    assert h.clocks["mem"][2] == 4000 and h.clocks["sync"][2] == 5000
    assert h[("memory", "latency")] == run.status["mig_latency"] == draw_latency(0, READ_LATENCY_RANGE)
    run._wake()                                          # no violation: the run goes on
    code = Violation.ADDRESS_OUTSIDE_WINDOW
    h.values.update({("memory", "violation", "code"): code.value, ("memory", "violation", "addr"): 0x40,
                     ("memory", "violation", "cycle"): 1234})
    with pytest.raises(MIGProtocolViolation) as stop:
        run._wake()
    assert str(stop.value) == violation_message(code, 0x40, 1234)
    assert MESSAGES[code] in str(stop.value)


@pytest.fixture(scope="module")
def ddr2_verilator():
    """The small DDR2 build on the Verilator C++ testbench (the model's storage in Verilog), the default pair."""
    setup = SystemSetup.small(disparity=DISPARITY, rectification=RECTIFICATION, memory="ddr2")
    pair = still_pair(*load_default_pair(setup.geometry.width, setup.geometry.height), setup)
    return setup, pair, simulate(setup, pair, Verilator())


@pytest.mark.slow
def test_end_to_end_ddr2_verilator(ddr2_verilator):
    """The small DDR2 build on Verilator (a build of about a minute, then a fraction of a second): the display
    frame equals the golden frame, no row withheld, the latency drawn as on the Amaranth simulator."""
    _, _, result = ddr2_verilator
    assert result.status["mig_latency"] == draw_latency(0, READ_LATENCY_RANGE)
    assert result.status["violations"] == [] and result.status["display_missed"] == 0
    assert result.frame is not None and result.ok, result.verdict
    assert result.verdict["withheld_rows"] == [0] and result.mismatched_pixels == 0
    np.testing.assert_array_equal(result.frame, result.golden)


@pytest.mark.slow
def test_half_size_panels_ddr2_verilator():
    """The small DDR2 build with the camera panels at half size (:func:`half_size_panels`: the panels' windows ask
    for every second row) on Verilator (a build of under a minute): the display frame equals the golden frame at
    that layout, no display read refused."""
    base = SystemSetup.small(disparity=DISPARITY, rectification=RECTIFICATION, memory="ddr2")
    setup = replace(base, layout=half_size_panels(base))
    left, right = load_default_pair(setup.geometry.width, setup.geometry.height)
    result = simulate(setup, still_pair(left, right, setup), Verilator())
    assert result.status["violations"] == [] and result.status["display_missed"] == 0
    assert result.frame is not None and result.ok, result.verdict
    assert result.verdict["withheld_rows"] == [0] and result.mismatched_pixels == 0
    np.testing.assert_array_equal(result.frame, result.golden)
    assert (result.golden != base.golden_frame(left, right)).any()      # the half-size panels are on the screen


@pytest.mark.slow
def test_a_violation_stops_the_verilator_run_with_its_message(ddr2_verilator):
    """A read latency outside the model's range (a harness set-up the model's checker reports at
    ``phy_init_done``) stops the run at that instant, through ``simulate`` with the table's one line."""
    setup, pair, _ = ddr2_verilator
    late = READ_LATENCY_RANGE[1] + 1
    with pytest.raises(SimulationFailed) as failed:
        simulate(setup, pair, Verilator(mig_latency=late))
    assert isinstance(failed.value.__cause__, MIGProtocolViolation)
    assert str(failed.value) == str(failed.value.__cause__)
    assert MESSAGES[Violation.LATENCY_OUT_OF_RANGE] in str(failed.value)
    run = VerilatorRun(setup, pair, mig_latency=late)
    with pytest.raises(MIGProtocolViolation):
        run.run()
    code, _, cycle = run.status["mig_violation"]
    assert code == Violation.LATENCY_OUT_OF_RANGE.value and cycle == INIT_CLOCKS
    # Stopped on the mem clock edge that set the code: the model's cycles since its reset, which is released
    # after the 50 ns button press, the clocking model's lock (16 sync clocks) and the 2-stage synchroniser.
    assert (run.h.now_ps - 4000) % 8000 == 0
    assert 0 <= run.h.now_ps - cycle * 8000 <= 250_000


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
    assert result.status["display_missed"] == 0
    assert result.mismatched_pixels == 0
    np.testing.assert_array_equal(result.frame, result.golden)


def test_cocotb_in_simulator_route_clocks_mem_and_a_violation_file_stops_with_its_message(tmp_path, monkeypatch):
    """The cocotb side of the DDR2 build without a simulation: the in-simulator route's bench generates ``mem``
    (8 ns; the block-RAM build has no such clock), and a run the scenario stopped on the model's violation (its
    file written) raises the model's one-line message."""
    from sim.testbench.system import run_cocotb
    from sim.testbench.system.cocotb_routes import InSimulator
    setup = SystemSetup.small(memory="ddr2")
    bench = InSimulator().design(setup)
    assert bench.periods_ps["mem"] == 8000 and "mem" in bench.signature.members["clock_en"].signature.members
    bram = InSimulator().design(SystemSetup.small())
    assert "mem" not in bram.periods_ps and "mem" not in bram.signature.members["clock_en"].signature.members
    code = Violation.READ_NOT_TAKEN

    def stopped(route, setup, simulator, params, **kwargs):
        (tmp_path / run_cocotb.VIOLATION_FILE).write_text(f'{{"violation": [{code.value}, 0, 77], "t_ps": 1}}')
        raise AssertionError("cocotb tests failed: ['end_to_end']")
    monkeypatch.setattr(run_cocotb, "run_scenario", stopped)
    pair = still_pair(*load_default_pair(setup.geometry.width, setup.geometry.height), setup)
    with pytest.raises(SimulationFailed) as failed:
        simulate(setup, pair, Cocotb("icarus", out_dir=tmp_path))
    assert str(failed.value) == violation_message(code, 0, 77)


@pytest.mark.slow
@pytest.mark.parametrize("route", ["in_simulator", "python"])
def test_end_to_end_ddr2_cocotb(simulator, route, tmp_path):
    """The small DDR2 build through cocotb (the model's storage in Verilog, ``mem`` from the route's clocks):
    the display frame equals the golden frame, no row withheld (about a minute each, Verilator's build longer)."""
    from sim.testbench.system.cocotb_routes import ROUTES
    setup = SystemSetup.small(disparity=DISPARITY, rectification=RECTIFICATION, memory="ddr2")
    pair = still_pair(*load_default_pair(setup.geometry.width, setup.geometry.height), setup)
    result = simulate(setup, pair, Cocotb(simulator, ROUTES[route](), out_dir=tmp_path))
    assert result.status["mig_latency"] == draw_latency(0, READ_LATENCY_RANGE)
    assert result.status["violations"] == [] and "mig_violation" not in result.status
    assert result.status["display_missed"] == 0
    assert result.ok, result.verdict
    assert result.verdict["withheld_rows"] == [0] and result.mismatched_pixels == 0
    np.testing.assert_array_equal(result.frame, result.golden)


@pytest.mark.slow
def test_a_violation_stops_the_cocotb_run_with_its_message(tmp_path):
    """On Icarus along the in-simulator route (the cheapest cocotb run, about 20 s): a read latency outside the
    model's range stops the run on the mem clock edge the model reports it, with the table's one line."""
    from sim.testbench.system.run_cocotb import VIOLATION_FILE
    setup = SystemSetup.small(disparity=DISPARITY, rectification=RECTIFICATION, memory="ddr2")
    pair = still_pair(*load_default_pair(setup.geometry.width, setup.geometry.height), setup)
    with pytest.raises(SimulationFailed) as failed:
        simulate(setup, pair, Cocotb("icarus", out_dir=tmp_path, mig_latency=READ_LATENCY_RANGE[1] + 1))
    assert isinstance(failed.value.__cause__, MIGProtocolViolation)
    assert MESSAGES[Violation.LATENCY_OUT_OF_RANGE] in str(failed.value)
    seen = json.loads((tmp_path / VIOLATION_FILE).read_text())
    code, _, cycle = seen["violation"]
    assert code == Violation.LATENCY_OUT_OF_RANGE.value and cycle == INIT_CLOCKS
    assert (seen["t_ps"] - 4000) % 8000 == 0 and 0 <= seen["t_ps"] - cycle * 8000 <= 250_000


class _Shown:
    def __init__(self, index, pair):
        self.index, self.verdict = index, {"equals_pair": pair}


def test_ddr2_sequence_verdict_asks_every_display_frame_from_one_pair():
    """The DDR2 build's sequence verdict (sim/system/verdict.py): every display frame equal to one pair's golden
    frame (-1: the empty buffers), or not."""
    assert Judge._whole_pairs([_Shown(0, -1), _Shown(1, 0), _Shown(2, 2)]) == {
        "pairs_shown": [-1, 0, 2], "display_frames_from_one_pair": True}
    assert not Judge._whole_pairs([_Shown(0, 0), _Shown(1, None)])["display_frames_from_one_pair"]
    assert not Judge._whole_pairs([])["display_frames_from_one_pair"]


def test_store_sequence_verdict_asks_one_pair_s_images_with_one_whole_map_never_going_back():
    """With the maps in the frame store: every display frame one pair's images with one pair's whole map (the
    panels' pair or an earlier one) or, before the first map, none, the maps never going back; a frame no two pairs
    make, a map going back, or no map after one, fails."""
    def shown(*pairs):
        out = []
        for i, p in enumerate(pairs):
            out.append(_Shown(i, None))
            out[-1].verdict["equals_pairs"] = p
        return out
    assert Judge._store_pairs(shown((-1, -1), (0, -1), (0, 0), (1, 0))) == {
        "pairs_shown": [(-1, -1), (0, -1), (0, 0), (1, 0)], "display_frames_from_whole_pairs": True}
    assert not Judge._store_pairs(shown((0, 0), None))["display_frames_from_whole_pairs"]
    assert not Judge._store_pairs(shown((1, 1), (2, 0)))["display_frames_from_whole_pairs"]
    # no map yet (q None: the depth panel every row not ready) before the first map only
    assert Judge._store_pairs(shown((-1, None), (0, None), (0, -1)))["display_frames_from_whole_pairs"]
    assert not Judge._store_pairs(shown((0, -1), (0, None)))["display_frames_from_whole_pairs"]
    assert not Judge._store_pairs([])["display_frames_from_whole_pairs"]


@pytest.mark.slow
def test_ddr2_frame_sequence_amaranth():
    """Three camera frames of the moving card on the small DDR2 build (Python sensor models, the MIG model, its
    checker stopping the run on any violation): every display frame equals the golden frame of one camera-frame pair
    -- no withheld row, no mixed row, the images and both maps of one pair -- the settled one the last pair's, and
    no display read refused."""
    setup = SystemSetup.small(memory="ddr2")
    sequence = moving_card(setup, 3)
    result = simulate(setup, sequence, Amaranth("python"))
    verdict, status = result.verdict, result.status
    assert status["violations"] == [] and status["display_missed"] == 0, status
    assert verdict["display_frames_from_one_pair"], verdict
    assert verdict["pairs_shown"][-1] == 2 and verdict["ok"], verdict
    assert all(f.verdict["depth_rows_mixed"] == 0 and f.verdict.get("depth_rows_withheld", 0) == 0
               and f.verdict["left_rows_mixed"] == 0 and f.verdict["right_rows_mixed"] == 0 for f in result.frames)


def test_maps_in_the_store_need_the_ddr2_and_a_map_a_camera_frame():
    """``maps="store"`` only with the DDR2 build; its check: the display frames a map takes (the engine starts at a
    display frame's start when the last map is whole) within a camera frame. The 800 x 600 build's engine (D = 128)
    takes 3 1080p frames (50 ms, under the sensors' 66.7 ms; 20 frames a second exactly: 21 refused), on three
    paths 6 (refused); the ring's check refuses the 800 x 600 build at 1080p, and the 800 x 600 system passes its
    checks with the maps in the store."""
    from spec.depth import DEPTH_800, DEPTH_800_THREE
    from spec.sensor import SENSOR_800
    from spec.video import CEA_1080P60
    from hdl.stereo_display import check_engine_keeps_up, check_map_rate, map_clocks
    from spec.layout import DisplayLayout
    with pytest.raises(ValueError, match="needs memory='ddr2'"):
        SystemParameters(**DesignConfig.small(maps="store").top_kwargs())
    with pytest.raises(ValueError, match="maps must be one of"):
        SystemParameters(**DesignConfig.small(memory="ddr2", maps="frames").top_kwargs())
    store = SystemParameters(**DesignConfig.small(memory="ddr2", maps="store").top_kwargs()).store_layout
    assert (store.maps, store.map_bits) == (3, DesignConfig.small().depth.code_bits)
    two = DEPTH_800
    assert 2 * 2_475_000 < map_clocks(SENSOR_800, two) <= 3 * 2_475_000
    assert check_map_rate(CEA_1080P60, SENSOR_800, two) == 3
    assert check_map_rate(CEA_1080P60, SENSOR_800, two, camera_fps=20) == 3
    with pytest.raises(ValueError, match="takes 3 display frames"):
        check_map_rate(CEA_1080P60, SENSOR_800, two, camera_fps=21)
    with pytest.raises(ValueError, match="takes 6 display frames"):
        check_map_rate(CEA_1080P60, SENSOR_800, DEPTH_800_THREE)
    # The writer's pace: a row drained within a pass (800 x 600: 12,034 clocks, so a code every 15 at the most).
    assert check_map_rate(CEA_1080P60, SENSOR_800, two, pace=15) == 3
    with pytest.raises(ValueError, match="drains a row in 12803 clocks .* longer than the engine's pass of 12034"):
        check_map_rate(CEA_1080P60, SENSOR_800, two, pace=16)
    with pytest.raises(ValueError, match="cannot keep up"):
        check_engine_keeps_up(CEA_1080P60, DisplayLayout.full_maps(CEA_1080P60, SENSOR_800, two), SENSOR_800, two)
    # The 800 x 600 system (its layout, the 8-bit thresholds): its checks pass with the maps in the store only.
    from spec.display import diff_thresholds
    system = dict(geometry=SENSOR_800, timing=CEA_1080P60, layout=DisplayLayout.full_maps(CEA_1080P60, SENSOR_800, two),
                  depth=two, thresholds=diff_thresholds(8), memory="ddr2")
    assert SystemParameters(**system, maps="store").store_layout.map_layout.pixel_bytes == 2
    with pytest.raises(ValueError, match="cannot keep up"):
        SystemParameters(**system, maps="ring")


@pytest.fixture(scope="module")
def store_verilator():
    """The small DDR2 build with the maps in the store on the Verilator C++ testbench, the default pair."""
    setup = SystemSetup.small(disparity=DISPARITY, rectification=RECTIFICATION, memory="ddr2", maps="store")
    pair = still_pair(*load_default_pair(setup.geometry.width, setup.geometry.height), setup)
    return simulate(setup, pair, Verilator())


@pytest.mark.slow
def test_end_to_end_maps_in_the_store_verilator(store_verilator):
    """``maps="store"`` on Verilator: the first display frame shows the map of the pair before the run's (not its
    golden frame); the frame shown (from the second on, the first with the run's pair's images and map) equals the
    golden frame bit for bit, no display read refused."""
    result = store_verilator
    assert result.status["violations"] == [] and result.status["display_missed"] == 0
    assert result.verdict["chosen"] >= 1 and result.ok, result.verdict
    assert result.frames[0].verdict["mismatched_pixels"] > 0
    np.testing.assert_array_equal(result.frame, result.golden)


@pytest.mark.slow
def test_end_to_end_maps_in_the_store_amaranth():
    """``maps="store"`` on Amaranth's simulator (about twice the ring build's time: two display frames or more): the
    frame shown (from the second on, the first with the run's pair's images and map) equals the golden frame bit for
    bit, no display read refused."""
    setup = SystemSetup.small(disparity=DISPARITY, rectification=RECTIFICATION, memory="ddr2", maps="store")
    left, right = load_default_pair(setup.geometry.width, setup.geometry.height)
    result = simulate(setup, still_pair(left, right, setup), Amaranth("python"))
    assert not result.sink.violations, result.sink.violations[:5]
    assert result.status["display_missed"] == 0
    assert result.verdict["chosen"] >= 1 and result.ok, result.verdict
    np.testing.assert_array_equal(result.frame, result.golden)


@pytest.mark.slow
def test_end_to_end_maps_in_the_store_cocotb(simulator, tmp_path):
    """``maps="store"`` through cocotb (the in-simulator route; about a minute on Icarus): the frame shown (from the
    second on, the first with the run's pair's images and map) equals the golden frame bit for bit, no display read
    refused."""
    from sim.testbench.system.cocotb_routes import ROUTES
    setup = SystemSetup.small(disparity=DISPARITY, rectification=RECTIFICATION, memory="ddr2", maps="store")
    pair = still_pair(*load_default_pair(setup.geometry.width, setup.geometry.height), setup)
    result = simulate(setup, pair, Cocotb(simulator, ROUTES["in_simulator"](), out_dir=tmp_path))
    assert result.status["violations"] == [] and result.status["display_missed"] == 0
    assert result.verdict["chosen"] >= 1 and result.ok, result.verdict
    np.testing.assert_array_equal(result.frame, result.golden)


@pytest.mark.slow
def test_maps_in_the_store_frame_sequence_verilator(store_verilator):
    """Three camera frames of the moving card, ``maps="store"``, on Verilator (the build the still run made): every
    display frame shows one pair's images and difference map with one pair's whole depth map, the map one pair
    behind or the same, never going back -- measured (p, q): (-1, -1), (0, -1), (0, 0), (1, 0), (1, 1), (2, 1),
    (2, 2) -- the settled frame the last pair's with its map, no display read refused."""
    setup = store_verilator.setup
    result = simulate(setup, moving_card(setup, 3), Verilator())
    verdict, status = result.verdict, result.status
    assert status["violations"] == [] and status["display_missed"] == 0, status
    assert verdict["display_frames_from_whole_pairs"] and verdict["ok"], verdict
    assert verdict["pairs_shown"][-1] == (2, 2)
    assert all(q in (p, p - 1) for p, q in verdict["pairs_shown"]), verdict["pairs_shown"]
