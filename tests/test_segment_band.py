"""SegmentBand (hdl/segment_band.py) against golden.segmentation, bit for bit, in the Amaranth simulator: every code
0..invalid at band centres across the register's range, the band's edges worked by hand, the band text of every
register value (RTL ROM = golden text)."""

import numpy as np
import pytest

from golden.segmentation import band_text, in_band, segment_picture
from hdl.segment_band import LATENCY, SegmentBand, band_table
from hdl.text_layer import char_codes
from sim.runners.amaranth import simulate
from spec.board import CLOCKS
from spec.depth import DEPTH, DEPTH_800, SMALL_DEPTH
from spec.display import SEGMENT_HALF_WIDTH
from spec.sensor import SENSOR, SENSOR_800, SMALL_SENSOR


def run_band(disparity, codes, greys, enable=1, geometry=SENSOR, config=DEPTH):
    """(rgb per sample, chars after the run) of the RTL for one register value."""
    dut = SegmentBand(geometry, config)
    rgb = []
    chars = []

    async def bench(ctx):
        ctx.set(dut.disparity, disparity)
        ctx.set(dut.enable, enable)
        await ctx.tick().repeat(3)                    # the band's edges and the text registered
        for k in range(len(codes) + LATENCY):
            if k < len(codes):
                ctx.set(dut.code, int(codes[k]))
                ctx.set(dut.grey, int(greys[k]))
            if k >= LATENCY:
                rgb.append(ctx.get(dut.rgb))
            await ctx.tick()
        chars.extend(ctx.get(dut.chars[i]) for i in range(len(dut.chars)))

    simulate(dut, clocks={"sync": CLOCKS.PIXEL_HZ}, testbenches=[bench])
    return np.array(rgb, dtype=np.int64), chars


@pytest.mark.parametrize("disparity", [0, 1, 2, 3, 31, 62, 63, 64, 66, 127])
def test_every_code_rtl_equals_golden(disparity):
    rng = np.random.default_rng(disparity)
    codes = np.arange(DEPTH.invalid + 1)
    greys = rng.integers(0, 2 ** SENSOR.grey_bits, size=codes.size)
    rgb, chars = run_band(disparity, codes, greys)
    expected = segment_picture(greys[None, :], codes[None, :], disparity, SENSOR.grey_bits, DEPTH)[0]
    assert (rgb == expected).all(), np.flatnonzero(rgb != expected)[:5]
    assert chars == char_codes(band_text(disparity, SENSOR))


def test_band_edges():
    """d = 31, half width 2: codes 16 x 29 and 16 x 33 are inside, one code past either edge is not; grey 31 shows
    0xFFFFFF inside, 0xFF >> 2 = 0x3F on each channel outside; the invalid code 0x3F3F3F | 0x80 = 0x3F3FBF."""
    assert SEGMENT_HALF_WIDTH == 2 and DEPTH.fraction == 16
    codes = np.array([16 * 29 - 1, 16 * 29, 16 * 33, 16 * 33 + 1, DEPTH.invalid])
    assert in_band(codes, 31).tolist() == [False, True, True, False, False]
    rgb, _ = run_band(31, codes, [31] * len(codes))
    assert rgb.tolist() == [0x3F3F3F, 0xFFFFFF, 0xFFFFFF, 0x3F3F3F, 0x3F3FBF]
    # d = 63: the band reaches past the largest disparity code; the invalid code (16 x 64) still never is inside.
    rgb, _ = run_band(63, [16 * 61 - 1, 16 * 61, DEPTH.invalid - 1, DEPTH.invalid], [16] * 4)
    assert rgb.tolist() == [0x212121, 0x848484, 0x848484, 0x2121A1]


def test_band_edges_800():
    """The 800 x 600 build (D = 128, 8-bit grey): d = 64, codes 16 x 62 and 16 x 66 inside, one past either edge not;
    d = 127, the band reaches past the largest code: 16 x 125 inside, one below it not, and the invalid code
    2048 (16 x 128, inside |code - 16 d| <= 32) never. Grey 200 shows 0xC8C8C8 inside, 200 >> 2 = 0x32 outside,
    0x3232B2 for the invalid code: by hand, the golden model and the RTL alike."""
    for disparity, codes, expected in (
            (64, [16 * 62 - 1, 16 * 62, 16 * 66, 16 * 66 + 1], [0x323232, 0xC8C8C8, 0xC8C8C8, 0x323232]),
            (127, [16 * 125 - 1, 16 * 125, DEPTH_800.invalid - 1, DEPTH_800.invalid],
             [0x323232, 0xC8C8C8, 0xC8C8C8, 0x3232B2])):
        greys = [200] * len(codes)
        golden = segment_picture(np.array([greys]), np.array([codes]), disparity, 8, DEPTH_800)[0]
        rgb, _ = run_band(disparity, codes, greys, geometry=SENSOR_800, config=DEPTH_800)
        assert golden.tolist() == rgb.tolist() == expected


def test_band_text_table():
    """The RTL's band ROM (exact fractions) is the golden text (floating point) for every register value; the hand
    values: d = 31 -> Z(33) = 0.8267 m, Z(29) = 0.9407 m; d = 2 -> far end d' = 0 has no distance; d = 0 -> near
    Z(2) = 13.64 m."""
    for geometry in (SENSOR, SMALL_SENSOR):
        assert band_table(geometry) == [band_text(d, geometry) for d in range(128)]
    table = band_table(SENSOR)
    assert table[31] == " 0.83- 0.94m" and table[2] == " 6.82---.--m" and table[0] == "13.64---.--m"
    assert table[3] == " 5.46-27.28m" and table[127] == " 0.21- 0.22m"


def test_text_off_and_small_config():
    """``enable`` low gives spaces; the small engine's codes (D = 8) against the golden model."""
    codes = np.arange(SMALL_DEPTH.invalid + 1)
    greys = (codes * 7) % 32
    rgb, chars = run_band(5, codes, greys, enable=0, geometry=SMALL_SENSOR, config=SMALL_DEPTH)
    assert chars == char_codes(" " * 12)
    expected = segment_picture(greys[None, :], codes[None, :], 5, SMALL_SENSOR.grey_bits, SMALL_DEPTH)[0]
    assert (rgb == expected).all()

