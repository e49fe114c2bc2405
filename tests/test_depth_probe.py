"""The depth probe's own stages (bench/bench_depth_probe.py) against plain loops written from their docstrings."""

import numpy as np

from bench.bench_depth_probe import background_fill, left_right_consistent, stored_row
from golden.depth import path_cost
from spec.depth import SMALL_DEPTH

INVALID = 999


def _consistent_by_loops(total, raw):
    d_count, h, w = total.shape
    out = np.zeros((h, w), dtype=bool)
    for y in range(h):
        left_winner = []
        for xl in range(w):
            sums = [total[d, y, xl - d] for d in range(min(d_count - 1, xl) + 1)]
            left_winner.append(int(np.argmin(sums)))          # first minimum: the smallest d
        for x in range(w):
            d = int(np.argmin(total[:, y, x]))
            out[y, x] = raw[y, x] != INVALID and abs(left_winner[min(x + d, w - 1)] - d) <= 1
    return out


def test_left_right_check_equals_its_loops():
    rng = np.random.default_rng(7)
    total = rng.integers(0, 12, size=(6, 5, 17)).astype(np.int32)     # small range: many ties
    raw = np.where(rng.random((5, 17)) < 0.1, INVALID, 16 * np.argmin(total, axis=0)).astype(np.uint16)
    config = type("Config", (), {"invalid": INVALID})()
    assert np.array_equal(left_right_consistent(total, raw, config), _consistent_by_loops(total, raw))


def test_background_fill_takes_the_farther_neighbour():
    codes = np.array([[10, 50, 50, 20, 30], [40, 41, 42, 43, 44], [5, 6, 7, 8, 9]], dtype=np.uint16)
    keep = np.array([[1, 0, 0, 1, 0], [0, 0, 0, 0, 0], [0, 1, 0, 0, 1]], dtype=bool)
    assert background_fill(codes, keep, INVALID).tolist() == [[10, 10, 10, 20, 20], [INVALID] * 5, [6, 6, 6, 6, 9]]


def test_line_buffer_of_clamped_differences_is_exact():
    """The vertical recursion from l = min(L - M, P2) of the row above gives the golden path costs."""
    rng = np.random.default_rng(3)
    cost = rng.integers(0, SMALL_DEPTH.census_bits + 1, size=(SMALL_DEPTH.disparities, 9, 12)).astype(np.int32)
    golden = path_cost(cost, "top_to_bottom", SMALL_DEPTH).astype(np.int32)
    above = np.zeros_like(cost[:, 0, :])
    for y in range(cost.shape[1]):
        prev = stored_row(above, SMALL_DEPTH.p2, 0) if y else above
        best = np.minimum(prev, SMALL_DEPTH.p2)
        best[1:] = np.minimum(best[1:], prev[:-1] + SMALL_DEPTH.p1)
        best[:-1] = np.minimum(best[:-1], prev[1:] + SMALL_DEPTH.p1)
        above = cost[:, y, :] + best                      # M' = 0: the stored row's minimum is 0
        assert np.array_equal(above, golden[:, y, :]), y
