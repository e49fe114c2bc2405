"""The tangent method (thesis 3.1.2, appendix A): slope matrices, its division by zero, and vertical shifts
recovered exactly on synthetic scenes and on the Middlebury motorcycle pair."""

import functools

import numpy as np
import pytest
from skimage import data

from golden.software.pipeline import estimate_vertical_shift, to_grey
from golden.software.rectify import (literal_shift, row_minima, shift_rows, slope_matrix, tangent_difference,
                                     vertical_shift)
from test_software_scenes import plane_pair, two_plane_pair


def test_slope_matrix_is_equation_3_14_by_hand():
    p = np.array([[10, 2], [4, 5], [7, 2]])          # (row y, column x)
    t = slope_matrix(p)
    assert t[0, 1] == (10 - 4) / (2 - 5) == t[1, 0]
    assert t[1, 2] == (4 - 7) / (5 - 2)
    assert np.isnan(t[0, 2]) and np.isnan(t[2, 0])    # equal x: vertical segment, no finite slope
    assert np.isnan(np.diag(t)).all()                 # c == t: 0 / 0


def _matlab_common_features(p1, p2):
    """Appendix A as Matlab evaluates it: unguarded IEEE division (+-Inf, NaN) and min(abs(x), [], 1),
    whose min skips NaN. Returns (r, c) per column, NaN/-1 for an all-NaN column."""
    with np.errstate(divide="ignore", invalid="ignore"):
        phi1 = (p1[:, None, 0] - p1[None, :, 0]) / (p1[:, None, 1] - p1[None, :, 1]).astype(float)
        phi2 = (p2[:, None, 0] - p2[None, :, 0]) / (p2[:, None, 1] - p2[None, :, 1]).astype(float)
        x = np.abs(phi1 - phi2)
    r = np.full(len(p1), np.nan)
    c = np.full(len(p1), -1)
    for col in range(len(p1)):
        column = x[:, col]
        if not np.isnan(column).all():
            c[col] = int(np.nanargmin(column))
            r[col] = column[c[col]]
    return r, c


def test_division_by_zero_rule_agrees_with_matlab_wherever_matlab_has_a_number():
    rng = np.random.default_rng(3)
    p1 = rng.integers(0, 12, size=(40, 2))            # small range: many equal x coordinates
    p2 = p1 + [2, -5]
    p2[::7] = rng.integers(0, 12, size=(len(p2[::7]), 2))
    val, col = row_minima(tangent_difference(p1, p2))
    r, c = _matlab_common_features(p1, p2)
    finite = np.isfinite(r)
    assert finite.sum() > 30
    assert np.array_equal(val[finite], r[finite])
    # the same minimum value; where it ties, Matlab and argmin both take the first index
    assert np.array_equal(col[finite], c[finite])
    assert (val[~finite] == np.inf).all() and (col[~finite] == -1).all()
    t = tangent_difference(p1, p2)
    assert np.array_equal(t, t.T) and (np.diag(t) == np.inf).all()


@pytest.mark.parametrize("shift", range(-6, 7))
@pytest.mark.parametrize("disparity", [0, 5, 17])
def test_shift_of_a_textured_plane_is_recovered_exactly(shift, disparity):
    left, right = plane_pair(120, 160, disparity, shift, seed=shift + 20)
    search = estimate_vertical_shift(left, right)
    assert search.shift == shift
    assert search.estimate.mean == shift              # every confirmed pair is a true correspondence
    assert search.estimate.direction == ("up" if shift > 0 else "down" if shift < 0 else "none")


def test_shift_of_a_two_plane_scene_is_recovered():
    left, right, _ = two_plane_pair(120, 160, 6, 18, (30, 90, 60, 120), vertical_shift=3)
    assert estimate_vertical_shift(left, right).shift == 3


@pytest.fixture(scope="module")
def true_pairs():
    left, right = plane_pair(120, 160, 9, 4)
    search = estimate_vertical_shift(left, right)
    true = np.all(search.matched_right - search.matched_left == [4, -9], axis=1)
    assert true.sum() > 100
    return search.matched_left[true], search.matched_right[true]


def _with_false_pairs(true_pairs, seed, count=30):
    """``count`` false pairs, each with its own row error of 11..40 rows and a random column error."""
    m1, m2 = true_pairs
    rng = np.random.default_rng(seed)
    false1 = rng.integers(10, 110, size=(count, 2))
    errors = np.stack([rng.permutation(np.arange(-40, -10))[:count], rng.integers(-30, 30, count)], axis=1)
    return np.vstack([m1, false1]), np.vstack([m2, false1 + errors])


@pytest.mark.parametrize("seed", range(5))
def test_tangent_check_removes_false_matches_that_bias_the_plain_mean(true_pairs, seed):
    p1, p2 = _with_false_pairs(true_pairs, seed)
    n_true = len(true_pairs[0])
    assert np.mean(p2[:, 0] - p1[:, 0]) < 0.5         # the plain mean of all pairs is off by > 3 rows
    est = vertical_shift(p1, p2)
    assert est.shift == 4 and est.mean == 4.0         # the confirmed pairs are exactly the true ones
    assert est.confirmed[:n_true].all() and not est.confirmed[n_true:].any()


def test_one_zero_per_row_lets_chance_slope_coincidences_through(true_pairs):
    """Why min_support defaults to 3: with the literal 'a zero in the row' some false pairs get confirmed."""
    n_true = len(true_pairs[0])
    let_through = [vertical_shift(*_with_false_pairs(true_pairs, seed), min_support=1).confirmed[n_true:].sum()
                   for seed in range(5)]
    assert sum(let_through) >= 5


def test_literal_reading_of_the_text_is_biased():
    """The thesis's sentence 'a minimum in row 4, column 5 matches feature 4 of the first image with feature 5
    of the second' averages y2[5] - y1[4]: with matched lists in the same order that is not the shift."""
    left, right = plane_pair(120, 160, 0, 3, seed=23)
    search = estimate_vertical_shift(left, right)
    assert search.shift == 3
    assert abs(literal_shift(search.matched_left, search.matched_right) - 3) > 1


def test_vertical_shift_needs_two_pairs_and_a_confirmed_one():
    with pytest.raises(ValueError):
        vertical_shift([[1, 2]], [[1, 2]])
    with pytest.raises(ValueError):                   # no segment keeps its slope
        vertical_shift([[0, 0], [5, 9]], [[0, 0], [7, 9]])


def test_shift_rows_moves_the_right_image_back_onto_the_left():
    left, right = plane_pair(60, 80, 0, 4)
    moved, valid = shift_rows(right, 4)
    assert np.array_equal(moved[valid], left[valid])
    assert valid.sum() == 56 and not valid[-4:].any()
    moved, valid = shift_rows(right, -2)
    assert not valid[:2].any() and np.array_equal(moved[2:], right[:-2])


@functools.cache
def _motorcycle_grey():
    left, right, _ = data.stereo_motorcycle()
    return to_grey(left), to_grey(right)


def _motorcycle_with_right_shifted(shift, margin=6):
    left, right = _motorcycle_grey()
    h = left.shape[0]
    # crop both so no row is invented: right row y shows the scene row y - shift of the left crop
    return left[margin:h - margin], right[margin - shift:h - margin - shift]


@pytest.mark.parametrize("shift", [s for s in range(-6, 7)])
def test_motorcycle_right_image_shifted_by_up_to_6_rows_is_rectified_back(shift):
    left, right = _motorcycle_with_right_shifted(shift)
    search = estimate_vertical_shift(left, right)
    assert search.shift == shift
    assert abs(search.estimate.mean - shift) < 0.25   # margin to the rounding boundary
