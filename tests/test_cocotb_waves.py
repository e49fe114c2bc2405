"""A cocotb run with ``STEREO_WAVES=1`` leaves, beside its dump in its own test directory, a save file that GTKWave
opens on the whole run, listing only signals the dump holds, with the state machines and enumerations by name and
markers at the events the run names (sim/waves/cocotb.py), on Verilator (VCD) and Icarus (FST).

The run: the I2C sequencer testbench (tests/cocotb/cocotb_i2c.py), its short fault test (the MT9D112 NACKs a data
byte, the CH7301C bus has no device: both sequencers end in ERROR). What the save file asks for is checked against
the dump as GTKWave loads it and as :func:`sim.waves.gtkw.changes` reads it.
"""

import re

import pytest

from hdl.i2c_init import InitSequencer
from hdl.init_tables import CH7301C_TABLE, MT9D112_TABLE
from sim.waves import gtkwave_check
from sim.runners.cocotb import run_cocotb, verilator_dump_names
from sim.waves.gtkw import I2C_FILTER, changes, read_vars
from sim.models.i2c.bus import I2CBench, i2c_bench_waves

needs_gtkwave = pytest.mark.skipif(not gtkwave_check.available(), reason="gtkwave or xvfb-run not installed")
PARAMS = dict(clk_hz=1_000_000, retries=3, retry_delay_us=200, timeout_us=2000)


def nack_run(simulator):
    kw = {k: v for k, v in PARAMS.items() if k != "clk_hz"}
    bench = I2CBench({b: InitSequencer(table, clk_hz=PARAMS["clk_hz"], **kw)
                      for b, table in (("cam", MT9D112_TABLE), ("dvi", CH7301C_TABLE))})
    return run_cocotb(bench, name="i2c_bench", test_module="cocotb_i2c", simulator=simulator, params=PARAMS,
                      testcase="test_faults_nack", run_waves=i2c_bench_waves(("cam", "dvi")))


def translated(gtkw):
    """``{dump name: {value: name}}`` of the traces a save file shows through a translate filter file."""
    lines = gtkw.read_text().splitlines()
    out = {}
    for i, line in enumerate(lines):
        if line.startswith("^1 "):
            name = re.sub(r"^\+\{[^}]*\} ", "", lines[i + 1])
            table = (pair.split(" ", 1) for pair in open(line[3:]).read().splitlines())
            out[name] = {int(v): n for v, n in table}
    return out


def values(dump, full_name):
    variables, _ = read_vars(dump)
    ident = next(v.ident for v in variables if v.full == full_name)
    return {int(v, 2) for _, v in changes(dump, {ident})[0][ident]}


@needs_gtkwave
@pytest.mark.parametrize("simulator", [pytest.param("verilator", marks=pytest.mark.slow), "icarus"])
def test_a_cocotb_run_with_waves_leaves_a_save_file_gtkwave_opens(simulator, monkeypatch):
    """(Verilator in the slow set: its traced build is most of the test; its dump names are checked without a build
    by :func:`test_verilator_dump_names_leaves_plain_names_alone`.)"""
    monkeypatch.setenv("STEREO_WAVES", "1")
    test_dir = nack_run(simulator)
    gtkw, dump = test_dir / "dump.gtkw", test_dir / ("dump.fst" if simulator == "icarus" else "dump.vcd")
    assert f'[dumpfile] "{dump}"' in gtkw.read_text()           # this run's dump, not a shared one
    want = gtkwave_check.listed(gtkw)
    shown, facilities = gtkwave_check.displayed(gtkw)
    assert shown == want and facilities > len(want) > 20        # every listed signal is in the dump
    assert [n for n in want if "$" in n] == []                  # names as the design gives them
    first, last = gtkwave_check.window(gtkw)
    end = changes(dump, ())[1]
    assert first == 0 and 0.95 * end <= last <= 1.1 * end       # the whole run

    filters = translated(gtkw)
    fsms = sorted(n for n in filters if "fsm_state" in n)
    assert [n.split(".")[1:-1] for n in fsms] == [["cam"], ["cam", "master"], ["dvi"], ["dvi", "master"]]
    for name, states in filters.items():                        # every value the simulator dumped has a name
        assert values(dump, name) <= set(states), name
    cam = filters[fsms[0]]
    assert {cam[v] for v in values(dump, fsms[0])} >= {"WAIT", "ERROR"}
    assert gtkw.read_text().count(f"^<1 {I2C_FILTER}") == 2     # both buses decoded

    marks = gtkwave_check.markers(gtkw)
    assert set(marks) == {"cam init error", "dvi init error"}   # neither sequencer completes its table
    for bus in ("cam", "dvi"):
        variables, _ = read_vars(dump)
        ident = next(v.ident for v in variables if v.full == f"i2c_bench.status__{bus}__error")
        assert marks[f"{bus} init error"] == next(t for t, v in changes(dump, {ident})[0][ident] if v == "1")


def test_verilator_dump_names_leaves_plain_names_alone():
    text = ("module top(a, b);\n  reg \\$auto$verilog_backend.cc:2355:dump_module$1  = 0;\n"
            "  wire [9:0] \\rd__data.count ;\n  wire [3:0] \\$12 ;\n  input a;\n  $display(\"x\\n.y\");\nendmodule\n")
    fixed = verilator_dump_names(text)
    assert "\\$auto$verilog_backend_cc_2355_dump_module$1  = 0;" in fixed and "\\rd__data_count ;" in fixed
    assert fixed.replace("_cc_2355_", ".cc:2355:").replace("rd__data_count", "rd__data.count") == text
