"""Ground truth for depth maps at buffer resolution, and the bad-pixel figures (docs/depth.md, bench/bench_depth.py).

* :func:`motorcycle_truth`: Middlebury's motorcycle disparity at every buffer pixel, in buffer pixels.
  ``view="left"`` samples Middlebury's map of the left image (``sim.analysis.disparity_pictures.ground_truth``).
  ``view="right"`` (the depth engine's reference image) is made from it, since scikit-image ships only the
  left map: along each original row, left pixel x is seen in the right image at x - d(x); between two
  neighbouring left pixels on one surface (disparities within 2 original pixels) the disparity is interpolated
  linearly at the right image's sample columns, the nearest surface wins where several land on one column, and
  a column that no surface reaches but lies in the gap a disparity drop opens (seen by the right camera only,
  hidden from the left one) gets the farther surface's disparity. Where the left map has no value, nothing is
  made. Original disparities are scaled to buffer pixels by the fit's horizontal factor (1600 / 667 / 4).
* :func:`right_view`: the same conversion for any left-view map at its own resolution (every original column).
* :func:`scene_truth`: the disparity of a synthetic scene (sim/testbed/scene.py) at the buffer pixels of one camera.
  Every map's sample point is the kept pixel's centre, or the block's centre for an averaging capture
  (:func:`sample_centre`).
* :func:`bad_pixel_rates`: bad > 1 and bad > 2 over every pixel with a truth (an invalid pixel counts bad),
  and the density (valid share of those pixels).
* :func:`error_figures`: bad > 0.5, bad > 1, bad > 2 (invalid counts bad), the mean absolute error of the valid
  pixels with a truth, and the density.
"""

import numpy as np

from spec.sensor import SENSOR

__all__ = ["motorcycle_truth", "scene_truth", "bad_pixel_rates", "error_figures", "right_view"]

SAME_SURFACE = 2.0      # original pixels: neighbours closer than this in disparity lie on one surface


def sample_centre(geometry):
    """Where a buffer pixel's sample lies in its ``scale`` x ``scale`` block (sensor pixels from the block's
    corner): the kept pixel's centre (0.5), or the block's centre for the averaging capture."""
    return geometry.scale / 2 if geometry.downscale == "average" else 0.5


def _sample_grid(geometry, crop_w, crop_h):
    i, j = np.arange(geometry.buf_height), np.arange(geometry.buf_width)
    c = sample_centre(geometry)
    rows = np.rint((geometry.scale * i + c) * crop_h / geometry.height - 0.5).astype(int).clip(0, crop_h - 1)
    cols = (geometry.scale * j + c) * crop_w / geometry.width - 0.5       # continuous original columns
    return rows, cols


def _right_row(disparity, cols):
    """The right view's disparity at the continuous original columns ``cols`` of one row (NaN = none)."""
    d = np.where(np.isfinite(disparity), disparity, np.nan).astype(np.float64)
    seen = np.arange(d.size) - d                   # where each left pixel lands in the right image
    da, db, pa, pb = d[:-1], d[1:], seen[:-1], seen[1:]
    out = np.full(cols.size, np.nan)
    both = ~(np.isnan(da) | np.isnan(db))
    surface = both & (np.abs(da - db) <= SAME_SURFACE)
    gap = both & (db < da - SAME_SURFACE)
    for k in np.flatnonzero(surface | gap):
        lo, hi = min(pa[k], pb[k]), max(pa[k], pb[k])
        if surface[k]:
            sel = (cols >= lo) & (cols <= hi)
            if not sel.any():
                continue
            t = (cols[sel] - pa[k]) / (pb[k] - pa[k]) if pb[k] != pa[k] else 0.0
            value = da[k] + t * (db[k] - da[k])
        else:
            sel = (cols > lo) & (cols < hi)
            value = db[k]
        out[sel] = np.fmax(out[sel], value)
    return out


def motorcycle_truth(view="right", geometry=SENSOR):
    """(H, W) float disparities in buffer pixels of the bundled motorcycle pair's ``view``; NaN = unknown."""
    from PIL import Image

    from golden.stereo_pair import DATA_DIR
    from sim.analysis.disparity_pictures import _middlebury, crop_offset, ground_truth
    if view == "left":
        return ground_truth(geometry)[0]
    if view != "right":
        raise ValueError(f"view must be 'left' or 'right', not {view!r}")
    _, disparity = _middlebury()
    x0 = crop_offset()
    crop_w, crop_h = Image.open(DATA_DIR / "motorcycle_left.png").size
    rows, cols = _sample_grid(geometry, crop_w, crop_h)
    truth = np.stack([_right_row(disparity[r], cols + x0) for r in rows])
    return truth * geometry.width / crop_w / geometry.scale


def right_view(left_disparity):
    """The right view's disparity (H x W, original pixels, NaN = none) made from a left-view map of the same
    size, row by row as for the motorcycle (surfaces interpolated, the nearest wins, disocclusions take the
    farther surface), sampled at every original column."""
    left_disparity = np.asarray(left_disparity, dtype=np.float64)
    cols = np.arange(left_disparity.shape[1], dtype=np.float64)
    return np.stack([_right_row(row, cols) for row in left_disparity])


def scene_truth(scene, rig, geometry=SENSOR, side="right"):
    """Disparity (buffer pixels) of the object seen at each buffer pixel of camera ``side`` (NaN: the empty
    white background, which has no distance). Exact for fronto-parallel objects and aligned cameras."""
    from sim.testbed.scene import _as_objects, object_footprint
    objects = _as_objects(scene)
    truth = np.full((geometry.buf_height, geometry.buf_width), np.nan)
    for index, obj in enumerate(objects):
        mask = object_footprint(objects, rig, side=side, scale=geometry.scale, index=index,
                                centre=sample_centre(geometry))
        truth[mask] = rig.disparity_px(obj.distance_m) / geometry.scale
    return truth


def bad_pixel_rates(disparity, valid, truth):
    """(bad > 1, bad > 2, density) over the pixels where ``truth`` is known; invalid pixels count bad."""
    known = np.isfinite(truth)
    err = np.where(valid, np.abs(np.asarray(disparity, dtype=np.float64) - np.where(known, truth, 0)), np.inf)
    err = err[known]
    return float(np.mean(err > 1)), float(np.mean(err > 2)), float(np.mean(np.asarray(valid)[known]))


def error_figures(disparity, valid, truth):
    """(bad > 0.5, bad > 1, bad > 2, mean absolute error of the valid pixels, density) over the pixels where
    ``truth`` is known; invalid pixels count bad."""
    known = np.isfinite(truth)
    valid = np.asarray(valid)
    err = np.where(valid, np.abs(np.asarray(disparity, dtype=np.float64) - np.where(known, truth, 0)), np.inf)[known]
    finite = err[np.isfinite(err)]
    mae = float(finite.mean()) if finite.size else float("nan")
    return (float(np.mean(err > 0.5)), float(np.mean(err > 1)), float(np.mean(err > 2)), mae,
            float(np.mean(valid[known])))
