"""The left-right check from the same sums and the background fill (docs/depth.md, "left-right check"): the
golden stage on hand-made sums and codes."""

import numpy as np
import pytest

from golden.depth import background_fill, depth_map, left_right_keep, left_winner
from spec.depth import DepthConfig, SMALL_DEPTH

CFG = DepthConfig(disparities=4, lanes=2)
BIG = 400                       # a sum above every hand-made one


def sums(width, entries):
    """(D, 1, W) sums, BIG everywhere but ``entries``: {(d, x): S}."""
    total = np.full((CFG.disparities, 1, width), BIG, dtype=np.int32)
    for (d, x), value in entries.items():
        total[d, 0, x] = value
    return total


def test_left_winner_smallest_sum_then_smallest_d():
    # Left pixel 5: offers S(d, 5 - d); d = 1 and d = 3 tie at 7, d = 2 is 9: the smaller d wins the tie.
    total = sums(6, {(1, 4): 7, (3, 2): 7, (2, 3): 9})
    assert left_winner(total)[0, 5] == 1
    total[2, 0, 3] = 6                      # now d = 2 is strictly smallest
    assert left_winner(total)[0, 5] == 2


def test_left_winner_only_right_pixels_in_the_image():
    # Left pixel 1 is offered d = 0, 1 only (right pixels 1, 0); S(3, x) at x = 0 reaches left pixel 3, not 1.
    total = sums(6, {(3, 0): 1, (1, 0): 5})
    assert left_winner(total)[0, 1] == 1
    assert left_winner(total)[0, 3] == 3
    assert left_winner(total)[0, 0] == 0


def test_left_winner_against_the_rule_on_random_sums():
    rng = np.random.default_rng(3)
    total = rng.integers(0, 6, size=(5, 3, 9))         # small range: many ties
    found = left_winner(total)
    for y in range(3):
        for x in range(9):
            offers = [(total[d, y, x - d], d) for d in range(min(5, x + 1))]
            assert found[y, x] == min(offers)[1]


def codes_for(total):
    """Valid codes 16 d* (no fraction) for every pixel."""
    return (np.argmin(total, axis=0) * CFG.fraction).astype(np.uint16)


def test_tolerance_one_step():
    # Right pixel 0 wins d* = 2 (S 1); left pixel 2's winner: d = 1 (S(1, 1) = 0) -> |1 - 2| = 1: kept.
    total = sums(6, {(2, 0): 1, (1, 1): 0})
    assert left_right_keep(total, codes_for(total), CFG)[0, 0]
    # Left pixel 2's winner d = 0 (S(0, 2) = 0 below S(1, 1) = 0? a tie goes to d = 0): |0 - 2| = 2: not kept.
    total = sums(6, {(2, 0): 1, (1, 1): 0, (0, 2): 0})
    assert not left_right_keep(total, codes_for(total), CFG)[0, 0]
    # The same winner exactly: kept.
    total = sums(6, {(2, 0): 0})
    assert left_right_keep(total, codes_for(total), CFG)[0, 0]


def test_target_clamped_at_the_last_column():
    # Right pixel 4 of 6 wins d* = 3: x + d* = 7 -> left pixel 5, whose winner is d = 2 (S(2, 3) = 0): kept.
    total = sums(6, {(3, 4): 1, (2, 3): 0})
    assert left_winner(total)[0, 5] == 2
    assert left_right_keep(total, codes_for(total), CFG)[0, 4]
    total[0, 0, 5] = 0                  # left pixel 5's winner: d = 0 (the tie with d = 2): |0 - 3| = 3
    assert left_winner(total)[0, 5] == 0
    assert not left_right_keep(total, codes_for(total), CFG)[0, 4]


def test_invalid_codes_never_kept():
    total = sums(6, {(2, 0): 0})
    codes = codes_for(total)
    assert left_right_keep(total, codes, CFG)[0, 0]
    codes[0, 0] = CFG.invalid
    assert not left_right_keep(total, codes, CFG)[0, 0]


def test_fill_both_sides_one_side_none():
    inv = CFG.invalid
    codes = np.array([[10, 20, 30, 40, 50, 60],
                      [10, 20, 30, 40, 50, 60],
                      [10, 20, 30, 40, 50, 60],
                      [10, 20, 30, 40, 50, 60]], dtype=np.uint16)
    keep = np.array([[0, 1, 0, 0, 1, 0],              # both sides between the kept ones: the smaller (left)
                     [0, 0, 0, 0, 1, 0],              # one side only
                     [0, 0, 0, 0, 0, 0],              # none: invalid
                     [1, 0, 1, 0, 0, 0]], dtype=bool)
    codes[0, 4] = 15                                  # the right kept code the smaller one for columns 2, 3
    out = background_fill(codes, keep, CFG)
    assert out[0].tolist() == [20, 20, 15, 15, 15, 15]
    assert out[1].tolist() == [50, 50, 50, 50, 50, 50]
    assert out[2].tolist() == [inv] * 6
    assert out[3].tolist() == [10, 10, 30, 30, 30, 30]


def test_depth_map_with_the_check():
    rng = np.random.default_rng(5)
    right = rng.integers(0, 32, size=(12, 16))
    left = np.roll(right, 3, axis=1)
    config = DepthConfig(**{**SMALL_DEPTH.__dict__, "left_right": True})
    plain = depth_map(left, right, SMALL_DEPTH, details=True)
    result = depth_map(left, right, config, details=True)
    assert (result.raw == plain.raw).all()
    keep = left_right_keep(sum(plain.paths.values()), plain.raw, config)
    assert (result.checked == background_fill(plain.raw, keep, config)).all()
    assert (plain.checked == plain.raw).all()
    assert not keep.all() and keep.any()


def test_left_right_must_be_a_bool():
    with pytest.raises(ValueError, match="left_right"):
        DepthConfig(left_right=1)
