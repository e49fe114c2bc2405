"""The Virtex-5 primitive models (sim/xilinx) against their documented behaviour, on Icarus and Verilator.

``tests/cocotb/cocotb_xilinx.py`` has one cocotb test per group of primitives (see its docstring). Each group
is also run on a deliberately wrong variant of its model (:data:`MUTANTS`, one textual change to the model
file): the test must fail on every one of them, so none of the checks can pass vacuously.
"""

from pathlib import Path

import pytest

from sim.cocotb_runner import REPO_ROOT, SIMULATORS, run_cocotb, simulator_available
from sim.xilinx import PRIMITIVES, VERILATOR_ARGS, model_sources

BENCH = REPO_ROOT / "tests" / "cocotb" / "xilinx_models_tb.v"
GROUPS = ("io_buffers", "flip_flops", "oddr", "dcm", "pll")

#: (test group, primitive, text in the model, replacement, what the mutant gets wrong)
MUTANTS = [
    ("io_buffers", "IBUF", "assign O = I;", "assign O = 1'b0;", "IBUF output stuck"),
    ("io_buffers", "BUFG", "assign O = I;", "assign O = ~I;", "BUFG inverts"),
    ("io_buffers", "OBUFT", "assign O = T ? 1'bz : I;", "assign O = I;", "OBUFT never releases"),
    ("io_buffers", "IOBUF", "assign O = IO;", "assign O = I;", "IOBUF reads its own input, not the pad"),
    ("flip_flops", "FDCE", "else if (CE)", "else", "FDCE ignores CE"),
    ("flip_flops", "FDPE", "always @(posedge C or posedge PRE)", "always @(posedge C)", "FDPE preset synchronous"),
    ("oddr", "ODDR", "q <= SAME ? d2_held : D2;", "q <= D2;", "SAME_EDGE behaves as OPPOSITE_EDGE"),
    ("oddr", "ODDR", "q <= SAME ? d2_held : D2;", "q <= d2_held;", "OPPOSITE_EDGE behaves as SAME_EDGE"),
    ("oddr", "ODDR", "    if (ASYNC) begin", "    if (1) begin", "SRTYPE SYNC acts asynchronously"),
    ("oddr", "ODDR", "    q = INIT;", "    q = 1'b0;", "INIT ignored"),
    ("dcm", "DCM_ADV", "default: period_of = t_in * CLKFX_DIVIDE / CLKFX_MULTIPLY;",
     "default: period_of = t_in * CLKFX_MULTIPLY / CLKFX_DIVIDE;", "CLKFX = CLKIN x D / M"),
    ("dcm", "DCM_ADV", "t_ready = $realtime + SIM_LOCK_TIME_NS;", "t_ready = $realtime;", "no lock time"),
    ("dcm", "DCM_ADV", "      1: offset_of = t_in / 4.0;", "      1: offset_of = 0.0;", "CLK90 in phase"),
    ("dcm", "DCM_ADV", "while (FEEDBACK && fb_edges < 2", "while (0", "locks without feedback"),
    ("pll", "PLL_ADV", "first = t0 + period * phase_of(g) / 360.0;", "first = t0;", "CLKOUTn_PHASE ignored"),
    ("pll", "PLL_ADV", "vco_period = period_in * DIVCLK_DIVIDE / CLKFBOUT_MULT;",
     "vco_period = period_in / CLKFBOUT_MULT;", "DIVCLK_DIVIDE ignored"),
    ("pll", "PLL_ADV", "high = period * duty_of(g);", "high = period / 2.0;", "CLKOUTn_DUTY_CYCLE ignored"),
    ("pll", "PLL_ADV", "while (fb_edges < 2 && RST === 1'b0)", "while (0)", "locks without feedback"),
    ("pll", "PLL_ADV", "          q = 1'b0;\n          k = k + 1;", "          k = k + 1;",
     "output never falls (stuck high)"),
]


def _skip_unless(simulator):
    if not simulator_available(simulator):
        pytest.skip(f"{simulator} not available")


def _run(simulator, sources, testcase=None):
    return run_cocotb(BENCH.read_text(), name="xilinx_models_tb", test_module="cocotb_xilinx",
                      simulator=simulator, extra_sources=sources, testcase=testcase,
                      build_args=VERILATOR_ARGS if simulator == "verilator" else ())


@pytest.mark.parametrize("simulator", SIMULATORS)
def test_primitive_models(simulator):
    _skip_unless(simulator)
    _run(simulator, model_sources())


def _mutant_sources(tmp_path, primitive, old, new):
    sources = []
    for path in model_sources():
        if path.stem == primitive:
            text = path.read_text()
            assert text.count(old) == 1, f"mutation text found {text.count(old)} times in {path.name}"
            path = Path(tmp_path) / path.name
            path.write_text(text.replace(old, new))
        sources.append(path)
    return sources


@pytest.mark.parametrize("group, primitive, old, new, what", MUTANTS, ids=[m[4] for m in MUTANTS])
def test_wrong_model_is_caught(tmp_path, group, primitive, old, new, what):
    _skip_unless("icarus")
    with pytest.raises(AssertionError):
        _run("icarus", _mutant_sources(tmp_path, primitive, old, new), testcase=group)


def test_every_primitive_has_a_mutant():
    assert {m[1] for m in MUTANTS} >= set(PRIMITIVES) - {"IBUFG", "OBUF"}
