"""The Verilator backend with its testbench in C++ (sim/testbench/system/run_verilator.py, sim/runners/verilator/) on
the small preset, through ``sim.system.simulate``: the frame, the models' checks, the raw reference model replaying
the run exactly, and each check shown to bite."""

import numpy as np
import pytest

from golden.stereo_pair import load_default_pair
from hdl.init_tables import CH7301C_TABLE
from sim.models.ch7301c.hdmi_sink import HdmiSink
from sim.models.i2c.table import expected_writes
from sim.testbench.system.result import SystemTimeout
from sim.system import Verilator, simulate, still_pair
from sim.testbench.system.run_verilator import VerilatorRun, camera_pins
from sim.testbench.system.setup import SystemSetup
from sim.runners.verilator.ctestbench import STIMULUS
from bench.raw_model import run_raw
from sim.runners.verilator.recording import decode, feed_sink

DISPARITY, RECTIFICATION = 2, 1


def _setup():
    return SystemSetup.small(disparity=DISPARITY, rectification=RECTIFICATION)


def _pair(setup):
    return still_pair(*load_default_pair(setup.geometry.width, setup.geometry.height), setup)


@pytest.fixture(scope="module")
def base():
    setup = _setup()
    return simulate(setup, _pair(setup), Verilator(keep_stimulus=True))


def test_small_run_is_bit_exact_and_every_check_holds(base):
    status, run = base.status, base.driver
    setup = run.setup
    for bus in ("cam_a", "cam_b", "dvi"):
        assert status[f"{bus}_init_done"] and not status[f"{bus}_init_error"]
        assert not status["drive_high"][bus] and not status["i2c_protocol_errors"][bus]
    assert status["cam_a_frame_ok"] and status["cam_b_frame_ok"]
    assert (status["disparity"], status["rectification"]) == (DISPARITY, RECTIFICATION)
    assert status["violations"] == [] and status["mismatched_pixels"] == 0
    np.testing.assert_array_equal(base.frame, base.golden)
    assert status["recorded_clocks"] == setup.timing.clocks_per_frame + 9
    # Every sample each camera sent (more than a frame period: the wrap-around too) equals the model's stream.
    for c in ("a", "b"):
        assert status["replay_checks"][c]["mismatches"] == 0
        assert status["replay_checks"][c]["samples"] > len(run.words[c])
    # The register-file models answered live: they received exactly the tables' writes.
    for bus in ("cam_a", "cam_b"):
        assert [("mt9d112", r, v) for r, v in base.models[bus][0].writes] == expected_writes(setup.cam_table)
        assert base.models[bus][0].problems() == []
    assert [("ch7301c", r, v) for r, v in base.models["dvi"][0].writes] == expected_writes(CH7301C_TABLE)
    assert status["dvi_config"]["dvi_on"] and status["dvi_config"]["idf"] == 0


@pytest.mark.slow
def test_raw_model_replays_the_run_exactly(base):
    """The raw model (raw_main.cpp, no Python) given the run's stimulus log evaluates the design as often and
    records the same pins, word for word. Slow, with the next test: the raw model is the system benchmark's
    reference (``python -m bench system`` checks the same equality on every run it measures) and its build
    compiles the Verilated design a second time."""
    run = base.driver
    figures, recording = run_raw(run)
    assert figures["complete"] and figures["evals"] == base.status["evals"]
    np.testing.assert_array_equal(recording, run.recording[:run.h.recorded])


@pytest.mark.slow
def test_raw_model_sees_a_changed_stimulus(base):
    """Bites: the same log with the disparity switch word changed records different pins."""
    run = base.driver
    stimulus = run.h.stimulus().copy()
    sw = run.h.port(("panel", "sw"))
    word = np.flatnonzero((stimulus["kind"] == 0) & (stimulus["a"] == sw) & (stimulus["b"] == 0x80 | DISPARITY))
    assert len(word) == 1
    stimulus["b"][word[0]] = 0x80 | (DISPARITY + 3)
    _, recording = run_raw(run, stimulus.astype(STIMULUS))
    assert len(recording) == run.h.recorded
    assert np.count_nonzero(recording != run.recording[:run.h.recorded]) > 10


def test_replay_check_bites():
    """A camera that replays one wrong sample is caught by the replay check (the frame would hide a shifted
    stream: the capture starts at the frame's FV edge)."""
    setup = _setup()
    run = VerilatorRun(setup, _pair(setup))
    bad = run.words["a"].copy()
    i = int(np.flatnonzero(bad >> 8 == 0b11)[100])          # a byte of an active line
    bad[i] ^= 0x10
    run.h.bind_camera(0, camera_pins("a"), bad, run.seen["a"])
    run.run()
    run.check()
    assert run.status["replay_checks"]["a"]["mismatches"] >= 1
    assert run.status["replay_checks"]["b"]["mismatches"] == 0


def test_configuration_guard(monkeypatch):
    """The streams are made before the run for the expected configuration: an I2C init that configures a sensor
    otherwise stops the run (here the stream is made for G byte first)."""
    import sim.testbench.system.run_verilator
    from sim.models.mt9d112.config import SensorConfig
    setup = _setup()
    g = setup.geometry
    monkeypatch.setattr(sim.testbench.system.run_verilator, "expected_sensor_config",
                        lambda geometry: SensorConfig(width=g.width, height=g.height, rgb565=True,
                                                      r_byte_first=False))
    with pytest.raises(SystemTimeout, match="camera a: the I2C init configured .*r_byte_first=True"):
        simulate(setup, _pair(setup), Verilator())


def test_a_device_that_does_not_answer_fails_the_init():
    """The models answer live: a CH7301C that NACKs its address leaves the DVI bus in error and no frame."""
    setup = _setup()
    run = VerilatorRun(setup, _pair(setup))
    run.models["dvi"][0].nack_address = True
    status = run.run()
    assert status["dvi_init_error"] and not status["dvi_init_done"] and status["cam_a_init_done"]
    assert "t_end_s" not in status and run.frames.shown == 0


def test_sink_reports_wrong_xclk_levels(base):
    """Bites: one recorded word with XCLK_P high a quarter period after the falling edge is an xclk violation at
    that clock; the frame is still rebuilt."""
    run = base.driver
    words = run.recording[:run.h.recorded].copy()
    words[1234] |= 1 << 30
    sink = feed_sink(words, HdmiSink(run.setup.timing))
    assert [(v.kind, v.clock) for v in sink.violations] == [("xclk", 1234)]
    assert sink.frames and np.array_equal(sink.frames[0], base.frame)


def test_recorder_word_fields():
    fields = decode(np.array([0xABC | 0x123 << 12 | 0b10101 << 24 | 0b01 << 29], dtype=np.uint32))
    assert {k: int(v[0]) for k, v in fields.items()} == {
        "first": 0xABC, "second": 0x123, "de": 1, "vsync": 0, "hsync": 1, "xclk_n_high": 0, "xclk_p_high": 1,
        "xclk_n_low": 1, "xclk_p_low": 0}


def test_build_key_follows_the_design(tmp_path, monkeypatch):
    """A cached build is found by the design's parameters and sources: the switch settings (inputs) keep the key,
    a design parameter or one changed line in a module the bench imports changes it; a module it does not import
    (the golden models, the runners) is not part of the key."""
    import shutil
    from sim.runners.verilator import build
    key = build.cache_key(_setup())
    assert build.cache_key(SystemSetup.small(disparity=DISPARITY + 1, rectification=0)) == key
    assert build.cache_key(SystemSetup.small(disparity=DISPARITY, rectification=RECTIFICATION, lock_cycles=17)) != key
    files = dict(build._design_files())
    assert {"hdl.system", "hdl.i2c_master", "board.export", "sim.models.i2c.bus", "sim.testbench.system.testbench"} <= set(files)
    assert not any(n.startswith(("golden", "sim.testbench.system.run_", "sim.runners.verilator", "bench")) for n in files)
    copies = {}
    for name, path in files.items():                # the same sources elsewhere: the same key
        copies[name] = tmp_path / name / path.name        # the file's own name: an __init__ stays a package's
        copies[name].parent.mkdir()
        shutil.copy(path, copies[name])
    found = build._module_file
    monkeypatch.setattr(build, "_module_file", lambda n: (n, copies[n]) if n in copies else found(n))
    assert build.cache_key(_setup()) == key
    source = copies["hdl.i2c_master"]
    source.write_text(source.read_text() + "\n# a change\n")
    assert build.cache_key(_setup()) != key


def test_testbench_refuses_values_that_do_not_fit(base):
    """A value wider than the port (Verilator expects the bits above a port's width clear) or a write to an output is
    refused before it reaches the model."""
    h = base.driver.h
    with pytest.raises(ValueError, match="does not fit .*8 bits"):
        h[("panel", "sw")] = 0x100
    with pytest.raises(ValueError, match="does not fit .*1 bits"):
        h[("bus", "dvi", "ext_sda_low")] = 2
    with pytest.raises(ValueError, match="is an output"):
        h["locked"] = 1


def test_the_testbench_has_every_port_of_the_exported_top(base):
    """The C++ testbench's ports are the exported top's (its signature flattened by board.export.flat_name, the
    design elaborated apart), with the same directions and widths: nothing in the route lists them, so a top that
    gains ports needs no change here."""
    from amaranth.hdl import Fragment, Shape
    from amaranth.lib import wiring
    from board.export import flat_name
    from sim.testbench.system.testbench import SystemTestbench
    run = base.driver
    design = SystemTestbench(clock_ports=True, **_setup().system_kwargs())
    want = {flat_name(path): (member.flow == wiring.In, Shape.cast(member.shape).width)
            for path, member, _ in design.signature.flatten(design)}
    Fragment.get(design, None)                      # elaborated, as an export would
    lib, handle = run.h._lib, run.h._h
    got = {name: (bool(lib.tb_port_is_input(handle, i)), lib.tb_port_width(handle, i))
           for name, i in run.h.ports.items()}
    assert got == want and not run.build.wide_ports


def test_ports_inc_leaves_ports_wider_than_64_bits_alone():
    """ports.inc from a Verilated header: member, Verilog name (escapes undone), direction and width of each port;
    a port wider than 64 bits gets a WIDE line (the testbench leaves it alone) rather than failing the build."""
    from sim.runners.verilator.build import ports_inc, wide_ports
    header = ("    VL_IN8(&clocks___05Fsync,0,0);\n    VL_OUT16(&ch7301c___05Fdata,11,0);\n"
              "    VL_IN64(&word,63,0);\n    VL_OUTW(&depth___05Frow,127,0,4);\n")
    text = ports_inc(header)
    assert text.splitlines() == ['PORT(clocks___05Fsync, "clocks__sync", true, 1)',
                                 'PORT(ch7301c___05Fdata, "ch7301c__data", false, 12)',
                                 'PORT(word, "word", true, 64)',
                                 'WIDE(depth___05Frow, "depth__row", false, 128)']
    assert wide_ports(text) == {"depth__row"}
    with pytest.raises(RuntimeError, match="no ports"):
        ports_inc("class Vsystem {};")


def test_a_still_pair_shows_a_whole_depth_map(base):
    """The cameras send the pair every frame, so a display frame's depth map can be computed while a capture
    overwrites the buffers: here the first one's is (rows withheld at the tear, the golden frame of that tear). The
    command line's policy runs display frames until one's depth map comes from complete camera frames and shows it:
    equal to the untorn golden frame, no row withheld; the verdict names it. (Bite: choosing the first frame fails
    the first assertion on the chosen frame.)"""
    setup = _setup()
    pair = _pair(setup)
    first = base.frames[0]
    assert first.verdict["withheld_rows"] > 0 and first.verdict["tear"] is not None
    result = simulate(setup, pair, Verilator(), policy="whole")
    shown = result.chosen
    assert shown.verdict["withheld_rows"] == 0 and shown.verdict["tear"] is None, result.verdict
    np.testing.assert_array_equal(shown.frame, setup.golden_frame(*pair.pairs[0]))
    k = result.verdict["chosen"]
    assert k == shown.index > 0 and all(w > 0 for w in result.verdict["withheld_rows"][:k]) and result.ok
    assert len(result.frames) == k + 1 and result.frame is shown.frame


def test_automatic_rectification_reports_the_offset_it_found():
    """A still pair with the rig's left image 12 sensor rows (3 buffer rows) low, in automatic rectification: the
    run shows a display frame with the offset locked and no row withheld, and reports the offset found (+3, the
    golden estimator's) and the first display frame that used it."""
    from sim.analysis.auto_rectification import expected_states
    from sim.testbed.sequence import moving_card, repeated_pair
    setup = SystemSetup.small(disparity=DISPARITY, rectification="auto")
    card = moving_card(setup, 1, vertical_offsets=[12])
    states = expected_states(setup, repeated_pair(*card.pairs[0], 4, setup))
    assert states[0].offset == 0 and states[-1].offset == 3          # locks after a few camera frames
    result = simulate(setup, still_pair(*card.pairs[0], setup), Verilator(), policy="whole")
    verdict, shown = result.verdict, result.chosen
    assert verdict["auto_offset"] == 3 and shown.settings["auto_rectification"]["locked"] and result.ok
    assert shown.verdict["withheld_rows"] == 0
    assert verdict["auto_offset_first_frame"] == min(f.index for f in result.frames if f.settings["rectification"] == 3)
    np.testing.assert_array_equal(shown.frame, setup.golden_frame(*card.pairs[0], in_use=3))


def test_run_command_shows_and_names_the_whole_frame(tmp_path, capsys):
    """``stereodepth run LEFT RIGHT --small``: hdmi_frame.png is the first display frame without withheld depth rows,
    the summary and result.json name it; with ``--frames 2`` the same pair accepts a ``--ground-truth`` (every
    frame's table row then has bad > 2)."""
    import json
    from PIL import Image
    from stereodepth.cli import main
    from sim.testbench.system.run_cocotb import DEFAULT_PAIR
    out = tmp_path / "one"
    assert main(["run", *map(str, DEFAULT_PAIR), "--small", "--disparity", str(DISPARITY), "--rectification",
                 str(RECTIFICATION), "--out", str(out)]) == 0
    verdict = json.loads((out / "result.json").read_text())["verdict"]
    k = verdict["chosen"]
    assert k > 0 and verdict["withheld_rows"][k] == 0 and verdict["policy"] == "whole"
    assert f"display frame {k} shown: the first whose depth map comes from complete camera frames" \
        in capsys.readouterr().out
    setup = _setup()
    np.testing.assert_array_equal(np.asarray(Image.open(out / "hdmi_frame.png").convert("RGB")),
                                  setup.golden_frame(*_pair(setup).pairs[0]))
    size = Image.open(DEFAULT_PAIR[1]).size
    with open(tmp_path / "truth.pfm", "wb") as f:
        f.write(b"Pf\n%d %d\n-1.0\n" % size)
        np.full((size[1], size[0]), 100.0, "<f4").tofile(f)
    frames = tmp_path / "frames"
    main(["run", *map(str, DEFAULT_PAIR), "--small", "--frames", "2", "--ground-truth", str(tmp_path / "truth.pfm"),
          "--out", str(frames)])
    rows = json.loads((frames / "result.json").read_text())["frames"]
    assert rows and all(r["bad2"] is not None for r in rows if r["depth_frame"] is not None and r["depth_frame"] >= 0)
    assert any(r["bad2"] is not None for r in rows)


def test_a_process_out_of_static_tls_says_what_to_do(monkeypatch, tmp_path):
    """Each Verilator build keeps its thread-local state in static TLS: a process that has no more says so in one
    line and names the glibc tunable the Makefile exports; any other load error is raised as it is."""
    import ctypes
    from sim.runners.verilator import ctestbench

    def refuse(message):
        def load(path):
            raise OSError(message)
        return load
    monkeypatch.setattr(ctypes, "CDLL", refuse(f"{tmp_path}/lib.so: cannot allocate memory in static TLS block"))
    with pytest.raises(RuntimeError, match=f"no static TLS left .* {ctestbench.STATIC_TLS_ENV}, as make does"):
        ctestbench._library(tmp_path / "lib.so")
    monkeypatch.setattr(ctypes, "CDLL", refuse("cannot open shared object file"))
    with pytest.raises(OSError, match="cannot open shared object file"):
        ctestbench._library(tmp_path / "lib.so")
    from pathlib import Path
    makefile = (Path(__file__).resolve().parents[1] / "Makefile").read_text()
    assert f"export {ctestbench.STATIC_TLS_ENV.replace('=', ' ?= ', 1)}\n" in makefile
