"""Disparity by shift-and-subtract, SAD window aggregation and winner-take-all (thesis 3.2, eq. 3.16).

"Disparity values are evaluated keeping one of the images constant, and shifting the other horizontally.
After each shifting operation, the images are subtracted from each other and these subtraction values are
stored as cost values." Here the left image is the reference (like the Middlebury ground truth): a scene point
at column x of the left image is at column x - d of the right image, so for each candidate d

    C_d(y, x) = | L(y, x) - R(y, x - d) |                                   (shift and subtract)
    S_d(y, x) = sum of C_d over the w x w window around (y, x)               (SAD, eq. 3.16)
    D(y, x)   = the d in 0..max_disparity with the smallest S_d(y, x)        (winner-take-all)

Conventions (docs/software.md):

* the w x w window covers rows y - w//2 .. y + w - 1 - w//2 (and the same for columns): centred for odd w,
  one pixel more above/left than below/right for even w (the thesis's 30 x 30);
* near the image border the window is cut to the part inside the image; the cut is the same for every d at a
  pixel, so it does not bias the choice;
* where x - d < 0 the right image is extended by repeating its first column (inside windows), and d is not a
  candidate for a pixel whose own x - d < 0 (cost = +inf): the left ``d`` columns cannot see disparity ``d``;
* ties go to the smallest disparity.

The window sums use an integral image (summed-area table), so the cost per pixel does not depend on w.
``sad_disparity`` keeps only the running minimum (memory of one image, not of the cost volume);
``sad_cost_volume`` + ``winner_take_all`` build the whole volume and give the same result.
"""

import numpy as np

__all__ = ["SAD_WINDOWS", "SAD_WINDOW", "MAX_DISPARITY", "shift_and_subtract", "integral_image", "box_sum",
           "sad_cost_volume", "winner_take_all", "sad_disparity"]

SAD_WINDOWS = (9, 15, 30)   # the window sizes the thesis tries (3.2.1, 3.3.1)
SAD_WINDOW = 30             # the one its distance map (figure 3.17) uses
MAX_DISPARITY = 63          # 64 candidates 0..63 (OpenCV's numDisparities=64; motorcycle disparities < 60)


def _as_grey(image, name):
    a = np.asarray(image)
    if a.ndim != 2:
        raise ValueError(f"{name} must be a 2-D grey image, got shape {a.shape}")
    return a.astype(np.int64) if a.dtype.kind in "iub" else a.astype(np.float64)


def _check(left, right, max_disparity, window):
    left, right = _as_grey(left, "left"), _as_grey(right, "right")
    if left.shape != right.shape:
        raise ValueError(f"left {left.shape} and right {right.shape} images differ in size")
    if not (isinstance(window, (int, np.integer)) and window >= 1):
        raise ValueError(f"SAD window must be a whole number >= 1, not {window!r}")
    if not (isinstance(max_disparity, (int, np.integer)) and 0 <= max_disparity < left.shape[1]):
        raise ValueError(f"max disparity must be a whole number in 0..{left.shape[1] - 1}, not {max_disparity!r}")
    return left, right


def shift_and_subtract(left, right, d):
    """C_d = |L(y, x) - R(y, x - d)|, the right image extended to the left by its first column."""
    left, right = _as_grey(left, "left"), _as_grey(right, "right")
    cols = np.clip(np.arange(left.shape[1]) - d, 0, None)
    return np.abs(left - right[:, cols])


def integral_image(image):
    """Summed-area table with a leading row and column of zeros: I[y, x] = sum of image[:y, :x]."""
    a = np.asarray(image)
    out = np.zeros((a.shape[0] + 1, a.shape[1] + 1), dtype=np.int64 if a.dtype.kind in "iub" else np.float64)
    np.cumsum(a, axis=0, out=out[1:, 1:])
    np.cumsum(out[1:, 1:], axis=1, out=out[1:, 1:])
    return out


def _window_bounds(n, window):
    lo = np.arange(n) - window // 2
    return np.clip(lo, 0, n), np.clip(lo + window, 0, n)


def box_sum(image, window):
    """Sum of ``image`` over the ``window`` x ``window`` window at every pixel (cut at the border)."""
    s = integral_image(image)
    y0, y1 = _window_bounds(s.shape[0] - 1, window)
    x0, x1 = _window_bounds(s.shape[1] - 1, window)
    return s[np.ix_(y1, x1)] - s[np.ix_(y0, x1)] - s[np.ix_(y1, x0)] + s[np.ix_(y0, x0)]


def sad_cost_volume(left, right, max_disparity=MAX_DISPARITY, window=SAD_WINDOW):
    """S[d, y, x] for d = 0..max_disparity, +inf where x < d. (max_disparity + 1) x H x W floats."""
    left, right = _check(left, right, max_disparity, window)
    volume = np.empty((max_disparity + 1,) + left.shape)
    for d in range(max_disparity + 1):
        volume[d] = box_sum(shift_and_subtract(left, right, d), window)
        volume[d, :, :d] = np.inf
    return volume


def winner_take_all(volume):
    """The disparity of the smallest cost at each pixel (first = smallest d on ties)."""
    return np.argmin(np.asarray(volume), axis=0).astype(np.int16)


def sad_disparity(left, right, max_disparity=MAX_DISPARITY, window=SAD_WINDOW, progress=None):
    """The winner-take-all SAD disparity map (int16, 0..max_disparity) of the left image. ``progress(fraction)``,
    if given, is called after each candidate disparity."""
    left, right = _check(left, right, max_disparity, window)
    best = np.full(left.shape, np.inf)
    disparity = np.zeros(left.shape, dtype=np.int16)
    for d in range(max_disparity + 1):
        cost = box_sum(shift_and_subtract(left, right, d), window).astype(np.float64)
        cost[:, :d] = np.inf
        better = cost < best
        best[better] = cost[better]
        disparity[better] = d
        if progress:
            progress((d + 1) / (max_disparity + 1))
    return disparity
