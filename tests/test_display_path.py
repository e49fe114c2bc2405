"""The display path (SyncGenerator -> PatternGenerator -> CH7301COutput) against the golden pattern and CEA-861.

* Amaranth simulator: the whole path through the HDMI sink (small modes), the pattern generator at 1080p
  positions, the CH7301C output stage bit by bit against the datasheet's IDF 0 table.
* cocotb: one run per simulator on the small mode (two frames) rebuilt from the dual-edge bus equals the golden
  frame bit for bit, and both the sink and the edge timestamps measure exactly the mode's intervals. Slow: a full
  1080p frame on Verilator, against the CEA-861 1080p60 intervals.
* The Virtex-5 board variant: it elaborates to ODDR/OBUFDS primitives, and with behavioural models of those
  two primitives (written below from the Virtex-5 documentation) it carries the same frames on Icarus.
"""

import dataclasses
import random
import re

import numpy as np
import pytest

from golden.video import pattern_frame
from hdl.ch7301c_output import CH7301COutput
from hdl.display_path import DISPLAY_PATH_LATENCY, DisplayPath
from spec.video import CEA_1080P60, SMALL_TIMING
from hdl.pattern_gen import PatternGenerator
from sim.runners.amaranth import simulate
from board.export import amaranth_verilog as export_verilog
from sim.testbench.display import run_display_cocotb
from sim.models.ch7301c.hdmi_sink import HdmiSink, amaranth_sink_testbench

#: CEA-861 1920x1080p60 (VIC 16) intervals as the sink and the edge timer measure them, written out here
#: from the standard (not taken from spec).
CEA_1080P60_INTERVALS = {
    "line_clocks": 2200, "hsync_clocks": 44, "h_front": 88, "h_back": 148, "active_pixels": 1920,
    "vsync_clocks": 5 * 2200, "vsync_lines": 5, "v_front": 4, "v_back": 36, "active_lines": 1080,
    "frame_clocks": 2200 * 1125,
}


def intervals(t):
    return {"line_clocks": t.h_total, "hsync_clocks": t.h_sync, "h_front": t.h_front, "h_back": t.h_back,
            "active_pixels": t.h_active, "vsync_clocks": t.v_sync * t.h_total, "vsync_lines": t.v_sync,
            "v_front": t.v_front, "v_back": t.v_back, "active_lines": t.v_active,
            "frame_clocks": t.clocks_per_frame}


def split_idf0(rgb):
    """The two CH7301C words of a 24-bit pixel, bit by bit from the datasheet's IDF 0 table."""
    r, g, b = (rgb >> 16) & 0xFF, (rgb >> 8) & 0xFF, rgb & 0xFF
    first = second = 0
    for i in range(8):
        first |= ((b >> i) & 1) << i                  # D[7:0]  = B[7:0]  (rising edge)
        second |= ((r >> i) & 1) << (4 + i)           # D[11:4] = R[7:0]  (falling edge)
    for i in range(4):
        first |= ((g >> i) & 1) << (8 + i)            # D[11:8] = G[3:0]  (rising edge)
        second |= ((g >> (4 + i)) & 1) << i           # D[3:0]  = G[7:4]  (falling edge)
    return first, second


def assert_ran(test_dir, names):
    """The cocotb tests ``names`` ran and passed (a skipped test would otherwise pass silently)."""
    import xml.etree.ElementTree as ET
    cases = {c.get("name"): c for c in ET.parse(test_dir / "results.xml").iter("testcase")}
    for name in names:
        assert name in cases, f"cocotb test {name} did not run ({sorted(cases)})"
        bad = [e.tag for e in cases[name] if e.tag in ("failure", "error", "skipped")]
        assert not bad, f"cocotb test {name}: {bad}"


def sink_run_amaranth(timing, frames=2, **dut_kwargs):
    dut = DisplayPath(timing, **dut_kwargs)
    sink = HdmiSink(timing)
    clocks = frames * timing.clocks_per_frame + DISPLAY_PATH_LATENCY + 1
    simulate(dut, clocks={"sync": timing.pixel_hz}, testbenches=[amaranth_sink_testbench(sink, dut.ch7301c, clocks)])
    return sink


# -- Amaranth simulator: the whole path ---------------------------------------------------------------------

@pytest.mark.parametrize("timing", [
    SMALL_TIMING,
    dataclasses.replace(SMALL_TIMING, h_active=40, h_front=2, h_sync=6, h_back=3, v_active=9, v_front=1,
                        v_sync=3, v_back=2, hsync_positive=False, vsync_positive=False),
], ids=["small", "small-negative-syncs"])
def test_display_path_amaranth_frames_equal_golden(timing):
    sink = sink_run_amaranth(timing, frames=2)
    sink.check()
    assert sink.frames_completed == 2
    for frame in sink.frames:
        assert np.array_equal(frame, pattern_frame(timing))
    for name, value in intervals(timing).items():
        assert set(sink.observed[name]) == {value}, (name, sink.observed[name])


# -- Amaranth simulator: the blocks -------------------------------------------------------------------------

def test_pattern_generator_1080p_positions():
    """Every pixel of the rows and columns where the pattern changes region, at 1080p, 1 clock latency."""
    t = CEA_1080P60
    golden = pattern_frame(t)
    bar_rows = (2 * t.v_active) // 3
    positions = [(x, y) for y in (0, bar_rows - 1, bar_rows, bar_rows + 1, t.v_active - 1)
                 for x in range(t.h_active)]
    positions += [(x, y) for x in (0, 1, 239, 240, t.h_active - 1) for y in range(t.v_active)]
    positions += [(t.h_active, 0), (t.h_total - 1, 5), (3, t.v_active), (100, t.v_total - 1)]   # blanking
    dut = PatternGenerator(t)
    errors = []

    async def bench(ctx):
        for x, y in positions:
            de = int(x < t.h_active and y < t.v_active)
            hs, vs = (x + y) & 1, x & 1
            for sig, value in ((dut.timing.x, x), (dut.timing.y, y), (dut.timing.de, de),
                               (dut.timing.hsync, hs), (dut.timing.vsync, vs)):
                ctx.set(sig, value)
            await ctx.tick()            # the output registers now hold this position's pixel
            want = int.from_bytes(bytes(golden[y, x]), "big") if de else 0
            got = (ctx.get(dut.video.rgb), ctx.get(dut.video.de), ctx.get(dut.video.hsync),
                   ctx.get(dut.video.vsync))
            if got != (want, de, hs, vs):
                errors.append(((x, y), got, want))

    simulate(dut, clocks={"sync": t.pixel_hz}, testbenches=[bench])
    assert not errors, f"{len(errors)} wrong pixels, first: {errors[:3]}"


def test_ch7301c_output_bits_and_alignment():
    """Random pixels and syncs: each pixel's two words appear on the pins one clock later, first word while
    the clock is high, second while it is low, syncs and de held for the whole clock, data 0 outside de."""
    t = dataclasses.replace(SMALL_TIMING, hsync_positive=False, vsync_positive=True)
    dut = CH7301COutput(t)
    rng = random.Random(7)
    stimulus = [(rng.getrandbits(24), rng.random() < 0.8, rng.getrandbits(1), rng.getrandbits(1))
                for _ in range(400)]
    seen = []

    pins = dut.pins

    async def bench(ctx):
        # Reset state: blank pixel, syncs at their inactive level (hsync negative: idle high).
        assert (ctx.get(pins.data), ctx.get(pins.de), ctx.get(pins.hsync), ctx.get(pins.vsync)) == (0, 0, 1, 0)
        for rgb, de, hs, vs in stimulus:
            ctx.set(dut.video.rgb, rgb)
            ctx.set(dut.video.de, de)
            ctx.set(dut.video.hsync, hs)
            ctx.set(dut.video.vsync, vs)
            await ctx.posedge(pins.xclk_p)
            high = [ctx.get(s) for s in (pins.data, pins.de, pins.hsync, pins.vsync, pins.xclk_p, pins.xclk_n)]
            await ctx.negedge(pins.xclk_p)
            low = [ctx.get(s) for s in (pins.data, pins.de, pins.hsync, pins.vsync, pins.xclk_p, pins.xclk_n)]
            seen.append((high, low))

    simulate(dut, clocks={"sync": t.pixel_hz}, testbenches=[bench])
    for (rgb, de, hs, vs), (high, low) in zip(stimulus, seen):
        first, second = split_idf0(rgb) if de else (0, 0)
        assert high == [first, de, hs, vs, 1, 0], (hex(rgb), high)
        assert low == [second, de, hs, vs, 0, 1], (hex(rgb), low)


def test_ch7301c_output_rejects_unknown_mode():
    with pytest.raises(ValueError):
        CH7301COutput(ddr="spartan")
    with pytest.raises(ValueError):
        CH7301COutput(xclk_domain="pix90")          # only meaningful for the board variant


# -- the Virtex-5 board variant -----------------------------------------------------------------------------

def test_board_variant_elaborates_to_virtex5_primitives():
    text = export_verilog(DisplayPath(CEA_1080P60, ddr="virtex5"), "display_path_board")
    oddr = re.findall(r"ODDR\s*#\s*\((.*?)\)\s*\\?(\S+)\s*\(", text, flags=re.S)
    assert len(oddr) == 12 + 3 + 1, [name for _, name in oddr]           # data, hsync/vsync/de, xclk
    for params, _ in oddr:
        assert '.DDR_CLK_EDGE("SAME_EDGE")' in params
    assert len(re.findall(r"\bOBUFDS\b", text)) == 1
    # The behavioural variant has no primitive at all.
    assert "ODDR" not in export_verilog(DisplayPath(SMALL_TIMING), "display_path")


#: Behavioural models of the two Virtex-5 primitives the board variant instantiates, written from the
#: Virtex-5 User Guide (UG190, "ODDR"): SAME_EDGE captures D1 and D2 on the rising edge of C and drives
#: D1 while C is high, D2 while C is low. OBUFDS: O = I, OB = not I.
VIRTEX5_MODELS = """
module ODDR #(parameter DDR_CLK_EDGE = "OPPOSITE_EDGE", parameter INIT = 1'b0, parameter SRTYPE = "SYNC")
             (output Q, input C, input CE, input D1, input D2, input R, input S);
    reg rise = INIT, fall = INIT;
    initial if (DDR_CLK_EDGE != "SAME_EDGE") begin $display("model supports SAME_EDGE only"); $finish; end
    always @(posedge C) if (CE) begin rise <= D1; fall <= D2; end
    assign Q = C ? rise : fall;
endmodule

module OBUFDS (output O, output OB, input I);
    assign O = I;
    assign OB = ~I;
endmodule
"""


def test_board_variant_carries_the_same_frames_on_icarus(tmp_path):
    models = tmp_path / "virtex5_models.v"
    models.write_text(VIRTEX5_MODELS)
    from sim.runners.cocotb import run_cocotb
    params = {"timing": dataclasses.asdict(SMALL_TIMING), "sink_clocks": 2 * SMALL_TIMING.clocks_per_frame + 8,
              "min_frames": 2}
    test_dir = run_cocotb(DisplayPath(SMALL_TIMING, ddr="virtex5"), name="display_path_board",
                          test_module="sim.testbench.display_cocotb", simulator="icarus", params=params, extra_sources=[models])
    assert_ran(test_dir, {"sink_frames"})


# -- cocotb on Verilator and Icarus (small mode); the full 1080p frame on Verilator (slow) ---------------------

def _run_cocotb_frames(timing, expected, frames, simulator):
    test_dir = run_display_cocotb(
        DisplayPath(timing), timing, simulator=simulator, sink_clocks=frames * timing.clocks_per_frame + 16,
        min_frames=frames, expect_values=expected, expect_edges=expected)
    assert_ran(test_dir, {"sink_frames"})


def test_display_path_cocotb(simulator):
    """From reset to the first pixel of the next frame, two small-mode frames: the sink rebuilds them bit for bit
    and measures the intervals clock by clock; the edge timestamps of the same run give the same intervals."""
    _run_cocotb_frames(SMALL_TIMING, intervals(SMALL_TIMING), 2, simulator)


@pytest.mark.slow
def test_display_path_1080p_cocotb():
    """The full 1080p frame on Verilator, checked against the CEA-861 numbers written out above (slow: 2.5 M
    pixel clocks sampled from Python; the default run checks the same path on the small mode,
    :func:`test_display_path_cocotb`, and three whole 1080p lines in tests/test_sync_gen.py)."""
    _run_cocotb_frames(CEA_1080P60, CEA_1080P60_INTERVALS, 1, "verilator")
