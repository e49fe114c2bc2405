"""The depth golden model (golden/depth.py) against hand-worked cases and independent formulations of
docs/depth.md, and its arithmetic bounds (hypothesis)."""

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.ndimage import median_filter

from golden.depth import (census, depth_map, matching_cost, median3x3, path_cost, path_step, second_best, subpixel,
                          winner)
from spec.depth import DEPTH, DepthConfig

SMALL = DepthConfig(disparities=4, census_width=3, census_height=3, lanes=2)


def test_census_by_hand():
    """3 x 3 census, bit k = window position k in raster order (centre skipped), 1 iff darker than the centre;
    outside the image the nearest pixel (a corner sees itself three times: equal, so 0)."""
    image = np.array([[5, 1, 9],
                      [3, 4, 4],
                      [8, 0, 2]])
    c = census(image, SMALL)
    # centre (1, 1) = 4: neighbours 5 1 9 / 3 _ 4 / 8 0 2 -> darker: 1 (bit 1), 3 (bit 3), 0 (bit 6), 2 (bit 7)
    assert int(c[1, 1]) == 0b11001010
    # corner (0, 0) = 5: window rows (0, 0, 1) cols (0, 0, 1): 5 5 1 / 5 _ 1 / 3 3 4 -> all but the 5s darker
    assert int(c[0, 0]) == 0b11110100


def test_cost_out_of_image_is_largest():
    rng = np.random.default_rng(0)
    left, right = rng.integers(0, 32, (5, 6)), rng.integers(0, 32, (5, 6))
    cost = matching_cost(left, right, SMALL)
    for d in range(SMALL.disparities):
        assert (cost[d, :, 6 - d:] == SMALL.census_bits).all()
    cl, cr = census(left, SMALL), census(right, SMALL)
    assert cost[2, 3, 1] == bin(int(cr[3, 1]) ^ int(cl[3, 3])).count("1")


def _path_loop(cost, p1, p2):
    """The path recursion of docs/depth.md with Python loops over one line of pixels (cost: D x n)."""
    d_count, n = cost.shape
    out = np.zeros_like(cost)
    prev = [0] * d_count
    for x in range(n):
        m = min(prev)
        for d in range(d_count):
            terms = [prev[d], m + p2]
            if d >= 1:
                terms.append(prev[d - 1] + p1)
            if d + 1 < d_count:
                terms.append(prev[d + 1] + p1)
            out[d, x] = cost[d, x] + min(terms) - m
        prev = list(out[:, x])
    return out


def test_paths_equal_a_loop_formulation():
    cost = np.random.default_rng(3).integers(0, 49, (8, 5, 7))
    cfg = DepthConfig(disparities=8, lanes=4)
    horizontal, vertical = path_cost(cost, "left_to_right", cfg), path_cost(cost, "top_to_bottom", cfg)
    for y in range(5):
        assert (horizontal[:, y, :] == _path_loop(cost[:, y, :], cfg.p1, cfg.p2)).all()
    for x in range(7):
        assert (vertical[:, :, x] == _path_loop(cost[:, :, x], cfg.p1, cfg.p2)).all()


def test_winner_ties_and_validity():
    """Whole pixels (F = 0): the code is d*."""
    cfg = DepthConfig(disparities=4, lanes=2, max_cost=10, fraction_bits=0)
    total = np.array([[[5, 5, 11, 3]], [[5, 4, 12, 3]], [[7, 4, 11, 3]], [[6, 9, 11, 2]]])   # D x 1 x 4
    codes, best = winner(total, cfg)
    assert codes.tolist() == [[0, 1, 4, 4]]            # tie -> smaller d; 11 > 10 invalid; d = D-1 invalid
    assert best.tolist() == [[5, 4, 11, 2]]


def _fit(a, b, c, d=1, config=DepthConfig(disparities=4, lanes=2, max_cost=200)):
    """The fraction q of a winner at ``d`` with S(d - 1), S(d), S(d + 1) = a, b, c (the rest large)."""
    total = np.full((config.disparities, 1, 1), 250)
    total[d - 1, 0, 0], total[d, 0, 0], total[d + 1, 0, 0] = a, b, c
    return int(subpixel(total, np.array([[d]]), config)[0, 0]), int(winner(total, config)[0][0, 0])


def test_subpixel_by_hand():
    """q = floor((16 (a - c) + e) / (2 e)), e = max(a, c) - b: the equiangular fit n / (2 e) in 1/16 pixel,
    rounded half up; the code is 16 d* + q."""
    assert _fit(10, 4, 6) == (5, 16 + 5)                # n = 4, e = 6: 4/12 = 5.33/16 -> 5
    assert _fit(10, 4, 4) == (8, 16 + 8)                # flat to the right: +1/2, the largest
    assert _fit(4 + 7, 4, 4 + 7) == (0, 16)             # symmetric: 0
    assert _fit(5, 4, 12) == (-7, 16 - 7)               # n = -7, e = 8: -7/16 exactly
    assert _fit(5, 4, 250) == (-8, 16 - 8)              # steep to the right: -1/2 (n = -245, e = 246 -> -7.97)
    assert _fit(20, 4, 19) == (1, 17)                   # n = 1, e = 16: +0.5/16 rounds up to 1
    assert _fit(19, 4, 20) == (0, 16)                   # n = -1, e = 16: -0.5/16 rounds up to 0
    assert _fit(19, 4, 21) == (-1, 15)                  # n = -2, e = 17: -0.94/16 -> -1


def test_subpixel_ends_and_validity_boundary():
    """d* = 0: no fraction; d* = D - 1: invalid; S* = max_cost valid, max_cost + 1 invalid."""
    cfg = DepthConfig(disparities=4, lanes=2, max_cost=30)
    total = np.array([[[3, 9, 40, 40, 40]], [[9, 9, 30, 31, 40]], [[9, 3, 35, 36, 40]], [[9, 1, 40, 40, 2]]])
    codes, best = winner(total, cfg)
    # x = 0: d* = 0 -> 0; x = 1: d* = 3 = D - 1 -> invalid; x = 2: S* = 30 = max_cost -> valid, d* = 1:
    # a = 40, b = 30, c = 35: e = 10, n = 5 -> floor(90 / 20) = 4; x = 3: S* = 31 -> invalid.
    assert codes.tolist() == [[0, cfg.invalid, 16 + 4, cfg.invalid, cfg.invalid]]
    assert cfg.invalid == 64 and codes.dtype == np.uint16


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(0, 2 * DEPTH.path_max), min_size=DEPTH.disparities, max_size=DEPTH.disparities))
def test_subpixel_matches_the_rounded_fit(sums):
    """q is the real equiangular offset n / (2 e) rounded half up to 1/16, in -8..8; a valid code's whole part
    (code + 8) // 16 is d*."""
    total = np.array(sums)[:, None, None]
    d = np.argmin(total, axis=0)
    q = int(subpixel(total, d, DEPTH)[0, 0])
    k = int(d[0, 0])
    if 0 < k < DEPTH.disparities - 1:
        a, b, c = sums[k - 1], sums[k], sums[k + 1]
        exact = Fraction(a - c, 2 * (max(a, c) - b))
        assert q == int(np.floor(exact * 16 + Fraction(1, 2)))
        assert -8 <= q <= 8
    else:
        assert q == 0


def test_median_equals_scipy_nearest():
    codes = np.random.default_rng(4).integers(0, 65, (9, 11))
    assert (median3x3(codes) == median_filter(codes, size=3, mode="nearest")).all()


def test_shifted_texture_gives_the_shift():
    """right(x) = left(x + 5) on a random texture: disparity 5 (code 80) everywhere away from the borders, the
    fraction within 1/8 pixel; whole pixels (F = 0): exactly 5."""
    texture = np.random.default_rng(5).integers(0, 32, (40, 80))
    left, right = texture[:, :75], texture[:, 5:]
    codes = depth_map(left, right, DepthConfig(disparities=16, lanes=4)).astype(int)
    assert (np.abs(codes[3:-3, 3:60] - 80) <= 2).mean() > 0.98
    codes = depth_map(left, right, DepthConfig(disparities=16, lanes=4, fraction_bits=0))
    assert (codes[3:-3, 3:60] == 5).mean() > 0.98


@settings(max_examples=40, deadline=None)
@given(st.data())
def test_path_values_never_leave_their_width(data):
    """Any costs 0..N and any P1 <= P2: every path value lies in 0..N + P2 (the documented width, no
    saturation), and every sum in 0..2 (N + P2)."""
    p2 = data.draw(st.integers(0, 200))
    cfg = DepthConfig(disparities=data.draw(st.sampled_from([2, 3, 8])), lanes=1, p1=data.draw(st.integers(0, p2)),
                      p2=p2)
    n = cfg.census_bits
    shape = (cfg.disparities, data.draw(st.integers(1, 4)), data.draw(st.integers(1, 6)))
    extreme = data.draw(st.sampled_from(["random", "zero", "max", "alternating"]))
    rng = np.random.default_rng(data.draw(st.integers(0, 2**32 - 1)))
    cost = {"random": rng.integers(0, n + 1, shape), "zero": np.zeros(shape, int),
            "max": np.full(shape, n), "alternating": (np.indices(shape).sum(0) % 2) * n}[extreme]
    for axis in ("left_to_right", "top_to_bottom"):
        values = path_cost(cost, axis, cfg)
        assert values.min() >= 0 and values.max() <= cfg.path_max < 2 ** cfg.path_bits
    total = path_cost(cost, "left_to_right", cfg) + path_cost(cost, "top_to_bottom", cfg)
    assert total.max() < 2 ** cfg.sum_bits


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(0, DEPTH.path_max), min_size=DEPTH.disparities, max_size=DEPTH.disparities),
       st.lists(st.integers(0, DEPTH.census_bits), min_size=DEPTH.disparities, max_size=DEPTH.disparities))
def test_one_step_bound_for_any_previous_vector(prev, cost):
    """The bound holds for any previous vector in range, not only reachable ones: 0 <= L <= N + P2."""
    out = path_step(np.array(cost)[:, None], np.array(prev)[:, None], DEPTH.p1, DEPTH.p2)
    assert out.min() >= 0 and out.max() <= DEPTH.path_max


def test_bad_input_is_rejected():
    with pytest.raises(ValueError, match="same size"):
        depth_map(np.zeros((4, 5), int), np.zeros((4, 6), int), SMALL)
    with pytest.raises(ValueError, match="width"):
        depth_map(np.zeros((4, 3), int), np.zeros((4, 3), int), SMALL)
    with pytest.raises(ValueError, match="path must be"):
        path_cost(np.zeros((2, 2, 2)), "diagonal", SMALL)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.integers(0, 2 * DEPTH.path_max), min_size=3, max_size=8), st.integers(1, 64))
def test_uniqueness_rule_equals_a_loop(sums, k):
    """Invalid by the confidence iff 64 S* > k S2, S2 = min S over |d - d*| >= 2 (a Python loop; 511 = none)."""
    cfg = DepthConfig(disparities=len(sums), lanes=1, uniqueness=k, max_cost=2 * DEPTH.path_max)
    total = np.array(sums)[:, None, None]
    d = min(range(len(sums)), key=lambda i: (sums[i], i))
    s2 = min([sums[i] for i in range(len(sums)) if abs(i - d) >= 2], default=511)
    assert int(second_best(total, np.array([[d]]), cfg)[0, 0]) == s2
    code = int(winner(total, cfg)[0][0, 0])
    assert (code == cfg.invalid) == (64 * sums[d] > k * s2 or d == len(sums) - 1)


def test_uniqueness_boundary_by_hand():
    """k = 60: S* = 15, S2 = 16 is exactly at the threshold (960 = 960): valid; S* = 16: invalid."""
    cfg = DepthConfig(disparities=6, lanes=2, uniqueness=60)
    total = np.array([[[99, 99]], [[20, 21]], [[15, 16]], [[20, 21]], [[16, 16]], [[99, 99]]])
    codes, _ = winner(total, cfg)
    assert codes.tolist() == [[32, cfg.invalid]]


# --- rows from different camera frames (docs/depth.md, "Rows from different camera frames") ---------------------

from golden.depth import row_flags                                     # noqa: E402
from spec.depth import SMALL_DEPTH                                     # noqa: E402

TAG_SHAPE = (12, 16)
TAG_H = SMALL_DEPTH.census_height // 2                                 # 3


def _tag_pair(seed=21):
    rng = np.random.default_rng(seed)
    return rng.integers(0, 32, TAG_SHAPE), rng.integers(0, 32, TAG_SHAPE)


def _rows(first, last):
    """The set of rows first..last, clamped to the image."""
    return set(range(max(first, 0), min(last, TAG_SHAPE[0] - 1) + 1))


def _flag_sets(tags):
    invalid, restart = row_flags(tags, TAG_SHAPE[0], SMALL_DEPTH)
    return set(np.flatnonzero(invalid).tolist()), set(np.flatnonzero(restart).tolist())


def test_equal_tags_are_todays_map():
    """Every tag of both images equal: the map without tags, bit for bit; no row invalid, the vertical path starts
    at row 0 only."""
    left, right = _tag_pair()
    h = TAG_SHAPE[0]
    tags = ([3] * h, [3] * h)
    assert (depth_map(left, right, SMALL_DEPTH, row_tags=tags) == depth_map(left, right, SMALL_DEPTH)).all()
    assert _flag_sets(tags) == (set(), {0})
    assert _flag_sets(None) == (set(), {0})


def test_images_of_different_pairs_are_invalid():
    """Each image of one frame, but of different camera frame pairs (the left tags 3, the right 4): every row
    pairs a left row of one pair with a right row of another, so every row is invalid."""
    h = TAG_SHAPE[0]
    invalid, restart = _flag_sets(([3] * h, [4] * h))
    assert invalid == set(range(h)) and restart == set(range(h))
    left, right = _tag_pair()
    assert (depth_map(left, right, SMALL_DEPTH, row_tags=([3] * h, [4] * h)) == SMALL_DEPTH.invalid).all()


@pytest.mark.parametrize("k", [1, 2, 3, 6, 9, 11])
def test_a_tag_change_invalidates_the_window_rows(k):
    """Tags a above row k, b from row k on (both images): rows k - h .. k + h - 1 are invalid (their census windows
    hold both), the path restarts at rows k - h + 1 .. k + h (each row after an invalid one, and row k); rows above
    the band keep today's raw codes, rows below it are the winner of a vertical path started afresh at k + h."""
    left, right = _tag_pair(k)
    h = TAG_SHAPE[0]
    changed = [0] * k + [1] * (h - k)
    tags = (changed, list(changed))
    invalid, restart = _flag_sets(tags)
    assert invalid == _rows(k - TAG_H, k + TAG_H - 1)
    assert restart == {0} | _rows(k - TAG_H + 1, k + TAG_H)
    got = depth_map(left, right, SMALL_DEPTH, row_tags=tags, details=True)
    today = depth_map(left, right, SMALL_DEPTH, details=True)
    assert (got.raw[sorted(invalid)] == SMALL_DEPTH.invalid).all()
    above = k - TAG_H
    assert (got.raw[:max(above, 0)] == today.raw[:max(above, 0)]).all()
    below = k + TAG_H
    if below < h:
        fresh = path_cost(today.cost[:, below:], "top_to_bottom", SMALL_DEPTH)   # rows below, path from row k + h
        raw, _ = winner(today.paths["left_to_right"][:, below:] + fresh, SMALL_DEPTH)
        assert (got.raw[below:] == raw).all()
    assert (got.codes == median3x3(got.raw)).all()


def test_restart_matters_below_the_band():
    """The restart at row k + h (not only at the tag change k) changes the rows below: a path restarted at k only
    gives other codes there for a random pair (so the rule is visible in the map)."""
    left, right = _tag_pair(4)
    h, k = TAG_SHAPE[0], 4
    changed = [0] * k + [1] * (h - k)
    got = depth_map(left, right, SMALL_DEPTH, row_tags=(changed, changed), details=True)
    at_k = np.zeros(h, dtype=bool)
    at_k[[0, k]] = True
    vertical = path_cost(got.cost, "top_to_bottom", SMALL_DEPTH, restart=at_k)
    raw, _ = winner(got.paths["left_to_right"] + vertical, SMALL_DEPTH)
    assert (raw[k + TAG_H:] != got.raw[k + TAG_H:]).any()


@pytest.mark.parametrize("k", [0, 1, 5, 11])
def test_a_torn_row(k):
    """Row k torn (None) in one image: rows k - h .. k + h invalid, restarts at k - h + 1 .. k + h + 1."""
    h = TAG_SHAPE[0]
    torn = [7] * h
    torn[k] = None
    invalid, restart = _flag_sets(([7] * h, torn))
    assert invalid == _rows(k - TAG_H, k + TAG_H)
    assert restart == {0} | _rows(k - TAG_H + 1, k + TAG_H + 1)
    left, right = _tag_pair(k + 40)
    got = depth_map(left, right, SMALL_DEPTH, row_tags=(torn, [7] * h), details=True)
    assert (got.raw[sorted(invalid)] == SMALL_DEPTH.invalid).all()
    assert (got.raw[sorted(set(range(h)) - invalid)] != SMALL_DEPTH.invalid).any()


def test_tears_in_both_images_and_a_short_window():
    """Left changes at row 3, right at row 8: both bands and the rows between (rows 3 .. 7 pair a left row of the
    new pair with a right row of the old one), widened by the window. A 7 x 1 census (h = 0): the rows 3 .. 7
    alone are invalid, the path restarts at each tag change and after each invalid row; a torn row is invalid
    alone."""
    h = TAG_SHAPE[0]
    tags = ([0] * 3 + [1] * (h - 3), [0] * 8 + [1] * (h - 8))
    invalid, restart = _flag_sets(tags)
    assert invalid == _rows(0, 10)
    assert restart == {0} | _rows(1, 11)
    flat = DepthConfig(disparities=8, lanes=4, census_height=1)
    inv, rst = row_flags(tags, h, flat)
    assert set(np.flatnonzero(inv)) == set(range(3, 8)) and set(np.flatnonzero(rst)) == {0} | set(range(3, 9))
    inv, rst = row_flags(([0] * 5 + [None] + [0] * (h - 6), [0] * h), h, flat)
    assert set(np.flatnonzero(inv)) == {5} and set(np.flatnonzero(rst)) == {0, 5, 6}


def test_bad_row_tags_are_rejected():
    left, right = _tag_pair()
    h = TAG_SHAPE[0]
    with pytest.raises(ValueError, match="12 rows"):
        depth_map(left, right, SMALL_DEPTH, row_tags=([0] * (h - 1), [0] * h))
    with pytest.raises(ValueError, match="ints or None"):
        depth_map(left, right, SMALL_DEPTH, row_tags=([0] * h, ["a"] * h))
    with pytest.raises(ValueError, match="pair"):
        depth_map(left, right, SMALL_DEPTH, row_tags=[0] * h)


AD = DepthConfig(disparities=4, census_width=3, census_height=3, lanes=2, pixel_bits=8, ad_clip=16)


@pytest.mark.parametrize("shift", [0, 1])
@pytest.mark.parametrize("step", [-17, -16, -15, 15, 16, 17])
def test_ad_term_at_the_clip(step, shift):
    """Flat images (every census 0: Hamming 0), the left one ``step`` greys brighter: the cost is min(|step|,
    ad_clip) >> ad_shift inside the image, at x + d = W - 1 too, and census_bits + (ad_clip >> ad_shift) from
    x + d = W on."""
    cfg = DepthConfig(**{**AD.__dict__, "ad_shift": shift})
    right = np.full((3, 6), 100)
    cost = matching_cost(right + step, right, cfg)
    w = right.shape[1]
    for d in range(cfg.disparities):
        assert (cost[d, :, :w - d] == min(abs(step), cfg.ad_clip) >> shift).all()   # x + d <= W - 1
        assert (cost[d, :, w - d:] == cfg.census_bits + (cfg.ad_clip >> shift)).all()    # x + d >= W
    assert cfg.cost_max == cfg.census_bits + (16 >> shift)


def test_ad_cost_is_hamming_plus_the_clipped_difference():
    """Random 8-bit images: each cost is the Hamming distance plus the clipped, shifted grey difference, counted
    pixel by pixel; at most cost_max; with ad_clip = 0 the plain census cost."""
    rng = np.random.default_rng(4)
    left, right = rng.integers(0, 256, (5, 7)), rng.integers(0, 256, (5, 7))
    cfg = DepthConfig(**{**AD.__dict__, "ad_clip": 24, "ad_shift": 1})
    cost = matching_cost(left, right, cfg)
    plain = matching_cost(left, right, DepthConfig(**{**AD.__dict__, "ad_clip": 0}))
    cl, cr = census(left, cfg), census(right, cfg)
    for d in range(cfg.disparities):
        for y in range(5):
            for x in range(7 - d):
                hamming = bin(int(cr[y, x]) ^ int(cl[y, x + d])).count("1")
                assert plain[d, y, x] == hamming
                assert cost[d, y, x] == hamming + (min(abs(int(right[y, x]) - int(left[y, x + d])), 24) >> 1)
    assert cost.max() <= cfg.cost_max and (cost[1:, :, -1] == cfg.cost_max).all()


def test_ad_widths_and_bad_parameters():
    """The widths follow cost_max = census_bits + (ad_clip >> ad_shift); nonsense AD parameters are refused."""
    cfg = DepthConfig(pixel_bits=8, ad_clip=255)
    assert (cfg.cost_max, cfg.cost_bits, cfg.path_max, cfg.path_bits) == (303, 9, 399, 9)
    assert (cfg.sum_max, cfg.sum_bits) == (798, 10)
    assert DEPTH.cost_max == DEPTH.census_bits and DEPTH.ad_max == 0
    for bad in ({"ad_clip": -1}, {"ad_clip": 32}, {"ad_clip": 16, "ad_shift": -1}, {"ad_clip": 16, "ad_shift": 5},
                {"ad_shift": 1}, {"ad_clip": 2.0}, {"ad_clip": True}):
        with pytest.raises(ValueError, match="ad_"):
            DepthConfig(**bad)          # 5-bit pixels: ad_clip at most 31


def test_ad_map_with_a_wide_cost():
    """A cost above 255 (7 x 7 census + ad_clip 255) is not wrapped: the costs reach above 255, the out-of-image
    cost is cost_max = 303, and the map finds the shift of 3."""
    rng = np.random.default_rng(9)
    texture = rng.integers(0, 256, (8, 24))
    cfg = DepthConfig(disparities=8, lanes=4, pixel_bits=8, ad_clip=255)
    cost = matching_cost(texture[:, :20], texture[:, 3:23], cfg)
    assert cost.max() > 255 and cost.max() <= cfg.cost_max
    assert (cost[:, :, -1][1:] == cfg.cost_max).all()
    codes = depth_map(texture[:, :20], texture[:, 3:23], cfg).astype(int)
    assert ((codes[:, 4:12] + cfg.fraction // 2) // cfg.fraction == 3).all()


def _bt_by_loop(left, right, d, x, y, symmetric):
    """Birchfield and Tomasi's dissimilarity of right(x) and left(x + d) in exact fractions, neighbours clamped."""
    def one_sided(image, at, grey):
        row = [int(v) for v in image[y]]
        near = [row[max(at - 1, 0)], row[at], row[min(at + 1, len(row) - 1)]]
        values = [Fraction(row[at])] + [Fraction(row[at] + n, 2) for n in (near[0], near[2])]
        return max(Fraction(0), grey - max(values), min(values) - grey)
    out = one_sided(left, x + d, int(right[y, x]))
    return min(out, one_sided(right, x, int(left[y, x + d]))) if symmetric else out


@pytest.mark.parametrize("sampling", ["bt_left", "bt"])
def test_bt_cost_is_hamming_plus_the_clipped_dissimilarity(sampling):
    """Random 8-bit images with an edge: each cost is the Hamming distance plus floor(min(dis, ad_clip) /
    2**ad_shift), dis Birchfield and Tomasi's dissimilarity in exact fractions (one-sided or symmetric)."""
    rng = np.random.default_rng(5)
    left, right = rng.integers(0, 256, (4, 9)), rng.integers(0, 256, (4, 9))
    for clip, shift in ((24, 1), (255, 0), (32, 2)):
        cfg = DepthConfig(**{**AD.__dict__, "ad_clip": clip, "ad_shift": shift, "ad_sampling": sampling})
        cost = matching_cost(left, right, cfg).astype(int)
        plain = matching_cost(left, right, DepthConfig(**{**AD.__dict__, "ad_clip": 0})).astype(int)
        for d in range(cfg.disparities):
            for y in range(4):
                for x in range(9 - d):
                    dis = _bt_by_loop(left, right, d, x, y, sampling == "bt")
                    assert cost[d, y, x] - plain[d, y, x] == int(min(dis, clip) // (1 << shift))
        assert cost.max() <= cfg.cost_max and (cost[1:, :, -1] == cfg.cost_max).all()


@pytest.mark.parametrize("grey, term", [(19, 0), (20, 0), (21, 0), (22, 1), (9, 1), (10, 0), (36, 15), (37, 16),
                                        (38, 16), (200, 16)])
def test_bt_left_at_its_boundaries(grey, term):
    """Left row 10 10 31 31 31 (x' = 1: Imin = 10, Imax = 20.5), right flat ``grey``, d = 0, x = 1, ad_clip 16,
    shift 0: the term (the cost less the census cost) is 0 on [10, 20.5], floor(21.5 - 20.5) = 1 at 22, 1 at 9,
    16 from 36.5 on (the clip); the symmetric form with a flat right image is the same (its range is the grey)."""
    left = np.tile([10, 10, 31, 31, 31], (3, 1))
    right = np.full((3, 5), grey)
    plain = matching_cost(left, right, DepthConfig(**{**AD.__dict__, "ad_clip": 0})).astype(int)
    for sampling in ("bt_left", "bt"):
        cfg = DepthConfig(**{**AD.__dict__, "ad_sampling": sampling})
        assert matching_cost(left, right, cfg).astype(int)[0, 1, 1] - plain[0, 1, 1] == term


def test_bt_symmetric_takes_the_right_images_range():
    """Left flat 20, right row 10 10 30 30: at x = 1, d = 0 the one-sided form gives |20 - 10| = 10, the symmetric
    one 0 (20 is within the right image's range 10 .. 20 there); the plain AD term 10."""
    left, right = np.full((3, 4), 20), np.tile([10, 10, 30, 30], (3, 1))
    plain = matching_cost(left, right, DepthConfig(**{**AD.__dict__, "ad_clip": 0})).astype(int)[0, 1, 1]
    terms = {s: matching_cost(left, right, DepthConfig(**{**AD.__dict__, "ad_sampling": s})).astype(int)[0, 1, 1]
             - plain for s in ("pixel", "bt_left", "bt")}
    assert terms == {"pixel": 10, "bt_left": 10, "bt": 0}


def test_bad_ad_sampling_is_refused():
    for bad in ({"ad_sampling": "bt"}, {"ad_clip": 16, "ad_sampling": "BT"}, {"ad_clip": 16, "ad_sampling": None}):
        with pytest.raises(ValueError, match="ad_sampling"):
            DepthConfig(pixel_bits=8, **bad)
