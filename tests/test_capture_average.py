"""The averaging capture's golden model (golden/capture.py, docs/capture.md "The averaging capture"): the grey formula,
its rounding at the boundary, and the image-level capture of the 800 x 600 build."""

from fractions import Fraction

import numpy as np
import pytest

from golden.capture import (average_downscale, capture_frame, capture_stream, grey5, grey8_of_sum, rgb565_fields,
                            rgb888_to_rgb565)
from spec.sensor import SENSOR, SENSOR_800, SensorGeometry

TINY = SensorGeometry(width=8, height=4, scale=2, grey_bits=8, downscale="average")


@pytest.mark.parametrize("scale", [1, 2, 4])
def test_grey8_is_the_rounded_scaled_mean_for_every_sum(scale):
    """Every block sum T in 0..187 s^2: grey8 = 255 T / (187 s^2) rounded half up (exact fractions)."""
    block = scale * scale
    for total in range(187 * block + 1):
        exact = Fraction(255 * total, 187 * block)
        assert int(grey8_of_sum(total, scale)) == int(exact + Fraction(1, 2)) // 1, total


def test_grey8_rounding_at_the_half():
    """s = 2: T = 22 is exactly 7.5 -> 8 (half up); T = 21 (7.16) -> 7; T = 66 (22.5) -> 23, T = 65 -> 22."""
    assert [int(grey8_of_sum(t, 2)) for t in (21, 22, 65, 66)] == [7, 8, 22, 23]


def test_grey8_range_boundary():
    """The largest block sum (white, 748 for s = 2) gives 255; one past it is refused, as is a negative sum."""
    assert int(grey8_of_sum(748, 2)) == 255 and int(grey8_of_sum(0, 2)) == 0
    with pytest.raises(ValueError, match="0..748"):
        grey8_of_sum(749, 2)
    with pytest.raises(ValueError, match="0..748"):
        grey8_of_sum(-1, 2)


def test_average_of_a_hand_block():
    """One 2 x 2 block of RGB565 words: g = 2 R5 + G6 + 2 B5 per pixel, summed, scaled, rounded half up."""
    words = np.zeros((TINY.height, TINY.width), dtype=np.uint16)
    block = [(31, 63, 31), (0, 0, 0), (10, 1, 0), (0, 40, 3)]          # (R5, G6, B5)
    for (y, x), (r, g, b) in zip([(0, 0), (0, 1), (1, 0), (1, 1)], block):
        words[y, x] = (r << 11) | (g << 5) | b
    total = sum(2 * r + g + 2 * b for r, g, b in block)                  # 187 + 0 + 21 + 46 = 254
    out = average_downscale(words, TINY)
    assert out.shape == (TINY.buf_height, TINY.buf_width) == (2, 4)
    assert int(out[0, 0]) == (510 * total + 187 * 4) // (374 * 4) == 87    # 255 * 254 / 748 = 86.6
    assert (out.ravel()[1:] == 0).all()


def test_uniform_image_keeps_its_value_and_white_is_255():
    """A uniform image: every buffer pixel is the value of its one colour; white is 255."""
    rgb = np.zeros((TINY.height, TINY.width, 3), dtype=np.uint8)
    rgb[:] = (200, 120, 40)
    r, g, b = rgb565_fields(int(rgb888_to_rgb565(rgb[0, 0])))
    one = int(grey8_of_sum(2 * r + g + 2 * b, 1))
    assert (capture_frame(rgb, TINY) == one).all()
    assert (capture_frame(np.full_like(rgb, 255), TINY) == 255).all()


def test_geometry_and_refusals():
    """SENSOR_800 captures 800 x 600 x 8-bit; the thesis's capture is unchanged; an averaging geometry without 8-bit
    grey, an unknown downscale and the stream-level rules of the averaging capture are refused (one line)."""
    assert (SENSOR_800.buf_width, SENSOR_800.buf_height, SENSOR_800.grey_bits) == (800, 600, 8)
    rgb = np.random.default_rng(2).integers(0, 256, (TINY.height, TINY.width, 3)).astype(np.uint8)
    thesis = SensorGeometry(width=8, height=4, scale=2)
    assert (capture_frame(rgb, thesis) == grey5(rgb888_to_rgb565(rgb))[::2, ::2]).all()
    assert SENSOR.downscale == "keep"
    with pytest.raises(ValueError, match="8-bit"):
        capture_frame(rgb, SensorGeometry(width=8, height=4, scale=2, downscale="average"))
    with pytest.raises(ValueError, match="downscale must be"):
        SensorGeometry(downscale="median")
    with pytest.raises(ValueError, match="image level"):
        capture_stream([0], [0], [0], TINY)
