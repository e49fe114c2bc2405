"""The GTKWave translate filters of the state machines (sim/waves/fsm_filters.py) name every state the RTL can be in.

Checked against two things the generator does not read: the state names written in the RTL's source (``m.State``
arguments, read with ``ast``; the I2C master's ``release_scl(prefix, ...)`` and ``hold_then_release(prefix, ...)``
helpers make ``<prefix>_HOLD``, ``<prefix>_SETUP`` and ``<prefix>_WAIT_HIGH`` from f-strings, expanded here from
their call sites, also where one helper hands its prefix on to the other) and the encoded values the exported
Verilog tests ``fsm_state`` for, with the register's reset value naming the first state.
"""

import ast
import dataclasses
import re
from pathlib import Path

import pytest

from hdl.depth import DepthEngine
from hdl.i2c_init import ErrorCode, InitSequencer
from hdl.i2c_master import Cmd, I2CMaster
from hdl.init_tables import MT9D112_TABLE
from spec.depth import SMALL_DEPTH, THREE_PATHS
from spec.sensor import SMALL_SENSOR
from sim.waves.fsm_filters import enum_states, state_machines, write_filter

HDL = Path(__file__).resolve().parent.parent / "hdl"


def source_states(path):
    """State names of the ``m.State(...)`` calls in a source file, in source order; f-string names made inside a
    helper function (or method) are expanded with the constant first argument of each call of that helper, or,
    where a helper passes its own parameter on, with the prefixes of its own call sites."""
    tree = ast.parse(Path(path).read_text())
    funcs = [f for f in ast.walk(tree) if isinstance(f, ast.FunctionDef)]
    names, templates, calls = [], {}, []
    for func in funcs:
        for node in ast.walk(func):
            if not isinstance(node, ast.Call) or not node.args:
                continue
            callee = getattr(node.func, "id", None) or getattr(node.func, "attr", None)
            arg = node.args[0]
            if callee == "State" and isinstance(arg, ast.Constant):
                names.append(arg.value)
            elif callee == "State" and isinstance(arg, ast.JoinedStr):
                templates.setdefault(func.name, []).append(arg)
            else:
                calls.append((func, callee, arg))

    def prefixes(helper):
        out = []
        for func, callee, arg in calls:
            if callee != helper:
                continue
            if isinstance(arg, ast.Constant):
                out.append(arg.value)
            elif isinstance(arg, ast.Name) and arg.id in (a.arg for a in func.args.args):
                out += prefixes(func.name)              # the helper's caller hands its own prefix on
        return out

    for helper, strings in templates.items():
        for prefix in prefixes(helper):
            for template in strings:
                names.append("".join(prefix if isinstance(v, ast.FormattedValue) else v.value
                                     for v in template.values))
    return names


def verilog_encodings(design, name, state="fsm_state"):
    """``(values the state register is tested for, reset value)`` in the top module of the Verilog: the labels of
    the ``case`` statements on it and its comparisons with constants (Yosys folds some states into defaults).
    ``state``: the register's name (``<fsm name>_state``)."""
    from amaranth.back import verilog
    text = verilog.convert(design, name=name, emit_src=False)
    top = text[text.index(f"module {name}("):]
    top = top[:top.index("endmodule")]
    reset = int(re.search(rf"reg \[\d+:0\] {state} = \d+'h([0-9a-f]+);", top)[1], 16)
    values = set()
    for block in re.findall(rf"casez \({state}\)(.*?)endcase", top, re.S):
        values |= {int(v, 16) for v in re.findall(r"^\s+\d+'h([0-9a-f]+):", block, re.M)}
    values |= {int(v, 16) for v in re.findall(rf"{state} == \d+'h([0-9a-f]+)", top)}
    return values | {reset}, reset


@pytest.mark.parametrize("block, source, state, absent", [
    (lambda: I2CMaster(clk_hz=1_000_000), "i2c_master.py", "fsm_state", ()),
    (lambda: InitSequencer(MT9D112_TABLE, clk_hz=1_000_000), "i2c_init.py", "fsm_state", ()),
    # the two-path engine has no backward phase; the three-path one every state of the source
    (lambda: DepthEngine(SMALL_SENSOR, SMALL_DEPTH), "depth/engine.py", "engine_state", ("BACK_DRAIN", "REPLAY")),
    (lambda: DepthEngine(SMALL_SENSOR, dataclasses.replace(SMALL_DEPTH, paths=THREE_PATHS)), "depth/engine.py",
     "engine_state", ()),
])
def test_every_state_is_named_as_in_the_rtl(block, source, state, absent):
    fsm = state_machines(block())[0]
    assert fsm.path == ("top",) and fsm.signal == state
    expected = [name for name in source_states(HDL / source) if name not in absent]
    assert sorted(fsm.states.values()) == sorted(expected) and len(set(expected)) == len(expected)
    values, reset = verilog_encodings(block(), "dut", state)
    assert set(fsm.states) == values            # every value the RTL's case statements test has a name
    assert fsm.states[reset] == expected[0]     # the reset state is the first one the source defines
    assert max(fsm.states) < 2 ** fsm.width


def test_the_system_has_four_state_machines_with_filters(tmp_path):
    """The init sequencer (all three buses), its I2C master, the depth engine's pass control and the
    vertical-offset search."""
    from sim.testbench.system.testbench import SystemTestbench
    from sim.testbench.system.setup import SystemSetup
    fsms = state_machines(SystemTestbench(**SystemSetup.small().system_kwargs()))
    paths = sorted(".".join(f.path[-2:]) for f in fsms)
    assert paths == sorted(["system.i2c_init", "i2c_init.master"]
                           + ["display.engine", "system.vertical_offset"])
    for f in fsms:
        lines = write_filter(tmp_path / f"{'.'.join(f.path)}.txt", f.states).read_text().splitlines()
        assert len(lines) == len(f.states)
        assert all(line == f"{v} {f.states[v]}" for v, line in zip(sorted(f.states), lines))


def test_enumerations():
    assert enum_states(Cmd) == {0: "START", 1: "WRITE", 2: "READ", 3: "STOP"}
    assert enum_states(ErrorCode)[ErrorCode.POLL.value] == "POLL"


def test_a_signal_with_another_decoder_is_not_a_state_machine():
    from amaranth import Module, Signal
    from amaranth.lib import wiring
    from amaranth.lib.wiring import Out

    class Odd(wiring.Component):
        out: Out(2)

        def elaborate(self, platform):
            m = Module()
            odd = Signal(2, decoder=lambda v: f"v{v}")
            m.d.sync += [odd.eq(odd + 1), self.out.eq(odd)]
            return m
    assert state_machines(Odd()) == []
