"""Golden model of the depth-keyed segmentation view (docs/display.md, "Segmentation"), written from the spec.

* :func:`in_band`: a depth code c (1 / 2**F pixel) is inside the band around the disparity register d when
  |c / 2**F - d| <= ``SEGMENT_HALF_WIDTH``; the invalid code never is.
* :func:`band_text`: the band's near and far distance, Z = B f / (d' p s) at d' = d + half width and
  d' = d - half width, in metres with two decimals (whole centimetres rounded half up), "--.--" where d' <= 0
  (no finite distance) or the distance does not fit, joined by "-", then "m".
* :func:`segment_picture`: the right image (the depth map's grid) in 8-bit grey inside the band; outside it each
  channel shifted right by ``SEGMENT_DIM_SHIFT``; an invalid pixel dimmed with ``SEGMENT_INVALID_RGB`` OR-ed in.

Only constants come from ``spec``; nothing is taken from the RTL.
"""

import numpy as np

from spec.depth import DEPTH
from spec.display import SEGMENT_DIM_SHIFT, SEGMENT_HALF_WIDTH, SEGMENT_INVALID_RGB, SEGMENT_TEXT
from spec.sensor import SENSOR, VMODCAM_RIG

__all__ = ["in_band", "band_text", "segment_picture", "blank_band_text"]


def in_band(codes, disparity, config=DEPTH):
    """Bool array shaped like ``codes``: inside the band around ``disparity`` (whole pixels)."""
    codes = np.asarray(codes, dtype=np.int64)
    inside = np.abs(codes - config.fraction * int(disparity)) <= config.fraction * SEGMENT_HALF_WIDTH
    return inside & (codes != config.invalid)


def _metres(disparity, geometry):
    if disparity <= 0:
        return "--.--"
    z = VMODCAM_RIG.BASELINE_M * VMODCAM_RIG.FOCAL_M / (disparity * VMODCAM_RIG.PIXEL_M * geometry.scale)
    cm = int(np.floor(z * 100 + 0.5))
    if cm > 9999:
        return "--.--"
    return f"{cm // 100:2d}.{cm % 100:02d}"


def band_text(disparity, geometry=SENSOR):
    """The band's text for the disparity register ``disparity``: "near-farm" (``SEGMENT_TEXT``'s length)."""
    d = int(disparity)
    return f"{_metres(d + SEGMENT_HALF_WIDTH, geometry)}-{_metres(d - SEGMENT_HALF_WIDTH, geometry)}m"


def blank_band_text():
    """The band box's text with the segmentation off: spaces (the box is then all background)."""
    return " " * len(SEGMENT_TEXT)


def segment_picture(right, codes, disparity, grey_bits=5, config=DEPTH):
    """(H, W) int64 0xRRGGBB: the segmented right image for the right buffer ``right`` and the depth ``codes``."""
    right = np.asarray(right, dtype=np.int64)
    codes = np.asarray(codes, dtype=np.int64)
    grey8 = right << (8 - grey_bits) | right >> (2 * grey_bits - 8) if grey_bits < 8 else right
    dim = grey8 >> SEGMENT_DIM_SHIFT
    shown = np.where(in_band(codes, disparity, config), grey8, dim) * 0x010101
    return np.where(codes == config.invalid, shown | SEGMENT_INVALID_RGB, shown)
