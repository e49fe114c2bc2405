"""The whole software flow of thesis figure 3.8 (chapter 3): capture -> grey -> Harris corners of each image ->
SSD matching -> tangent method -> vertical shift of the right (processing) image -> SAD disparity (WTA) ->
distance map.

The left image is the reference. The right image is moved by the found shift (``rectify.shift_rows``); rows
that then have no right-image data get disparity -1 ("no data") and distance NaN.
"""

from dataclasses import dataclass

import numpy as np

from . import harris, rectify, sad, ssd
from .distance import BOARD_CAMERAS, distance_from_disparity

__all__ = ["GREY_WEIGHTS", "to_grey", "ShiftSearch", "estimate_vertical_shift", "DepthResult", "depth_pipeline"]

#: Matlab rgb2gray (the thesis's model ran in Matlab): Y = 0.2989 R + 0.5870 G + 0.1140 B, rounded to 8 bits.
GREY_WEIGHTS = (0.2989, 0.5870, 0.1140)


def to_grey(image):
    """8-bit grey of an RGB(A) or grey image (Matlab rgb2gray weights, rounded to nearest)."""
    a = np.asarray(image)
    if a.ndim == 2:
        return a.astype(np.uint8) if a.dtype == np.uint8 else np.clip(np.rint(a), 0, 255).astype(np.uint8)
    if a.ndim != 3 or a.shape[2] < 3:
        raise ValueError(f"expected a grey (H, W) or colour (H, W, 3) image, got shape {a.shape}")
    grey = a[..., :3].astype(np.float64) @ np.asarray(GREY_WEIGHTS)
    return np.clip(np.rint(grey), 0, 255).astype(np.uint8)


@dataclass(frozen=True)
class ShiftSearch:
    """Everything the vertical-shift search found: the corners, the SSD pairs and the tangent estimate."""
    left_corners: np.ndarray
    right_corners: np.ndarray
    matched_left: np.ndarray
    matched_right: np.ndarray
    estimate: rectify.ShiftEstimate

    @property
    def shift(self):
        return self.estimate.shift


def estimate_vertical_shift(left_grey, right_grey, max_vertical_shift=ssd.MAX_VERTICAL_SHIFT,
                            patch_half=ssd.PATCH_HALF, max_corners=harris.MAX_CORNERS):
    """Harris (3.1.1) + SSD (3.13) + tangent method (3.1.2) on two grey images. Raises ValueError when too
    few corners match to estimate a shift."""
    c1 = harris.harris_corners(left_grey, max_corners=max_corners, border=patch_half)
    c2 = harris.harris_corners(right_grey, max_corners=max_corners, border=patch_half)
    m1, m2, _ = ssd.match_corners(left_grey, c1, right_grey, c2, half=patch_half,
                                  max_vertical_shift=max_vertical_shift)
    if len(m1) < 2:
        raise ValueError(f"only {len(m1)} corner pairs matched ({len(c1)} left and {len(c2)} right corners): "
                         "too little texture to estimate the vertical shift")
    return ShiftSearch(c1, c2, m1, m2, rectify.vertical_shift(m1, m2))


@dataclass(frozen=True)
class DepthResult:
    shift: int                    # rows the right image was moved up (negative: down)
    search: ShiftSearch | None    # None when the shift was given, not estimated
    disparity: np.ndarray         # int16 (H, W), 0..max_disparity, -1 = no data
    distance_m: np.ndarray        # float (H, W) metres, inf for disparity 0, NaN for no data


def depth_pipeline(left, right, max_disparity=sad.MAX_DISPARITY, window=sad.SAD_WINDOW, camera=BOARD_CAMERAS,
                   shift=None, max_vertical_shift=ssd.MAX_VERTICAL_SHIFT, progress=None):
    """Figure 3.8 on a left/right pair (RGB or grey arrays of one size). ``shift=None`` estimates the vertical
    shift by the tangent method; an int uses that shift instead (0 = no rectification, thesis figure 3.18).
    ``progress(stage, fraction)``, if given, is called as the stages (``vertical shift``, ``SAD``) go on."""
    progress = progress or (lambda stage, fraction: None)
    left_grey, right_grey = to_grey(left), to_grey(right)
    if left_grey.shape != right_grey.shape:
        raise ValueError(f"left {left_grey.shape[1]}x{left_grey.shape[0]} and right "
                         f"{right_grey.shape[1]}x{right_grey.shape[0]} images differ in size")
    search = None
    if shift is None:
        progress("vertical shift", 0.0)
        search = estimate_vertical_shift(left_grey, right_grey, max_vertical_shift)
        shift = search.shift
    height = left_grey.shape[0]
    if abs(shift) >= height:
        raise ValueError(f"vertical shift {shift} leaves no common rows in {height}-row images")
    right_moved, valid_rows = rectify.shift_rows(right_grey, shift)
    disparity = np.full(left_grey.shape, -1, dtype=np.int16)
    disparity[valid_rows] = sad.sad_disparity(left_grey[valid_rows], right_moved[valid_rows],
                                              max_disparity, window, lambda f: progress("SAD", f))
    return DepthResult(int(shift), search, disparity, distance_from_disparity(disparity, camera))
