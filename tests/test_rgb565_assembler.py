"""RGB565Assembler against the golden model, with random byte streams (hypothesis).

The golden side: golden.capture.assemble_line (pairs of bytes in order, an odd trailing byte dropped,
either byte order) and the column rule of docs/capture.md (column = byte count / 2 within LV, saturating at
``width``); a line is well formed iff it has exactly ``2 * width`` bytes.
"""

from amaranth.sim import Simulator
from hypothesis import given, settings
from hypothesis import strategies as st

from golden.capture import assemble_line, rgb565_to_bytes
from hdl.rgb565_assembler import RGB565Assembler


def run_assembler(width, r_byte_first, lines, gaps):
    """Send each line (a list of bytes, LV high) followed by its gap (LV low, random data) and collect
    ``(pixel, column)`` per completed pixel, and ``line_ok`` at every ``line_end``."""
    dut = RGB565Assembler(width, r_byte_first=r_byte_first)
    pixels, line_oks = [], []

    async def bench(ctx):
        cycles = []
        for line, gap in zip(lines, gaps):
            cycles += [(1, b) for b in line]
            cycles += [(0, (37 * k + 11) & 0xFF) for k in range(gap)]
        for lv, data in cycles:
            ctx.set(dut.lv, lv)
            ctx.set(dut.data, data)
            if ctx.get(dut.line_end):
                line_oks.append(ctx.get(dut.line_ok))
            await ctx.tick()
            if ctx.get(dut.valid):
                pixels.append((ctx.get(dut.pixel), ctx.get(dut.column)))

    sim = Simulator(dut)
    sim.add_clock(1 / 24e6)
    sim.add_testbench(bench)
    sim.run()
    return pixels, line_oks


def golden(width, r_byte_first, lines):
    pixels, oks = [], []
    for line in lines:
        words = assemble_line(line, r_byte_first)
        pixels += [(w, min(k, width)) for k, w in enumerate(words)]
        if line:
            oks.append(int(len(line) == 2 * width))
    return pixels, oks


@st.composite
def line_streams(draw):
    width = draw(st.integers(1, 12))
    n = draw(st.integers(1, 6))
    lines = [draw(st.lists(st.integers(0, 255), min_size=0, max_size=2 * width + 5)) for _ in range(n)]
    gaps = [draw(st.integers(1, 4)) for _ in range(n)]
    return width, draw(st.booleans()), lines, gaps


@settings(max_examples=40, deadline=None)
@given(line_streams())
def test_random_lines_match_golden(stream):
    width, r_byte_first, lines, gaps = stream
    assert run_assembler(width, r_byte_first, lines, gaps) == golden(width, r_byte_first, lines)


def test_exact_lines_both_orders():
    """Known pixels through both byte orders; exactly 2 * width bytes is a good line."""
    words = [0xF800, 0x07E0, 0x001F, 0x8204, 0xFFFF]
    for r_first in (True, False):
        line = [b for w in words for b in rgb565_to_bytes(w, r_first)]
        pixels, oks = run_assembler(len(words), r_first, [line, line[:-1], line + [1, 2]], [2, 2, 2])
        assert [p for p, _ in pixels[:5]] == words
        assert [c for _, c in pixels] == [0, 1, 2, 3, 4] + [0, 1, 2, 3] + [0, 1, 2, 3, 4, 5]
        assert oks == [1, 0, 0]


def test_r_byte_is_red():
    """The R byte carries R[4:0] G[5:3]: pure red is 0xF8 0x00 with the R byte first."""
    pixels, _ = run_assembler(1, True, [[0xF8, 0x00]], [1])
    assert pixels == [(0xF800, 0)]
    pixels, _ = run_assembler(1, False, [[0x00, 0xF8]], [1])
    assert pixels == [(0xF800, 0)]
