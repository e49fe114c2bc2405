"""The GTKWave save files the tools write (sim/waves/gtkw.py) open in GTKWave with every listed signal found in the VCD,
on the window they ask for, with their markers at the events they name, and with names as the design gives them.

Checked by opening them in GTKWave itself, headless (``sim/waves/gtkwave_check.py``); skipped where GTKWave or
xvfb-run is missing (``.ci/run`` installs both). The whole system's save file is opened in tests/test_system.py's
Amaranth run, which writes it; here it is written over a short run for its names.
"""

import re
import shutil

import pytest

from spec.video import SMALL_TIMING
from sim.waves import gtkwave_check
from sim.waves.gtkw import I2C_FILTER, changes, read_vars

needs_gtkwave = pytest.mark.skipif(not gtkwave_check.available(), reason="gtkwave or xvfb-run not installed")


@pytest.fixture(scope="module")
def display_waves(tmp_path_factory):
    from sim.testbench.display import write_display_waves
    return write_display_waves(SMALL_TIMING, tmp_path_factory.mktemp("waves") / "display.vcd")


@needs_gtkwave
def test_display_save_file_shows_every_signal(display_waves):
    gtkw = display_waves["GTKWave"]
    want = gtkwave_check.listed(gtkw)
    shown, facilities = gtkwave_check.displayed(gtkw)
    assert len(want) >= 16 and facilities >= len(want)
    assert shown == want


@needs_gtkwave
def test_a_missing_signal_is_caught(display_waves, tmp_path):
    """The check can fail: a save file naming a signal the VCD lacks shows one signal fewer."""
    gtkw = tmp_path / "bad.gtkw"
    shutil.copy(display_waves["VCD"], tmp_path / "display.vcd")
    text = display_waves["GTKWave"].read_text().replace(str(display_waves["VCD"]), str(tmp_path / "display.vcd"))
    first = gtkwave_check.listed(display_waves["GTKWave"])[0]
    gtkw.write_text(text.replace(first + "\n", first + "\nbench.no_such_signal\n", 1))
    want = gtkwave_check.listed(gtkw)
    shown, _ = gtkwave_check.displayed(gtkw)
    assert "bench.no_such_signal" in want and "bench.no_such_signal" not in shown
    assert len(shown) == len(want) - 1


# --- what the save files open on, and the names they show --------------------------------------------------------

COLLISION = re.compile(r"\$\d+")


def first_change(vcd, name, value):
    """First time the dump variable ``name`` (full name) equals ``value``, read from the VCD directly."""
    variables, _ = read_vars(vcd)
    ident = next(v.ident for v in variables if v.full == name)
    seen, _ = changes(vcd, {ident})
    return next(t for t, v in seen[ident] if int(v, 2) == value)


@needs_gtkwave
def test_display_save_file_opens_on_the_vsync_window(display_waves):
    gtkw, vcd = display_waves["GTKWave"], display_waves["VCD"]
    first, last = gtkwave_check.window(gtkw)
    end = changes(vcd, ())[1]
    assert first == 0 and 0.95 * end <= last <= 1.1 * end         # the whole window, not a femtosecond
    marks = gtkwave_check.markers(gtkw)
    assert set(marks) == {"last active line end", "vsync", "vsync end", "vsync on the pins"}
    vsync = "bench.top.sync_gen.vsync"
    assert marks["vsync"] == first_change(vcd, vsync, int(SMALL_TIMING.vsync_positive))
    assert first < marks["vsync"] < marks["vsync end"] < last


@pytest.fixture(scope="module")
def system_save_file(tmp_path_factory):
    """The system's save file over a short run (the names and groups do not depend on the run's length)."""
    from amaranth.sim import Simulator
    from sim.waves.gtkw import recording
    from sim.testbench.system.testbench import SystemTestbench
    from sim.testbench.system.setup import SystemSetup
    from sim.testbench.system.waves import system_waves
    bench = SystemTestbench(**SystemSetup.small().system_kwargs())
    sim = Simulator(bench)
    for domain, hz in (("sync", 100e6), ("pix", 25e6), ("cam_a", 80e6), ("cam_b", 80e6)):
        sim.add_clock(1 / hz, domain=domain)
    out = tmp_path_factory.mktemp("system")
    with recording(sim, out / "system.vcd", out / "system.gtkw", system_waves(bench)):
        sim.run_until(2e-6)
    return out / "system.gtkw"


def test_system_save_file_decodes_the_buses_and_names_the_states(system_save_file):
    text = system_save_file.read_text()
    assert text.count(f"^<1 {I2C_FILTER}") == 3 and I2C_FILTER.stat().st_mode & 0o111
    names = gtkwave_check.listed(system_save_file)
    fsms = [n for n in names if n.endswith(".fsm_state")]
    # the init sequencer and its I2C master, and the vertical-offset search
    assert len(fsms) == 3 and any(".vertical_offset." in n for n in fsms)
    assert len(names) == len(set(names)) + 6                          # each bus's two lines twice: shown, decoded


def test_no_saved_trace_has_a_collision_suffix(system_save_file, display_waves):
    """No listed trace carries a ``$NN`` suffix: every signal shown has its plain name in the module of the block
    that owns it (sim/waves/gtkw.py shows that one)."""
    suffixed = [n for gtkw in (system_save_file, display_waves["GTKWave"]) for n in gtkwave_check.listed(gtkw)
                if COLLISION.search(n)]
    assert suffixed == []


def test_exported_system_ports_have_no_collision_suffix():
    from board.export import export_verilog
    from sim.testbench.system.testbench import SystemTestbench
    from sim.testbench.system.setup import SystemSetup
    text = export_verilog(SystemTestbench(clock_ports=True, **SystemSetup.small().system_kwargs()), "system")
    header = text[text.index("module system("):]
    ports = re.findall(r"^\s*(?:input|output|inout)\s+(?:wire\s+|reg\s+)?(?:\[\d+:0\]\s+)?(\S+);", header, re.M)
    assert len(ports) > 40
    assert [p for p in ports if "$" in p] == []


def test_a_named_state_machine_gets_a_row_by_state_name(tmp_path):
    """An FSM given a name (the depth engine's ``m.FSM(name="engine")``) has its state in ``engine_state``."""
    from amaranth import Module, Signal
    from amaranth.sim import Simulator
    from sim.waves.gtkw import recording
    m = Module()
    go = Signal()
    with m.FSM(name="engine"):
        with m.State("IDLE"):
            m.d.sync += go.eq(1)
            m.next = "RUN"
        with m.State("RUN"):
            m.next = "IDLE"
    sim = Simulator(m)
    sim.add_clock(1e-6)
    with recording(sim, tmp_path / "x.vcd", tmp_path / "x.gtkw", {"go": [go]}):
        sim.run_until(5e-6)
    assert [n for n in gtkwave_check.listed(tmp_path / "x.gtkw") if n.endswith("_state")] == ["bench.top.engine_state"]
