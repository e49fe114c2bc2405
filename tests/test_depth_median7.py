# amaranth: UnusedElaboratable=no
"""The separable 7 x 7 median and the medians over the valid codes (docs/depth.md, "median"): the golden model on
hand-made arrays (the clamp, the valid count at its threshold k // 2 and k // 2 + 1, the rank (v - 1) // 2) and
against a per-pixel reading of the rule, ``separable_median(n, valid_only)`` against it for n = 5 and 7, and the
engine with ``median=7, median_valid=True`` against the golden map."""

import dataclasses
import itertools

import numpy as np
import pytest
from scipy.ndimage import median_filter

from golden.depth import depth_map, median, separable_median
from hdl.depth.engine import schedule
from hdl.depth.separable_median import SeparableMedian, separable_median as block_of
from spec.depth import DepthConfig
from spec.sensor import SensorGeometry
from tests.test_depth_engine import BUSY, CFG, G, SHAPE, assert_same, engine_tags, random_pair, run_engine, steps
from tests.test_depth_median5 import run_block

INVALID = DepthConfig(disparities=8, lanes=4).invalid      # 128 (7 bits)


def test_config_median_valid_is_validated():
    """``median_valid`` with the separable medians only; a bool; off by default."""
    assert not DepthConfig().median_valid
    assert DepthConfig(median=7, median_valid=True).median_valid and DepthConfig(median=5, median_valid=True)
    for median_, valid in ((3, True), (7, 1), (5, "yes")):
        with pytest.raises(ValueError, match="median_valid must be"):
            DepthConfig(median=median_, median_valid=valid)


def reference(codes, n, valid_only):
    """The rule of docs/depth.md read pixel by pixel: the median of the clamped column medians."""
    h, w = codes.shape
    m = n // 2

    def median_of(values):
        values = sorted(int(v) for v in values)
        if not valid_only:
            return values[len(values) // 2]
        valid = [v for v in values if v != INVALID]
        return valid[(len(valid) - 1) // 2] if len(valid) > len(values) // 2 else INVALID

    column = [[median_of(codes[min(max(y + j, 0), h - 1), x] for j in range(-m, m + 1)) for x in range(w)]
              for y in range(h)]
    return np.array([[median_of(column[y][min(max(x + i, 0), w - 1)] for i in range(-m, m + 1)) for x in range(w)]
                     for y in range(h)])


@pytest.mark.parametrize("valid_only", [False, True])
@pytest.mark.parametrize("side", ["top", "bottom", "left", "right"])
def test_a_border_line_stays_on_the_border_7(side, valid_only):
    """A line of 9s along one border of 1s: clamped, the border row counts four times in its own 7 x 7 windows
    (four 9s of seven: the median), three times in the next row's (1)."""
    codes = np.ones((9, 10), dtype=np.uint16)
    line = {"top": (0, slice(None)), "bottom": (-1, slice(None)), "left": (slice(None), 0),
            "right": (slice(None), -1)}[side]
    codes[line] = 9
    expected = np.ones_like(codes)
    expected[line] = 9
    assert (separable_median(codes, 7, valid_only, INVALID) == expected).all()


@pytest.mark.parametrize("n", [5, 7])
def test_valid_count_threshold_and_rank(n):
    """A single row (each column median is its code): with v of the n codes valid, the median over the valid codes
    is invalid for v = n // 2 and the ((v - 1) // 2)-th smallest valid code from v = n // 2 + 1 on; the plain
    median is the (n // 2)-th smallest with invalid last. A single column: the same along the column."""
    k = n // 2
    for v in range(n + 1):
        codes = np.array([[10 * (i + 1) if i < v else INVALID for i in range(n)]], dtype=np.uint16)
        centre = (0, k)
        valid = separable_median(codes, n, True, INVALID)[centre]
        plain = separable_median(codes, n, False, INVALID)[centre]
        assert valid == (10 * ((v - 1) // 2 + 1) if v > k else INVALID), (v, valid)
        assert plain == (10 * (k + 1) if v > k else INVALID), (v, plain)
        assert separable_median(codes.T, n, True, INVALID)[centre[::-1]] == valid
    # At the threshold's boundary the two differ only in the rank: v = k + 1 valid codes.
    codes = np.array([[10 * (i + 1) if i <= k else INVALID for i in range(n)]], dtype=np.uint16)
    assert separable_median(codes, n, True, INVALID)[0, k] == 10 * (k // 2 + 1)
    assert separable_median(codes, n, False, INVALID)[0, k] == 10 * (k + 1)


def test_equals_the_rule_and_scipy():
    """On random codes with many invalid ones at small sizes: 5 and 7, valid option on and off, equal to the rule
    read pixel by pixel; the plain 7 x 7 equal to two one-dimensional medians (scipy, borders "nearest");
    ``median`` chooses by ``config``."""
    rng = np.random.default_rng(7)
    for h, w in ((1, 1), (1, 8), (8, 1), (2, 3), (5, 4), (9, 11)):
        codes = rng.choice([0, 1, 5, 17, 60, INVALID, INVALID], size=(h, w)).astype(np.uint16)
        for n, valid_only in itertools.product((5, 7), (False, True)):
            assert (separable_median(codes, n, valid_only, INVALID) == reference(codes, n, valid_only)).all()
        columns = median_filter(codes, size=(7, 1), mode="nearest")
        assert (separable_median(codes, 7) == median_filter(columns, size=(1, 7), mode="nearest")).all()
        config = DepthConfig(disparities=8, lanes=4, median=7, median_valid=True)
        assert (median(codes, config) == separable_median(codes, 7, True, INVALID)).all()


@pytest.mark.parametrize("n, valid_only", [(5, True), (7, False), (7, True)])
@pytest.mark.parametrize("shape", [(1, 2), (2, 3), (4, 1), (8, 5)])
def test_block_equals_golden(n, valid_only, shape):
    """``separable_median(n, valid_only)`` on random codes (half of them invalid) at small sizes (images smaller
    than the window included), inputs every other clock and slower: every output once, equal to
    ``golden.depth.separable_median``; a row's last output ``LATENCY`` clocks after its end token."""
    block = block_of(n, valid_only)
    assert block.ROW_LAG == n // 2 and issubclass(block, SeparableMedian)
    rng = np.random.default_rng(sum(shape) + n)
    codes = rng.choice([0, 1, 2, 7, 33, 127, INVALID, INVALID, INVALID], size=shape).astype(np.uint16)
    got, latencies = run_block(codes, block, gaps=[0, 0, 1, 0, 3])
    expected = separable_median(codes, n, valid_only, INVALID)
    assert (got == expected).all(), f"{got}\n{expected}"
    assert latencies == [block.LATENCY] * shape[0]


def test_block_of_rejects_other_sizes():
    with pytest.raises(ValueError, match="5 x 5 or 7 x 7"):
        block_of(3)


# --- the engine with the separable 7 x 7 median over the valid codes ---------------------------------------------

CFG7 = dataclasses.replace(CFG, median=7, median_valid=True)


def test_engine_tag_change_and_torn_row():
    """SMALL_DEPTH with ``median=7, median_valid=True`` (H + 3 passes): a tag change at left row 5 and right row 7
    and a torn right row 2, the invalid rows and the median over them (three rows each side of a row) bit for bit
    with the golden map, which differs from the plain 7 x 7's."""
    h = SHAPE[0]
    left_table, right_table = steps(h, 5), steps(h, 7)
    right_table[2] |= BUSY
    left, right = random_pair(37)
    tags = (engine_tags(left_table), engine_tags(right_table))
    expected = depth_map(left, right, CFG7, row_tags=tags)
    codes, clocks, reads, _ = run_engine(left, right, config=CFG7, grant_mask=0b101,
                                         tag_tables=(left_table, right_table))
    assert_same(codes, expected)
    assert (expected != CFG.invalid).any() and (expected == CFG.invalid).any()
    assert (expected != depth_map(left, right, dataclasses.replace(CFG7, median_valid=False), row_tags=tags)).any()
    assert reads == (G.buf_depth, G.buf_depth)
    assert clocks > (h + 3) * schedule(G, CFG7).pass_clocks


def test_map_time_at_800():
    """The 800 x 600 build with the separable 7 x 7 median over the valid codes: a pass 5 clocks longer than with
    the plain 5 x 5 (19 clocks from the end token to the last output against 14), one pass more (H + 3), still a
    map in 3 display frames of 1080p60."""
    from hdl.stereo_display import check_map_rate, map_clocks
    from spec.depth import DEPTH_800_BASE
    from spec.sensor import SENSOR_800
    from spec.video import CEA_1080P60
    five, seven = (dataclasses.replace(DEPTH_800_BASE, median=n, median_valid=n == 7) for n in (5, 7))
    p5, p7 = schedule(SENSOR_800, five).pass_clocks, schedule(SENSOR_800, seven).pass_clocks
    assert p7 == p5 + 5
    h = SENSOR_800.buf_height
    assert map_clocks(SENSOR_800, seven) - map_clocks(SENSOR_800, five) == (h + 3) * (p7 + 3) - (h + 2) * (p5 + 3)
    assert check_map_rate(CEA_1080P60, SENSOR_800, seven) == 3


@pytest.mark.slow
def test_three_path_engine_bit_exact():
    """The three-path engine (the row's codes replayed into the median after the backward pass) with
    ``median=7, median_valid=True``: the replay's end token and the two clocks after it finish the row, before the
    drain ends."""
    from spec.depth import THREE_PATHS
    config = dataclasses.replace(CFG7, paths=THREE_PATHS, max_cost=CFG.max_cost * 3 // 2)
    geometry = SensorGeometry(width=G.width, height=7 * G.scale)
    left, right = random_pair(43, (geometry.buf_height, geometry.buf_width))
    codes, *_ = run_engine(left, right, geometry=geometry, config=config, grant_mask=0b1, platform="formal")
    assert_same(codes, depth_map(left, right, config))


@pytest.mark.slow
def test_package_engine_bit_exact():
    """The probe's package with the 7 x 7 median over the valid codes: AD-census 16 >> 1, the diagonal as the
    second path, ``median=7, median_valid=True``, on 8-bit grey: the map equals the golden map and differs from
    the plain 5 x 5's."""
    from spec.depth import DIAGONAL_PATHS
    from tests.test_depth_engine_ad import AD, G8, low_contrast_pair
    config = dataclasses.replace(AD, paths=DIAGONAL_PATHS, median=7, median_valid=True)
    left, right = low_contrast_pair(3)
    codes, *_ = run_engine(left, right, geometry=G8, config=config, grant_mask=0b1)
    expected = depth_map(left, right, config)
    assert_same(codes, expected)
    assert (expected != depth_map(left, right, dataclasses.replace(config, median=5, median_valid=False))).any()
