"""The thesis's tangent (slope) method: vertical shift between the two images (section 3.1.2, appendix A).

Given the SSD-matched corner lists F1 (left) and F2 (right), F1[i] <-> F2[i]:

    T1[c, t] = (y1_c - y1_t) / (x1_c - x1_t)     slope of the segment between features c and t, image 1  (3.14)
    T2[c, t] = (y2_c - y2_t) / (x2_c - x2_t)     the same segment in image 2
    T        = |T1 - T2|                                                                                (3.15)

and "the zeros or the minimum values are searched in each row" of T. A vertical shift moves every feature of
one image by the same number of rows, so it cancels in every slope: T does not measure the shift, it tests the
matches. A pair i whose row of T holds a zero keeps the slope of at least one of its segments across the two
images, i.e. is geometrically consistent with another pair; the vertical shift is the mean of y2_i - y1_i (the
"row values of the first image subtracted from the second") over those confirmed pairs, rounded half away
from zero to whole rows. Its sign gives the direction: positive = the right (processing) image is lower and
must move up by that many rows.

"Zero" is exact by default (``tolerance=0``): corner positions are integers, every slope is a ratio of
integers, and IEEE division is correctly rounded, so two slopes compare equal exactly when the two ratios are
equal. A positive ``tolerance`` accepts near-zeros ("or the minimum values").

A single zero is weak evidence: segments between integer points often share a simple slope by chance (4/1 =
56/14), and in tests/test_software_rectify.py 17 of 150 random false pairs find such a partner. A true
pair has a zero with every other true pair at the same depth. So a pair needs ``min_support`` = 3 zeros in its
row by default (``min_support=1`` is the thesis's literal "a zero in the row"); docs/software.md.

Read literally, the thesis says the minimum in row i, column j "matches feature i of the first image with
feature j of the second" and averages y2_j - y1_i. With two matched lists in the same order this is biased by
y1_j - y1_i (the minimum of row i is never on the diagonal, which is 0/0); ``literal_shift`` computes that
reading so the difference can be shown (tests/test_software_rectify.py), ``vertical_shift`` is the method used.

Division by zero (the Matlab code divides by x_c - x_t unguarded): a segment with equal x coordinates, and the
diagonal c = t, has no finite slope. Matlab yields +-Inf or NaN there and its ``min`` skips NaN; here such an
entry of T is +inf whenever the segment is vertical in either image, so it never wins a row minimum. A row
with no finite entry confirms nothing. This equals Matlab's result except for two segments vertical in both
images (NaN = skipped in Matlab, +inf here: also never the minimum of a row that has a finite entry).
"""

from dataclasses import dataclass

import numpy as np

__all__ = ["SLOPE_TOLERANCE", "MIN_SUPPORT", "slope_matrix", "tangent_difference", "row_minima", "ShiftEstimate",
           "vertical_shift", "literal_shift", "shift_rows"]

SLOPE_TOLERANCE = 0.0     # an entry of T at most this counts as a zero (exact slope equality by default)
MIN_SUPPORT = 3           # zeros a row of T needs to confirm its pair (1 = the thesis read literally)


def slope_matrix(points):
    """T[c, t] = (y_c - y_t) / (x_c - x_t) for (row, column) ``points``; NaN where x_c == x_t (incl. c == t)."""
    p = np.asarray(points, dtype=np.float64).reshape(-1, 2)
    dy = p[:, None, 0] - p[None, :, 0]
    dx = p[:, None, 1] - p[None, :, 1]
    slope = np.full(dy.shape, np.nan)
    np.divide(dy, dx, out=slope, where=dx != 0)
    return slope


def tangent_difference(points1, points2):
    """T = |T1 - T2| (eq. 3.15), +inf where either segment is vertical (and on the diagonal)."""
    p1 = np.asarray(points1).reshape(-1, 2)
    p2 = np.asarray(points2).reshape(-1, 2)
    if p1.shape != p2.shape:
        raise ValueError(f"matched lists differ in length: {len(p1)} and {len(p2)}")
    t = np.abs(slope_matrix(p1) - slope_matrix(p2))
    t[np.isnan(t)] = np.inf
    return t


def row_minima(t):
    """(minimum, column of the minimum) of each row of T; (inf, -1) for a row with no finite entry.
    T is symmetric, so this equals the column-wise ``min(abs(x), [], 1)`` of the appendix code."""
    t = np.asarray(t)
    if t.shape[0] == 0:
        return np.zeros(0), np.zeros(0, dtype=np.int64)
    col = np.argmin(t, axis=1)
    val = t[np.arange(len(t)), col]
    col = np.where(np.isfinite(val), col, -1)
    return val, col


@dataclass(frozen=True)
class ShiftEstimate:
    """Result of the tangent method. ``shift`` > 0: the right image is ``shift`` rows lower than the left."""
    shift: int                 # rounded mean, whole rows
    mean: float                # mean of y2 - y1 over the confirmed pairs (nan if none)
    confirmed: np.ndarray      # bool per matched pair
    support: np.ndarray        # zeros (entries <= tolerance) in each row of T
    row_minimum: np.ndarray    # min of each row of T
    partner: np.ndarray        # column of that minimum (-1 if none)

    @property
    def direction(self):
        """How the right (processing) image must move to line up with the left one."""
        return "up" if self.shift > 0 else "down" if self.shift < 0 else "none"


def _round_half_away(value):
    return int(np.sign(value) * np.floor(abs(value) + 0.5))


def vertical_shift(points1, points2, tolerance=SLOPE_TOLERANCE, min_support=MIN_SUPPORT):
    """The vertical shift between matched lists ``points1`` (left) and ``points2`` (right) by the tangent method.

    Pair i is confirmed when row i of T has at least ``min_support`` entries <= ``tolerance``.

    Raises ValueError when fewer than two pairs are given or no pair is confirmed.
    """
    p1 = np.asarray(points1, dtype=np.int64).reshape(-1, 2)
    p2 = np.asarray(points2, dtype=np.int64).reshape(-1, 2)
    if len(p1) < 2:
        raise ValueError(f"the tangent method needs at least 2 matched features, got {len(p1)}")
    if tolerance < 0 or min_support < 1:
        raise ValueError("tolerance must be >= 0 and min_support >= 1")
    t = tangent_difference(p1, p2)
    val, col = row_minima(t)
    support = (t <= tolerance).sum(axis=1)
    confirmed = support >= min_support
    if not confirmed.any():
        raise ValueError("no matched feature keeps its slopes between the images: vertical shift unknown")
    mean = float(np.mean(p2[confirmed, 0] - p1[confirmed, 0]))
    return ShiftEstimate(_round_half_away(mean), mean, confirmed, support, val, col)


def literal_shift(points1, points2):
    """The thesis text read literally: mean over rows i of y2[j_i] - y1[i], j_i the column of row i's minimum."""
    p1 = np.asarray(points1, dtype=np.int64).reshape(-1, 2)
    p2 = np.asarray(points2, dtype=np.int64).reshape(-1, 2)
    _, col = row_minima(tangent_difference(p1, p2))
    ok = col >= 0
    return float(np.mean(p2[col[ok], 0] - p1[ok, 0]))


def shift_rows(image, shift):
    """Move ``image`` up by ``shift`` rows (down if negative): out[y] = image[y + shift].

    Returns ``(shifted, valid_rows)``; rows with no source row are filled by the nearest edge row and marked
    False in ``valid_rows``.
    """
    image = np.asarray(image)
    h = image.shape[0]
    src = np.arange(h) + int(shift)
    valid = (src >= 0) & (src < h)
    return image[np.clip(src, 0, h - 1)], valid
