"""The whole system end to end: stereo pair -> two MT9D112 models (configured over I2C by the RTL) -> capture ->
frame buffers -> compositor and depth engine -> CH7301C pins -> HDMI sink model, compared bit for bit with the
golden model's frame (golden.disparity.composite_frame of golden.capture.capture_frame of each image: the four
panels, the depth map with its colour bar, labels, crosshair and centre distance).

Every run goes through ``sim.system.simulate`` with a still pair. Default run: the small preset (64 x 48 sensor,
112 x 52 display, D = 8; sim/testbench/system/setup.py) on Amaranth's simulator and through cocotb on Verilator and
Icarus, along every route (tests/test_verilator_route.py runs the Verilator backend with the C++ testbench; the
Amaranth Python-model route runs through the command line, tests/test_cli_outputs.py's complete run, with this
file's checks). Slow: the full 1600 x 1200 -> 1080p run (tests marked ``slow``), parametrized over the backends.
"""

import numpy as np
import pytest

from golden.stereo_pair import load_default_pair
from hdl.init_tables import MT9D112_TABLE, Poll, Wait, Write
from spec.display import NO_DATA_RGB
from spec.sensor import SMALL_SENSOR
from sim.system import Amaranth, Cocotb, Verilator, simulate, still_pair
from sim.testbench.system.cocotb_routes import InSimulator, PythonModels
from sim.testbench.system.run_cocotb import DEFAULT_PAIR
from sim.testbench.system.result import SystemTimeout, tear_tags
from sim.testbench.system.setup import SystemSetup
from sim.testbench.system.tables import QUICK_VARIABLES, SIZE_VARIABLES, mt9d112_table

DISPARITY, RECTIFICATION = 2, 1     # small buffers are 16 x 12: a shift of 2 leaves a no-data band


def _var_writes(table):
    """``{(driver, offset): value}`` written through 0x338C/0x3390, in order."""
    out, var = {}, None
    for e in table.entries:
        if isinstance(e, Write) and e.reg == 0x338C:
            var = ((e.value >> 8) & 0x1F, e.value & 0xFF)
        elif isinstance(e, Write) and e.reg == 0x3390:
            out[var] = e.value
    return out


def test_derived_tables_keep_the_board_table_but_size_and_time():
    full = _var_writes(MT9D112_TABLE)
    for quick in (False, True):
        t = mt9d112_table(SMALL_SENSOR, time_scale=0.5, quick=quick)
        vals = _var_writes(t)
        for var, field in SIZE_VARIABLES.items():
            assert vals[var] == getattr(SMALL_SENSOR, field)
        for var, value in vals.items():
            if var not in SIZE_VARIABLES:
                assert value == full[var]                  # every other variable as on the board
        assert set(vals) == (QUICK_VARIABLES if quick else set(full))
        # Entries are the board table's, in the same order (a subsequence), waits halved.
        base = list(MT9D112_TABLE.entries)
        i = 0
        for e in t.entries:
            while not (type(base[i]) is type(e) and getattr(base[i], "reg", None) == getattr(e, "reg", None)):
                i += 1
            if isinstance(e, Wait):
                assert e.us == max(1, round(base[i].us * 0.5))
            if isinstance(e, Poll):
                assert e.interval_us == (max(1, round(base[i].interval_us * 0.5)) if base[i].interval_us else 0)
            i += 1
    assert len(mt9d112_table(SMALL_SENSOR, quick=False)) == len(MT9D112_TABLE)


def check_golden_is_interesting(golden, setup):
    """The comparison would be weak if the golden frame were flat: require several disparity levels and the
    no-data colour in the difference map, several depth colours in the depth map and a distance (digits, not
    dashes) in the readout."""
    r = setup.display_layout.region("disparity")
    region = golden[r.y0:r.y1, r.x0:r.x1].reshape(-1, 3)
    colours = {tuple(c) for c in region}
    no_data = ((NO_DATA_RGB >> 16) & 0xFF, (NO_DATA_RGB >> 8) & 0xFF, NO_DATA_RGB & 0xFF)
    assert no_data in colours and len(colours) >= 4
    d = setup.display_layout.region("depth")
    assert len({tuple(c) for c in golden[d.y0:d.y1, d.x0:d.x1].reshape(-1, 3)}) >= 4
    assert setup.golden_frame(*load_default_pair(setup.geometry.width, setup.geometry.height),
                              details=True)[2].strip()[0].isdigit()


def _run(setup, backend):
    left, right = load_default_pair(setup.geometry.width, setup.geometry.height)
    return simulate(setup, still_pair(left, right, setup), backend)


def check_status(status, settings=(DISPARITY, RECTIFICATION)):
    """The parts configured, the buses released, both captures whole, the switches' ``settings`` (disparity,
    rectification) read back and the LEDs: a run's status (in-process, or a command line run's result.json)."""
    for bus in ("cam_a", "cam_b", "dvi"):
        assert status[f"{bus}_init_done"] and not status[f"{bus}_init_error"], status
        assert not status["drive_high"][bus]
    assert status["cam_a_frame_ok"] and status["cam_b_frame_ok"]
    assert (status["disparity"], status["rectification"]) == settings
    assert status["auto_rectification"]["auto"] == 0                 # a manual value
    assert status["leds"] & 0b111111 == 0b010101          # init done on all three buses, no error


@pytest.mark.parametrize("route", [pytest.param("python", marks=pytest.mark.slow),
                                   pytest.param("replay", marks=pytest.mark.slow)])
def test_end_to_end_amaranth(route):
    """The small system end to end in Amaranth's simulator, along each route: the Python sensor models per PCLK, and
    the full-size route (sim/testbench/system/rom_testbench.py: each camera's stream, made by the sensor model before
    the run, replayed from a ROM; gated simulator clocks), whose every sample of the replayed frame period was sent.
    The frame equals the golden frame, the parts end configured, the buses clean. No waveforms (they cost twice the
    run). Both routes are slow. The default suite runs the ``python`` route's simulation through the command line,
    tests/test_cli_outputs.py's complete run (``stereodepth run --small --simulator amaranth``: the same backend;
    with ``--vcd`` and ``system_waves`` in its slow variant), with these checks on its result.json and frames; the
    ``replay`` route as far as the I2C init in test_replayed_sensors_need_the_configuration_their_stream_was_made_for,
    and replayed camera pins to a whole frame on Verilator and Icarus in test_in_simulator_route_is_equivalent."""
    setup = SystemSetup.small(disparity=DISPARITY, rectification=RECTIFICATION)
    result = _run(setup, Amaranth(route))
    check_status(result.status)
    check_golden_is_interesting(result.golden, setup)
    assert not result.sink.violations, result.sink.violations[:5]
    assert result.frame is not None and result.ok
    assert result.mismatched_pixels == 0
    np.testing.assert_array_equal(result.frame, result.golden)
    for bus in ("cam_a", "cam_b"):
        model = result.models[bus][0]
        cfg = model.sensor_config()
        assert (cfg.width, cfg.height, cfg.rgb565) == (setup.geometry.width, setup.geometry.height, True)
        assert model.problems() == []
    dvi = result.models["dvi"][0].dvi_config()
    assert dvi.dvi_on and dvi.idf == 0 and dvi.hsync_positive and dvi.vsync_positive and dvi.pll_range == "high"
    for bus, monitor in result.monitors.items():
        assert not monitor.protocol_errors, (bus, monitor.protocol_errors[:3])
        assert monitor.transactions
    if route == "replay":
        frame_period = setup.sensor(result.models["cam_a"][0], seed=0).frame(result.sequence.pairs[0][0])
        assert min(result.figures["cam_samples"].values()) > len(frame_period)


@pytest.mark.slow
def test_end_to_end_amaranth_segmentation():
    """The switches on 1000001 (automatic rectification + the segmentation view): the frame equals the golden frame
    with the segmentation view in the difference map's place, which differs from the difference map. Slow: the
    default suite makes these checks through the command line on Verilator, tests/test_cli_outputs.py::
    test_segment_run_records_its_band."""
    setup = SystemSetup.small(disparity=DISPARITY, rectification="auto", segment=True)
    assert setup.switch_words() == [0x80 | DISPARITY, 0b1000001]
    left, right = load_default_pair(setup.geometry.width, setup.geometry.height)
    result = _run(setup, Amaranth())
    assert result.status["auto_rectification"]["auto"] == 1
    assert result.mismatched_pixels == 0 and not result.sink.violations
    np.testing.assert_array_equal(result.frame, result.golden)
    plain = SystemSetup.small(disparity=DISPARITY, rectification="auto").golden_frame(     # with the same tear
        left, right, in_use=result.status["rectification"],
        row_tags=tear_tags(setup.geometry.buf_height, result.status["tear"]))
    r = setup.display_layout.region("disparity")
    assert (plain[r.y0:r.y1, r.x0:r.x1] != result.golden[r.y0:r.y1, r.x0:r.x1]).any()
    outside = result.golden.copy()
    outside[r.y0:r.y1, r.x0:r.x1] = plain[r.y0:r.y1, r.x0:r.x1]
    np.testing.assert_array_equal(outside, plain)      # nothing else changes (the small layout has no band text)


def test_replayed_sensors_need_the_configuration_their_stream_was_made_for(monkeypatch):
    """The replay ROM is made before the run for the spec's sensor configuration; if the RTL's I2C init leaves a
    register-file model configured otherwise (here: the ROM made for G byte first), the run stops with an error
    instead of replaying a stream the model would not send."""
    import sim.testbench.system.run_amaranth       # where the replay route makes its ROMs
    from sim.models.mt9d112.config import SensorConfig
    setup = SystemSetup.small()
    g = setup.geometry
    monkeypatch.setattr(sim.testbench.system.run_amaranth, "expected_sensor_config",
                        lambda geometry: SensorConfig(width=g.width, height=g.height, rgb565=True,
                                                      r_byte_first=False))
    with pytest.raises(SystemTimeout, match="camera a: the I2C init configured .*r_byte_first=True"):
        _run(setup, Amaranth("replay"))


@pytest.mark.parametrize("simulator", ["verilator", pytest.param("icarus", marks=pytest.mark.slow)])
def test_end_to_end_cocotb_python_models(simulator, tmp_path):
    """cocotb with the Python models driven per clock (sensor pins per PCLK, the HDMI sink per pixel clock), in the
    real start-up order: the pixel clock (and the display) runs from time 0, during the I2C init
    (``pix_after_init=False``; the other routes start it after the init). Icarus is slow here (twice Verilator's
    time: its VPI callbacks per clock); the default suite runs Icarus through the in-simulator route below."""
    setup = SystemSetup.small(disparity=DISPARITY, rectification=RECTIFICATION, pix_after_init=False)
    result = _run(setup, Cocotb(simulator, PythonModels(), out_dir=tmp_path))
    status = result.status
    check_status(status)
    check_golden_is_interesting(result.golden, SystemSetup.small(disparity=DISPARITY,
                                                                  rectification=RECTIFICATION))
    assert status["violations"] == []
    assert result.mismatched_pixels == 0
    np.testing.assert_array_equal(result.frame, result.golden)
    assert all(not errs for errs in status["i2c_protocol_errors"].values())
    assert status["dvi_config"]["dvi_on"] and status["dvi_config"]["idf"] == 0
    assert all(not p for p in status["mt9d112_problems"].values())


def test_in_simulator_route_is_equivalent(simulator, tmp_path):
    """The end-to-end run along the in-simulator route (sim/testbench/system/verilog_testbench.py), checked against the Python
    models in the same run: the replayed camera pins equal the sensor model's stream sample for sample, and the
    pin recorder's per-clock samples equal those of the Python sink (``CocotbSink``) sampling the same pins; the
    frame rebuilt from them equals the golden frame bit for bit."""
    setup = SystemSetup.small(disparity=DISPARITY, rectification=RECTIFICATION)
    result = _run(setup, Cocotb(simulator, InSimulator(cross_check=5000), out_dir=tmp_path))
    status = result.status
    check_status(status)
    assert status["replay_checks"]["a"] == {"samples": 5000, "mismatches": 0}
    assert status["replay_checks"]["b"] == {"samples": 5000, "mismatches": 0}
    assert status["recorded_clocks"] == SystemSetup.small().timing.clocks_per_frame + 9
    assert status["sink_vs_recorder_mismatches"] == 0 and status["recorder_violations"] == []
    assert result.mismatched_pixels == 0


FULL_SETUP = SystemSetup.full(disparity=10, rectification=1)


def _check_full_size_status(status):
    for bus in ("cam_a", "cam_b", "dvi"):
        assert status[f"{bus}_init_done"] and not status[f"{bus}_init_error"]
    assert status["cam_a_frame_ok"] and status["cam_b_frame_ok"]
    assert (status["disparity"], status["rectification"]) == (10, 1)


def _check_full_size_frame(status, result):
    assert status["violations"] == [] and result.mismatched_pixels == 0
    assert status["recorded_clocks"] == 2200 * 1125 + 9
    assert status["i2c_transactions"]["cam_a"] >= 40        # the board's whole MT9D112 table


@pytest.mark.slow
@pytest.mark.parametrize("backend", [
    pytest.param(lambda tmp: Verilator(), id="verilator"),          # the C++ testbench: the route of make demo
    pytest.param(lambda tmp: Cocotb("icarus", InSimulator(), out_dir=tmp), id="icarus"),
    # Hours long (README gives the figure): each camera's stream replayed from a ROM, gated clocks
    # (sim/testbench/system/rom_testbench.py), the HDMI sink still samples every pixel clock in Python.
    pytest.param(lambda tmp: Amaranth("replay"), id="amaranth", marks=pytest.mark.hours),
])
def test_end_to_end_full_size(backend, tmp_path):
    """1600 x 1200 sensors -> 400 x 300 buffers -> one 1080p frame, bit for bit, on each backend."""
    result = _run(FULL_SETUP, backend(tmp_path))
    _check_full_size_status(result.status)
    _check_full_size_frame(result.status, result)
    assert result.frame.shape == (1080, 1920, 3) and result.ok
    for check in result.status.get("replay_checks", {}).values():
        assert check["mismatches"] == 0 and check["samples"] > 4_000_000


@pytest.mark.slow
def test_end_to_end_full_size_ddr2():
    """The DDR2 build at full size on Verilator (the route of ``make demo``): the first display frame equals the
    golden frame bit for bit, no depth row withheld, no display read refused (the small DDR2 runs of
    tests/test_system_ddr2.py do not load the store as the 1080p display and the 400 x 300 engine do)."""
    from dataclasses import replace
    result = _run(replace(FULL_SETUP, memory="ddr2"), Verilator())
    _check_full_size_status(result.status)
    assert result.status["violations"] == [] and result.mismatched_pixels == 0
    assert result.status["display_missed"] == 0 and not result.chosen.verdict["tear"]
    assert result.frame.shape == (1080, 1920, 3) and result.ok


@pytest.mark.slow
def test_end_to_end_full_size_800():
    """The 800 x 600 build at full size on Verilator (the averaging capture, the frames and the depth maps in the
    DDR2 with the MIG model, D = 128, the maps 1:1): the first display frame whose images and map are of the
    captured pair equals the golden frame bit for bit, no display read refused, no depth row withheld."""
    result = _run(SystemSetup.full_800(disparity=60, rectification=1), Verilator())
    status = result.status
    for bus in ("cam_a", "cam_b", "dvi"):
        assert status[f"{bus}_init_done"] and not status[f"{bus}_init_error"]
    assert status["cam_a_frame_ok"] and status["cam_b_frame_ok"] and (status["disparity"], status["rectification"]) == (60, 1)
    assert status["violations"] == [] and result.mismatched_pixels == 0 and status["display_missed"] == 0
    assert result.chosen.verdict["map_shown"] and result.chosen.verdict["withheld_rows"] == 0
    assert result.frame.shape == (1080, 1920, 3) and result.ok


def test_run_command_rejects_bad_input(tmp_path, capsys):
    from PIL import Image
    from stereodepth.cli import main
    left, right = map(str, DEFAULT_PAIR)
    small = tmp_path / "small.png"
    Image.new("RGB", (10, 10)).save(small)
    junk = tmp_path / "junk.png"
    junk.write_bytes(b"not an image")
    cases = [
        ([str(tmp_path / "missing.png"), right], "no such image file"),
        ([left, str(junk)], "cannot read image"),
        ([left, str(small)], "must be the same size"),
        ([left, right, "--disparity", "200"], "0..127"),
        ([left, right, "--rectification", "x"], "integer"),
        ([left, right, "--simulator", "amaranth", "--vcd"], "--small"),
        ([left, right, "--vcd"], "--vcd"),
    ]
    for argv, message in cases:
        assert main(["run", *argv, "--out", str(tmp_path / "out")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and message in err[0], (argv, err)


def test_setup_rejects_out_of_range_switch_values():
    with pytest.raises(ValueError, match="disparity"):
        SystemSetup.small(disparity=128)
    with pytest.raises(ValueError, match="rectification"):
        SystemSetup.small(rectification=64)
    with pytest.raises(ValueError, match="rectification"):
        SystemSetup.small(rectification=-64)            # 1000000 selects the automatic mode
    with pytest.raises(ValueError, match="rectification"):
        SystemSetup.small(rectification=-63)            # 1000001: automatic + the segmentation view
    with pytest.raises(ValueError, match="segmentation view comes with the automatic"):
        SystemSetup.small(rectification=3, segment=True)
    assert SystemSetup.small(rectification="auto", segment=True).switch_words()[1] == 0b1000001
    assert SystemSetup.small(rectification=-62).switch_words()[1] == 0b1000010
    assert SystemSetup.small(rectification=-1).switch_words()[1] == 0b1111111
    assert SystemSetup.small(rectification="auto").switch_words()[1] == 0b1000000
