"""Golden model of the disparity map generator and the display compositor, written from docs/disparity.md.

* :func:`difference_levels`: for every right-image pixel (x, y) of the buffer, ``|L(x + d, y + r) - R(x, y)|``
  quantised to ``level`` = number of thresholds ``t`` with ``|L - R| >= t``; ``r`` is signed (negative: the
  left image read higher); where ``x + d >= width``, ``y + r >= height`` or ``y + r < 0`` there is no left pixel: ``no_data`` is True and ``level`` is 0 (no wrapping).
* :func:`composite_frame`: the displayed active area: the left and right images (grey replicated to 8 bits
  by :func:`spec.display.grey_to_rgb24`), the disparity map (``level_grey[level]`` on all channels, or
  ``NO_DATA_RGB``), the depth map of the pair (``golden.depth.depth_map`` of the rectification-shifted left
  image and the right one) with its colour bar, labels and readout (``golden.depth_display``),
  ``BACKGROUND_RGB`` elsewhere, placed by :class:`spec.layout.DisplayLayout` with every buffer pixel repeated
  ``scale`` x ``scale`` times (a region with ``shrink`` > 1: every ``shrink``-th pixel of every ``shrink``-th row,
  from (0, 0)); with ``segment`` the difference map's place shows the segmentation view
  (``golden.segmentation``, the band around the disparity register) and the band's text box its band (spaces,
  so all background, without ``segment``).

Only constants and the layout definition come from ``spec`` (the spec's single source of truth); nothing
here is derived from the RTL.
"""

import numpy as np

from golden.depth import depth_map
from golden.depth_display import draw_depth_display, draw_text, engine_left
from golden.rectification_display import rectification_text
from golden.segmentation import band_text, blank_band_text, segment_picture
from spec.depth import DEPTH
from spec.display import BACKGROUND_RGB, DIFF_LEVEL_GREY, DIFF_THRESHOLDS, NO_DATA_RGB, diff_thresholds, grey_to_rgb24
from spec.layout import DisplayLayout
from spec.sensor import SENSOR
from spec.video import CEA_1080P60

__all__ = ["difference_levels", "composite_frame"]


def _check_images(left, right, geometry=None):
    left = np.asarray(left)
    right = np.asarray(right)
    if left.ndim != 2 or left.shape != right.shape:
        raise ValueError(f"left {left.shape} and right {right.shape} must be two grey images of the same size")
    if not (np.issubdtype(left.dtype, np.integer) and np.issubdtype(right.dtype, np.integer)):
        raise ValueError("grey images must hold integers")
    if geometry is not None:
        if left.shape != (geometry.buf_height, geometry.buf_width):
            raise ValueError(f"images are {left.shape[1]}x{left.shape[0]}, the buffers "
                             f"{geometry.buf_width}x{geometry.buf_height}")
        top = 2 ** geometry.grey_bits
        if left.min(initial=0) < 0 or right.min(initial=0) < 0 or max(left.max(initial=0),
                                                                       right.max(initial=0)) >= top:
            raise ValueError(f"grey values must be in 0..{top - 1}")
    return left.astype(np.int32), right.astype(np.int32)


def _check_shift(name, value, signed=False):
    if int(value) != value or (value < 0 and not signed):
        raise ValueError(f"{name} must be a{'n' if signed else ' non-negative'} integer, not {value!r}")
    return int(value)


def difference_levels(left, right, disparity, rectification, thresholds=DIFF_THRESHOLDS):
    """``(levels uint8, no_data bool)``, both shaped like the images (buffer resolution)."""
    left, right = _check_images(left, right)
    d = _check_shift("disparity", disparity)
    r = _check_shift("rectification", rectification, signed=True)
    h, w = right.shape
    no_data = np.ones((h, w), dtype=bool)
    shifted = np.zeros((h, w), dtype=np.int32)
    if d < w and -h < r < h:
        # Left pixel (x + d, y + r) for the right pixel (x, y) with x < w - d and 0 <= y + r < h.
        y0, y1 = max(-r, 0), min(h - r, h)
        shifted[y0:y1, :w - d] = left[y0 + r:y1 + r, d:]
        no_data[y0:y1, :w - d] = False
    diff = np.abs(shifted - right)
    table = np.asarray(list(thresholds), dtype=np.int32)
    levels = (diff[..., None] >= table).sum(axis=-1)
    levels[no_data] = 0
    return levels.astype(np.uint8), no_data


def _check_segment_layout(layout):
    """The segmentation view reads the depth map's rows as the depth panel shows them: same rows and scale."""
    diff, dep = layout.region("disparity"), layout.region("depth")
    if (diff.y0, diff.scale) != (dep.y0, dep.scale) or diff.x1 > dep.x0:
        raise ValueError("the segmentation view needs the difference map on the depth map's rows, at its scale, "
                         "left of it")


def rgb24_to_bytes(rgb):
    """(..., ) int array of 0xRRGGBB -> (..., 3) uint8."""
    rgb = np.asarray(rgb, dtype=np.int64)
    return np.stack([(rgb >> 16) & 0xFF, (rgb >> 8) & 0xFF, rgb & 0xFF], axis=-1).astype(np.uint8)


def composite_frame(left, right, disparity, rectification, timing=CEA_1080P60, geometry=SENSOR, layout=None,
                    thresholds=None, level_grey=DIFF_LEVEL_GREY, depth=DEPTH, *, details=False,
                    segment=False, rectification_mode=(False, False), row_tags=None):
    """The displayed frame, uint8 (v_active, h_active, 3), for the two grey buffers and the switch settings.
    ``layout`` None: :meth:`spec.layout.DisplayLayout.default`; ``thresholds`` None:
    :func:`spec.display.diff_thresholds` of the geometry's grey bits (``DIFF_THRESHOLDS`` for 5-bit grey).
    ``details=True`` returns ``(frame, codes, readout text)``: also the depth map shown and its readout.
    ``segment``: the segmentation view in the difference map's place (``ValueError`` if the layout's difference
    map is not on the depth map's rows at its scale, left of it). ``rectification_mode``: (automatic mode, held
    verdict) for the layout's rectification text (``golden.rectification_display``). ``row_tags``: None, or the
    frame tags of the buffers' rows (left_tags, right_tags), H entries each, an int or None (torn): the depth map is
    then ``depth_map(..., row_tags=...)`` with the left tags moved with the left rows (docs/depth.md, "Rows from
    different camera frames")."""
    left, right = _check_images(left, right, geometry)
    if layout is None:
        layout = DisplayLayout.default(timing, geometry, depth)
    if thresholds is None:
        thresholds = diff_thresholds(geometry.grey_bits)
    if len(level_grey) != len(thresholds) + 1:
        raise ValueError(f"level_grey needs {len(thresholds) + 1} entries, got {len(level_grey)}")
    frame = np.empty((timing.v_active, timing.h_active), dtype=np.int64)
    frame[:] = BACKGROUND_RGB
    levels, no_data = difference_levels(left, right, disparity, rectification, thresholds)
    grey_rgb = np.array([(v << 16) | (v << 8) | v for v in level_grey], dtype=np.int64)
    shift = _check_shift("rectification", rectification, signed=True)
    if row_tags is not None:
        left_tags, right_tags = row_tags
        row_tags = (list(engine_left(np.array(list(left_tags), dtype=object), shift)), list(right_tags))
    codes = depth_map(engine_left(left, shift), right, depth, row_tags=row_tags)
    pictures = {
        "left": grey_to_rgb24(left, geometry.grey_bits),
        "right": grey_to_rgb24(right, geometry.grey_bits),
        "disparity": np.where(no_data, NO_DATA_RGB, grey_rgb[levels]),
    }
    if segment:
        _check_segment_layout(layout)
        pictures["disparity"] = segment_picture(right, codes, disparity, geometry.grey_bits, depth)
    for region in layout.regions:
        if region.source in pictures:
            s, k = region.scale, region.shrink
            frame[region.y0:region.y1, region.x0:region.x1] = np.repeat(
                np.repeat(pictures[region.source][::k, ::k], s, axis=0), s, axis=1)
    text = draw_depth_display(frame, codes, layout, geometry, depth)
    if layout.band is not None:
        draw_text(frame, layout.band, band_text(disparity, geometry) if segment else blank_band_text())
    if layout.rectification is not None:
        draw_text(frame, layout.rectification, rectification_text(rectification, *rectification_mode))
    if details:
        return rgb24_to_bytes(frame), codes, text
    return rgb24_to_bytes(frame)
