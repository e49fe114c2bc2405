"""The Virtex-5 primitive models (sim/board/xilinx) against their documented behaviour, on Icarus and Verilator.

``tests/cocotb/cocotb_xilinx.py`` has one cocotb test per group of primitives (see its docstring). Each group
is also run on a deliberately wrong variant of its model (:data:`MUTANTS`, one textual change to the model
file): the test must fail on every one of them, so none of the checks can pass vacuously.
"""

from pathlib import Path

import pytest

from sim.runners.cocotb import run_cocotb, simulator_available

REPO_ROOT = Path(__file__).resolve().parents[1]
from sim.board.xilinx import PRIMITIVES, VERILATOR_ARGS, model_sources

BENCH = REPO_ROOT / "tests" / "cocotb" / "xilinx_models_tb.v"
GROUPS = ("io_buffers", "flip_flops", "oddr", "dcm", "pll", "pll_base")

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
    ("dcm", "DCM_ADV", "1.0 * CLKFX_DIVIDE / CLKFX_MULTIPLY", "1.0 * CLKFX_MULTIPLY / CLKFX_DIVIDE",
     "CLKFX = CLKIN x D / M"),
    ("dcm", "xil_clocking", "t_ready = $realtime + LOCK_TIME_NS;", "t_ready = $realtime;", "no lock time"),
    ("dcm", "DCM_ADV", "g == 1 ? 0.25 :", "g == 1 ? 0.0 :", "CLK90 in phase"),
    ("dcm", "DCM_ADV", ".FEEDBACK(FEEDBACK)", ".FEEDBACK(1'b0)", "DLL locks without feedback"),
    ("dcm", "DCM_ADV", "START_FRACTION(SHIFT < 0.0 ? SHIFT + 1.0 : SHIFT)", "START_FRACTION(0.0)",
     "PHASE_SHIFT ignored"),
    ("pll", "PLL_ADV", ".PHASE((PH < 0.0 ? PH + 360.0 : PH) / 360.0)", ".PHASE(0.0)", "CLKOUTn_PHASE ignored"),
    ("pll", "PLL_ADV", ".RATIO(1.0 * DIVCLK_DIVIDE * DIV / CLKFBOUT_MULT)", ".RATIO(1.0 * DIV / CLKFBOUT_MULT)",
     "DIVCLK_DIVIDE ignored"),
    ("pll", "PLL_ADV", ".DUTY(DUTY)) gen (", ".DUTY(0.5)) gen (", "CLKOUTn_DUTY_CYCLE ignored"),
    ("pll", "PLL_ADV", ".FEEDBACK(1'b1)", ".FEEDBACK(1'b0)", "PLL locks without feedback"),
    ("pll", "xil_clocking", "      q = 1'b0;\n      k = k + 1;", "      k = k + 1;", "output never falls (stuck high)"),
    ("pll", "xil_clocking", "period = (t_edge - t_first) / MEASURE_EDGES;", "period = (t_edge - t_first) / 10;",
     "input period mis-measured"),
    ("pll_base", "PLL_BASE", ".CLKOUT1_PHASE(CLKOUT1_PHASE)", ".CLKOUT1_PHASE(0.0)", "PLL_BASE CLKOUT1_PHASE ignored"),
    ("pll_base", "PLL_BASE", ".CLKOUT2_DIVIDE(CLKOUT2_DIVIDE)", ".CLKOUT2_DIVIDE(CLKOUT3_DIVIDE)",
     "PLL_BASE CLKOUT2 divided as CLKOUT3"),
]


def _skip_unless(simulator):
    if not simulator_available(simulator):
        pytest.skip(f"{simulator} not available")


def _run(simulator, sources, testcase=None):
    return run_cocotb(BENCH.read_text(), name="xilinx_models_tb", test_module="cocotb_xilinx",
                      simulator=simulator, extra_sources=sources, testcase=testcase,
                      build_args=VERILATOR_ARGS if simulator == "verilator" else ())


@pytest.mark.parametrize("simulator", [pytest.param("verilator", marks=pytest.mark.slow), "icarus"])
def test_primitive_models(simulator):
    """Each group's checks (Verilator in the slow set: the default suite runs these models on Verilator inside
    the board top, tests/test_board_top.py)."""
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
