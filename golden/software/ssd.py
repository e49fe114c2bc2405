"""Matching Harris corners between the two images by the sum of squared differences (thesis eq. 3.13).

    F = sum over (i, j) in W of (I1(i, j) - I2(x + i, y + j))^2                                   (3.13)

Each corner's neighbourhood W is the (2 ``half`` + 1)^2 patch centred on it. A left corner and a right corner
are paired when each is the other's smallest-SSD partner (mutual best match): the thesis keeps the pairs with a
small SSD and admits that some are false; the tangent method (rectify.py) then screens them. The search is
limited to a plausible stereo geometry: at most ``max_vertical_shift`` rows apart and, when ``max_disparity``
is given, the right corner at most that many columns left of the left one (``-max_disparity <= x_r - x_l <=
0`` with a one-column allowance for corner jitter). See docs/software.md for these choices.
"""

import numpy as np

__all__ = ["PATCH_HALF", "MAX_VERTICAL_SHIFT", "ssd", "patches", "ssd_matrix", "match_corners"]

PATCH_HALF = 5             # 11 x 11 neighbourhoods
MAX_VERTICAL_SHIFT = 16    # rows; the thesis found 3 for its webcams


def ssd(patch_a, patch_b):
    """Equation 3.13 for two equal-sized patches."""
    a = np.asarray(patch_a, dtype=np.float64)
    b = np.asarray(patch_b, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError(f"patches differ in shape: {a.shape} and {b.shape}")
    return float(((a - b) ** 2).sum())


def _inside(image, points, half):
    h, w = image.shape
    p = np.asarray(points, dtype=np.int64).reshape(-1, 2)
    return (p[:, 0] >= half) & (p[:, 0] < h - half) & (p[:, 1] >= half) & (p[:, 1] < w - half)


def patches(image, points, half=PATCH_HALF):
    """The flattened (2 half + 1)^2 neighbourhoods of ``points`` (all must lie ``half`` inside the image)."""
    image = np.asarray(image, dtype=np.float64)
    p = np.asarray(points, dtype=np.int64).reshape(-1, 2)
    if not _inside(image, p, half).all():
        raise ValueError(f"a point lies closer than {half} pixels to the image edge")
    offsets = np.arange(-half, half + 1)
    rows = p[:, 0, None, None] + offsets[None, :, None]
    cols = p[:, 1, None, None] + offsets[None, None, :]
    return image[rows, cols].reshape(len(p), -1)


def ssd_matrix(image1, points1, image2, points2, half=PATCH_HALF):
    """S[i, j] = SSD (eq. 3.13) between the neighbourhood of points1[i] in image1 and points2[j] in image2."""
    a = patches(image1, points1, half)
    b = patches(image2, points2, half)
    # |a - b|^2 = |a|^2 + |b|^2 - 2 a.b ; exact for integer-valued grey levels (well below 2^53)
    s = (a * a).sum(1)[:, None] + (b * b).sum(1)[None, :] - 2.0 * (a @ b.T)
    return np.maximum(s, 0.0)


def match_corners(image1, points1, image2, points2, half=PATCH_HALF,
                  max_vertical_shift=MAX_VERTICAL_SHIFT, max_disparity=None):
    """Pair corners of image1 (left, reference) with corners of image2 (right) by mutual smallest SSD.

    Returns ``(matched1, matched2, cost)``: two (M, 2) int arrays of (row, column), matched1[m] <-> matched2[m],
    and the SSD of each pair, in the order of ``points1``. Points whose patch leaves the image are ignored.
    """
    p1 = np.asarray(points1, dtype=np.int64).reshape(-1, 2)
    p2 = np.asarray(points2, dtype=np.int64).reshape(-1, 2)
    p1 = p1[_inside(np.asarray(image1), p1, half)]
    p2 = p2[_inside(np.asarray(image2), p2, half)]
    empty = np.zeros((0, 2), dtype=np.int64)
    if len(p1) == 0 or len(p2) == 0:
        return empty, empty, np.zeros(0)
    s = ssd_matrix(image1, p1, image2, p2, half)
    allowed = np.abs(p2[None, :, 0] - p1[:, None, 0]) <= max_vertical_shift
    if max_disparity is not None:
        dx = p2[None, :, 1] - p1[:, None, 1]        # right column - left column = -disparity
        allowed &= (dx <= 1) & (dx >= -max_disparity - 1)
    s = np.where(allowed, s, np.inf)
    best2 = np.argmin(s, axis=1)                    # for each left corner, its best right corner
    best1 = np.argmin(s, axis=0)                    # for each right corner, its best left corner
    i = np.arange(len(p1))
    mutual = (best1[best2] == i) & np.isfinite(s[i, best2])
    i = i[mutual]
    return p1[i], p2[best2[i]], s[i, best2[i]]
