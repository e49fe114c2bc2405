"""The depth display's pieces: colour map ROM, readout ROM, text layer, centre median, the arbiter and the layout.

The RTL tables (hdl/colour_map.py, hdl/centre_distance.py) against the golden model (golden/depth_display.py,
written separately from the spec) and against values worked by hand; the text layer and the centre median in
the Amaranth simulator against the golden drawing and NumPy's median.
"""

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from golden.depth_display import centre_readout, depth_colours, draw_text, distance_m
from hdl.centre_distance import CentreDistance, SETTLE_CLOCKS, readout_table
from hdl.colour_map import LATENCY as COLOUR_LATENCY, ColourMap, colour_table
from spec.depth import DEPTH, DEPTH_800, SMALL_DEPTH, DepthConfig
from spec.display import BACKGROUND_RGB, DEPTH_COLOURS, DEPTH_INVALID_RGB, TEXT_RGB
from spec.font import FONT, FONT_CELL
from spec.layout import DisplayLayout, TextBox
from spec.sensor import SENSOR, SENSOR_800, SMALL_SENSOR, disparity_of_distance
from spec.video import CEA_1080P60, SMALL_TIMING, VideoTiming
from hdl.read_arbiter import ReadArbiter
from hdl.text_layer import FONT_ORDER, LATENCY as TEXT_LATENCY, TextLayer, char_codes
from sim.runners.amaranth import simulate

CONFIGS = [DEPTH, SMALL_DEPTH, DepthConfig(disparities=128, lanes=16)]


def _rgb(value):
    return tuple((value >> s) & 0xFF for s in (16, 8, 0))


@pytest.mark.parametrize("config", CONFIGS, ids=lambda c: f"D{c.disparities}")
def test_colour_rom_equals_golden(config):
    """The ROM's contents (exact fractions) equal the golden colours (integer NumPy arithmetic) for every code
    0..16 D."""
    assert colour_table(config) == depth_colours(config).tolist()
    assert len(colour_table(config)) == config.invalid + 1


def run_colour_map(config):
    """Every code 0..16 D through the ColourMap block (Amaranth simulator), in order: the colours it gives."""
    dut, codes, got = ColourMap(config), list(range(config.invalid + 1)), []

    async def bench(ctx):
        for c in codes + [0] * COLOUR_LATENCY:
            ctx.set(dut.code, c)
            await ctx.tick()
            got.append(ctx.get(dut.rgb))

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    return got[COLOUR_LATENCY - 1:COLOUR_LATENCY - 1 + len(codes)]


@pytest.mark.parametrize("config", [SMALL_DEPTH, DEPTH], ids=lambda c: f"D{c.disparities}")
def test_colour_map_block_equals_golden(config):
    """The RTL lookup (block-RAM ROM read synchronously, the invalid code chosen after it) gives the golden colour
    of every code 0..16 D, two clocks after the code."""
    assert run_colour_map(config) == depth_colours(config).tolist()


def _whole_pixel_colours(config):
    """The colours of whole disparities 0..D - 1 by the whole-pixel rule (NumPy's float
    interpolation at u = 8 d / (D - 1), rounded half up): a third computation, for the codes 16 d."""
    anchors = np.asarray(DEPTH_COLOURS, dtype=np.float64)
    t = np.arange(config.disparities) / (config.disparities - 1)
    ch = [np.floor(np.interp(t, np.linspace(0, 1, len(anchors)), anchors[:, c]) + 0.5).astype(int) for c in range(3)]
    return ((ch[0] << 16) | (ch[1] << 8) | ch[2]).tolist()


@pytest.mark.parametrize("config", CONFIGS, ids=lambda c: f"D{c.disparities}")
def test_colour_rule_at_its_boundaries(config):
    """Code 16 d has the colour whole disparity d had (every d); the largest valid code 16 (D - 2) + 8 lies below
    the last anchor (u < 8) and before its colour; the invalid code is DEPTH_INVALID_RGB and no valid code's
    colour. Between 16 d and 16 (d + 1) some code has a colour of its own (the panel shows fractions), and where
    no anchor lies strictly between them every channel of every code between is between theirs."""
    colours, f, top = depth_colours(config), config.fraction, config.disparities - 1
    assert colours[:config.invalid:f].tolist() == _whole_pixel_colours(config)
    largest = f * (config.disparities - 2) + f // 2
    assert 8 * largest < 8 * f * top                            # u = 8 c / (16 (D - 1)) < 8
    assert colours[largest] != colours[f * top] and colours[f * top] == (253 << 16 | 231 << 8 | 37)
    assert colours[config.invalid] == DEPTH_INVALID_RGB and DEPTH_INVALID_RGB not in colours[:-1].tolist()
    rgb = np.array([_rgb(v) for v in colours[:f * top + 1]])
    for d in range(top):
        lo, hi, inside = rgb[f * d], rgb[f * (d + 1)], rgb[f * d + 1:f * (d + 1)]
        assert any((c != lo).any() and (c != hi).any() for c in inside)        # a fraction has its own colour
        if not any(f * d < f * top * k // 8 < f * (d + 1) for k in range(9) if f * top * k % 8 == 0):
            assert ((inside >= np.minimum(lo, hi)) & (inside <= np.maximum(lo, hi))).all()


def test_colour_map_by_hand():
    """Far = the first anchor, near = the last (yellow: warm); D = 64: u = 8 c / 1008 = c / 126. d = 31 (code 496)
    is at u = 3 + 118/126, from anchor 3 (44, 114, 142) to anchor 4 (33, 145, 140): (33.70, 143.03, 140.13) ->
    (34, 143, 140); code 500 (d = 31.25): u = 3 + 122/126: (33.35, 144.02, 140.06) -> (33, 144, 140); code 504
    (d = 31.5) is anchor 4 itself; code 512 (d = 32): 8/126 past it: (33.44, 146.84, 139.24) -> (33, 147, 139).
    Half up: code 21, u = 1/6: (68 + 3/6, 1 + 44/6, 84 + 39/6) = (68.5, 8.33, 90.5) -> (69, 8, 91) (truncation
    or half-to-even would give 68 and 90). The largest valid code 1000 (d = 62.5): u = 7 + 118/126 from (173,
    220, 48) to (253, 231, 37): (247.92, 230.30, 37.70) -> (248, 230, 38). Invalid (1024) is black. Lightness
    (Rec. 709 luma) rises with disparity: the map is perceptually ordered, near is brightest."""
    table = colour_table(DEPTH)
    assert _rgb(table[0]) == DEPTH_COLOURS[0] and _rgb(table[16 * 63]) == DEPTH_COLOURS[-1] == (253, 231, 37)
    assert _rgb(table[496]) == (34, 143, 140) and _rgb(table[500]) == (33, 144, 140)
    assert _rgb(table[504]) == DEPTH_COLOURS[4] and _rgb(table[512]) == (33, 147, 139)
    assert _rgb(table[21]) == (69, 8, 91) and _rgb(table[1000]) == (248, 230, 38)
    assert table[1024] == DEPTH_INVALID_RGB == 0 and len(table) == 1025
    rgb = np.array([_rgb(v) for v in table[:16 * 63 + 1:16]], dtype=float)
    luma = rgb @ [0.2126, 0.7152, 0.0722]
    assert (np.diff(luma) > 0).all()
    assert rgb[63, 0] > rgb[63, 2] and rgb[0, 2] > rgb[0, 0]        # near warm (red > blue), far cool


@pytest.mark.parametrize("config, geometry", [(DEPTH, SENSOR), (SMALL_DEPTH, SMALL_SENSOR)])
def test_readout_rom_equals_golden(config, geometry):
    """Every code's readout (exact rationals) equals the golden text (floats) for a map made of that code."""
    for code, text in enumerate(readout_table(geometry, config)):
        codes = np.full((12, 16), code)
        assert centre_readout(codes, geometry, config) == (code, text)


def test_readout_by_hand():
    """Z = 0.063 x 3.81e-3 / (d x 4 x 2.2e-6) m = 27.2761 / d m, d = code / 16: d = 1 -> 2728 cm, d = 27 ->
    101.02 -> 101 cm, d = 62 -> 43.99 -> 44 cm; d = 9 + 1/16 -> 301.0 cm, d = 9 -> 303.07 cm; d = 0.3125
    (code 5) -> 8728 cm, d = 0.25 (code 4) -> 10910 cm: five digits, dashes; d = 0 (infinitely far) and the
    invalid code show dashes."""
    table = readout_table()
    assert table[16] == "2728cm" and table[27 * 16] == " 101cm" and table[62 * 16] == "  44cm"
    assert table[9 * 16 + 1] == " 301cm" and table[9 * 16] == " 303cm"
    assert table[5] == "8728cm" and table[4] == "----cm"
    assert table[0] == table[1024] == "----cm" and len(table) == 1025
    assert abs(disparity_of_distance(1.0) - 27.2761) < 1e-3 and abs(distance_m(27.2761) - 1.0) < 1e-4


def test_centre_median_golden_by_hand():
    """The fifth smallest of the 3 x 3 window at (W // 2, H // 2); the invalid code sorts above every
    disparity: 4 invalid codes leave the median valid, 5 make it invalid."""
    codes = np.zeros((12, 16), dtype=int)
    codes[5:8, 7:10] = [[1024, 1024, 480], [1024, 1024, 448], [432, 432, 465]]
    assert centre_readout(codes) == (480, f"{int(27.2761 / 30 * 100 + 0.5):4d}cm")
    codes[7, 7] = 1024
    assert centre_readout(codes)[0] == 1024


def test_font_and_layout_facts():
    """Every glyph is 5 x 7 of '#' and '.'; the label texts, the readout and the layout's numbers
    (spec.layout.DisplayLayout docstring)."""
    for char, glyph in FONT.items():
        assert len(glyph) == FONT_CELL[1] - 1 and all(len(r) == FONT_CELL[0] - 1 and set(r) <= {"#", "."}
                                                         for r in glyph), char
    full = DisplayLayout.centred(CEA_1080P60, SENSOR, DEPTH)
    assert [r.box for r in full.regions][2:] == [full.region("disparity").box, full.region("depth").box]
    assert (full.region("disparity").x0, full.region("depth").x0, full.region("depth").y0) == (100, 940, 410)
    assert (full.bar.x0, full.bar.y0, full.bar.box.y1) == (1748, 422, 998)
    assert [lab.text for lab in full.labels] == ["0.5m", "1m", "2m", "3m", "5m"]
    assert full.readout.box.inside(full.region("depth").box)
    small = DisplayLayout.centred(SMALL_TIMING, SMALL_SENSOR, SMALL_DEPTH)
    assert [lab.text for lab in small.labels] == ["5m"]          # d(3 m) = 9.1 is beyond D = 8
    assert small.readout.y0 == small.region("depth").y1 + 1      # does not fit inside a 32 x 24 map


def run_text_layer(boxes, dynamic, dynamic_texts, timing):
    """The text layer over one frame of the raster (``dynamic``: name -> box, ``dynamic_texts``: name -> text):
    (in_text, lit) as (v_active, h_active) arrays."""
    dut = TextLayer(boxes, dynamic, v_active=timing.v_active)
    out_in = np.zeros((timing.v_active, timing.h_active), dtype=bool)
    out_lit = np.zeros_like(out_in)

    async def bench(ctx):
        for name, text in dynamic_texts.items():
            for i, c in enumerate(char_codes(text)):
                ctx.set(getattr(dut.chars, name)[i], c)
        ctx.set(dut.y, timing.v_active)                # blanking first: the counters clear
        await ctx.tick().repeat(2)
        pending = []
        for y in range(timing.v_active + 1):
            for x in range(timing.h_active):
                if y < timing.v_active:
                    ctx.set(dut.x, x)
                    ctx.set(dut.y, y)
                    pending.append((y, x))
                else:
                    ctx.set(dut.y, timing.v_active)
                await ctx.tick()
                if len(pending) >= TEXT_LATENCY:
                    py, px = pending.pop(0)
                    out_in[py, px], out_lit[py, px] = ctx.get(dut.in_text), ctx.get(dut.lit)

    simulate(dut, clocks={"sync": 1e6}, testbenches=[bench])
    return out_in, out_lit


def test_text_layer_equals_golden_drawing():
    """Constant boxes at scales 1 and 2 and two named dynamic boxes, every glyph of the font, against golden
    draw_text. (The raster here has no blanking columns: the layer needs none.)"""
    timing = VideoTiming(h_active=120, h_front=0, h_sync=1, h_back=0, v_active=48, v_front=1, v_sync=1, v_back=1)
    everything = "".join(FONT_ORDER)
    half = (len(everything) + 1) // 2
    boxes = (TextBox(everything[:half], 1, 0, 1), TextBox(everything[half:], 1, 9, 1), TextBox("0.5m", 40, 20, 2))
    dynamic = {"readout": TextBox("0000cm", 0, 30, 1), "band": TextBox("00.00-00.00m", 20, 39, 1)}
    shown = {"readout": "-9.1cm", "band": " 0.83-12.50m"}
    lit_in, lit = run_text_layer(boxes, dynamic, shown, timing)
    frame = np.full((timing.v_active, timing.h_active), -1, dtype=np.int64)
    for box in boxes:
        draw_text(frame, box, box.text)
    for name, box in dynamic.items():
        draw_text(frame, box, shown[name])
    assert (lit_in == (frame != -1)).all()
    assert (lit == (frame == TEXT_RGB)).all()
    assert ((frame == TEXT_RGB) | (frame == BACKGROUND_RGB) | (frame == -1)).all()


def run_centre_distance(windows, config=DEPTH, geometry=SENSOR):
    dut = CentreDistance(geometry, config)
    results = []

    async def bench(ctx):
        for window in windows:
            for k, code in enumerate(window):
                ctx.set(dut.capture, 1 << k)
                ctx.set(dut.code, int(code))
                await ctx.tick()
            ctx.set(dut.capture, 0)
            await ctx.tick().repeat(SETTLE_CLOCKS)
            text = "".join(FONT_ORDER[ctx.get(dut.chars[i])] for i in range(6))
            results.append((ctx.get(dut.median), text))

    simulate(dut, clocks={"sync": 1e6}, testbenches=[bench])
    return results


@settings(max_examples=5, deadline=None)
@given(st.lists(st.lists(st.sampled_from([0, 1, 4, 5, 16, 27, 30, 31, 145, 992, 1000, 1023, 1024]),
                        min_size=9, max_size=9),
                min_size=6, max_size=6))
def test_centre_distance_equals_golden(windows):
    """Windows of codes with many ties and invalid codes: the RTL's median and readout equal the golden's, each
    within SETTLE_CLOCKS of the window's last change."""
    got = run_centre_distance(windows)
    for window, result in zip(windows, got):
        codes = np.zeros((300, 400), dtype=int)
        codes[149:152, 199:202] = np.reshape(window, (3, 3))
        assert result == centre_readout(codes)


def test_centre_distance_800_at_the_rom_ends():
    """The 800 build's readout (D = 128, scale 2: a 2K-word ROM, the invalid code 2048 one past it) equals the
    golden's for the codes at the ROM's ends, the invalid code and codes past it (dashes, as the golden's; the
    invalid code alone would read entry 0, dashes too, without the comparison)."""
    codes = [0, 1, 8, 9, 16 * 54, 2046, 2047, DEPTH_800.invalid, 3000, 4095]
    windows = [[c] * 9 for c in codes] + [[2047] * 4 + [DEPTH_800.invalid] * 5, [1] * 5 + [2048] * 4]
    got = run_centre_distance(windows, DEPTH_800, SENSOR_800)
    for window, result in zip(windows, got):
        assert result == centre_readout(np.reshape(window, (3, 3)), SENSOR_800, DEPTH_800)
    assert [text for _, text in got[2:4]] == ["----cm", "9698cm"] and got[6][1] == "  43cm"


def test_arbiter_priority():
    """The display always wins; the engine is granted exactly in the clocks the display leaves free and sees
    the buffer's data in both cases."""
    dut = ReadArbiter(SMALL_SENSOR)
    seen = []

    async def bench(ctx):
        for display, engine in ((0, 0), (0, 1), (1, 0), (1, 1)):
            ctx.set(dut.display.request, display)
            ctx.set(dut.display.port.addr, 5)
            ctx.set(dut.engine.request, engine)
            ctx.set(dut.engine.port.addr, 9)
            ctx.set(dut.buffer.data, 17)
            seen.append((ctx.get(dut.display.grant), ctx.get(dut.engine.grant), ctx.get(dut.buffer.addr),
                         ctx.get(dut.engine.port.data), ctx.get(dut.display.port.data)))
            await ctx.delay(1e-9)

    simulate(dut, clocks={}, testbenches=[bench])
    assert seen == [(1, 1, 9, 17, 17), (1, 1, 9, 17, 17), (1, 0, 5, 17, 17), (1, 0, 5, 17, 17)]


def test_board_readout_has_no_zero_width_vector():
    """At the board's size the invalid code is one past the readout ROM (a power of two): the Verilog has no
    zero-width vector (Verilator refuses ``[-1:0]``; the demo's build caught one in a readout ROM's address)."""
    from amaranth.back import verilog
    from spec.depth import DEPTH
    text = verilog.convert(CentreDistance(SENSOR, DEPTH), name="centre_distance")
    assert "[-1:0]" not in text
