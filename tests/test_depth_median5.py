# amaranth: UnusedElaboratable=no
"""The separable 5 x 5 median (docs/depth.md, "median"): the golden model on hand-made arrays (the clamp at all
four borders, invalid codes, where it differs from the full 5 x 5 median) and ``SeparableMedian`` (the plain
5 x 5) against it."""

import dataclasses

import numpy as np
import pytest
from scipy.ndimage import median_filter

from golden.depth import median, median3x3, separable_median
from hdl.depth.median import Median3x3
from hdl.depth.separable_median import SeparableMedian
from spec.depth import DepthConfig
from spec.sensor import SensorGeometry
from sim.runners.amaranth import simulate

INVALID = DepthConfig(disparities=8, lanes=4).invalid      # 128 (7 bits)


def separable_median5(codes):
    """The plain separable 5 x 5 median."""
    return separable_median(codes, 5)


def full_median5(codes):
    """The full 5 x 5 median (the 13th of 25), coordinates clamped: what the separable form is not."""
    return median_filter(codes, size=5, mode="nearest")


def test_config_median_is_validated():
    assert DepthConfig().median == 3 and DepthConfig(median=5).median == 5 and DepthConfig(median=7).median == 7
    for bad in (1, 4, 9, "5"):
        with pytest.raises(ValueError, match="median must be 3"):
            DepthConfig(median=bad)


@pytest.mark.parametrize("side", ["top", "bottom", "left", "right"])
def test_a_border_line_stays_on_the_border(side):
    """A line of 9s along one border of zeros: clamped, the border row counts three times in its own windows (three
    9s of five: the median), twice in the next row's (0). Zero padding or either mirroring would count it at most
    twice: 0 everywhere."""
    codes = np.zeros((7, 8), dtype=np.uint16)
    line = {"top": (0, slice(None)), "bottom": (-1, slice(None)), "left": (slice(None), 0),
            "right": (slice(None), -1)}[side]
    codes[line] = 9
    expected = np.zeros_like(codes)
    expected[line] = 9
    assert (separable_median5(codes) == expected).all()


def test_corner_and_tiny_images():
    """A single code and a 2 x 3 image: every window is clamped at all four borders."""
    assert separable_median5(np.array([[5]], dtype=np.uint16)).tolist() == [[5]]
    codes = np.array([[1, 2, 9], [3, 4, 9]], dtype=np.uint16)
    # Column medians (rows 0, 0, 0, 1, 1 and 0, 0, 1, 1, 1): row 0 [1, 2, 9], row 1 [3, 4, 9]; then along the row
    # (columns 0, 0, 0, 1, 2 / 0, 0, 1, 2, 2 / 0, 1, 2, 2, 2).
    assert separable_median5(codes).tolist() == [[1, 2, 9], [3, 4, 9]]
    codes = np.array([[7, 7, 0, 0, 0]], dtype=np.uint16)    # columns 0, 0, 0, 1, 2 at x = 0; 0, 0, 1, 2, 3 at x = 1
    assert separable_median5(codes).tolist() == [[7, 7, 0, 0, 0]]
    assert separable_median5(codes[:, ::-1]).tolist() == [[0, 0, 0, 7, 7]]


def test_invalid_codes_and_the_separable_form():
    """Invalid sorts above every disparity: a column with two invalid codes of five keeps a valid median, three make
    it invalid. So the separable median can be invalid with 9 invalid codes of 25 (three columns of three) where the
    full 5 x 5 median (13 of 25) is valid, and valid with 16 of 25 (two whole columns, three columns of two) where
    the full one is invalid: the separable form is what is computed."""
    few = np.zeros((5, 5), dtype=np.uint16)
    few[:3, 1:4] = INVALID                                  # 9 of 25
    many = np.ones((5, 5), dtype=np.uint16)
    many[:, 3:] = INVALID                                   # two whole columns
    many[:2, :3] = INVALID                                  # two in each other column: 16 of 25
    for codes, separable, full in ((few, INVALID, 0), (many, 1, INVALID)):
        assert separable_median5(codes)[2, 2] == separable
        assert full_median5(codes)[2, 2] == full
    # An even split along the row: two of the five column medians invalid, the median valid; three invalid.
    row = np.array([[3, INVALID, 3, INVALID, 3]], dtype=np.uint16)
    assert separable_median5(row)[0, 2] == 3
    row[0, 0] = INVALID
    assert separable_median5(row)[0, 2] == INVALID


def test_equals_two_one_dimensional_medians():
    """On random codes at small sizes: the median of five along each column, then along each row, borders
    "nearest" (scipy's clamped median filters), and ``median`` chooses by ``config.median``."""
    rng = np.random.default_rng(5)
    for h, w in ((1, 1), (1, 6), (6, 1), (2, 3), (4, 4), (9, 11)):
        codes = rng.choice([0, 1, 5, 17, 60, INVALID], size=(h, w)).astype(np.uint16)
        columns = median_filter(codes, size=(5, 1), mode="nearest")
        assert (separable_median5(codes) == median_filter(columns, size=(1, 5), mode="nearest")).all()
        assert (median(codes, DepthConfig(median=5)) == separable_median5(codes)).all()
        assert (median(codes, DepthConfig()) == median3x3(codes)).all()


def run_block(codes, block, gaps, config=DepthConfig(disparities=8, lanes=4)):
    """Stream ``codes`` through ``block`` (a median class) as the engine does: pass y brings row y (every other
    clock or slower, ``gaps``: extra clocks per pixel), then the end token; ``ROW_LAG`` finishing passes bring
    codes that must not matter. Returns the outputs as an array and the clocks from each end token to its row's
    last output."""
    h, w = codes.shape
    dut = block(config, SensorGeometry(width=w, height=h, scale=1))
    got = np.full(codes.shape, -1, dtype=np.int64)
    ends, lasts = [], []
    rng = np.random.default_rng(1)

    async def bench(ctx):
        clock = 0

        async def tick():                   # one clock, its output recorded
            nonlocal clock
            await ctx.tick()
            clock += 1
            if ctx.get(dut.out_valid):
                row, x = ctx.get(dut.y) - block.ROW_LAG, ctx.get(dut.out_x)
                assert 0 <= row < h, f"an output in pass {row + block.ROW_LAG}"
                assert got[row, x] == -1, f"column {x} of row {row} twice"
                got[row, x] = ctx.get(dut.out_code)
                lasts.append((row + block.ROW_LAG, clock))

        for y in range(h + block.ROW_LAG):
            ctx.set(dut.y, y)
            for x in range(w + 1):
                ctx.set(dut.valid, 1)
                ctx.set(dut.x, x)
                ctx.set(dut.code, int(codes[y, x]) if y < h and x < w else int(rng.integers(0, INVALID + 1)))
                if x == w:
                    ends.append(clock)
                await tick()
                ctx.set(dut.valid, 0)
                for _ in range(1 + int(gaps[(y * (w + 1) + x) % len(gaps)])):
                    await tick()
            for _ in range(block.LATENCY + 2):
                await tick()

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    last_by_pass = {}
    for y, clock in lasts:
        last_by_pass[y] = clock
    latencies = [last_by_pass[y] - ends[y] for y in sorted(last_by_pass)]
    return got, latencies


@pytest.mark.parametrize("shape", [(1, 1), (2, 3), (5, 2), (6, 7)])
def test_block_equals_golden(shape):
    """``SeparableMedian`` on random codes (invalid ones included) at small sizes, inputs every other clock and
    slower: every output once, equal to ``golden.depth.separable_median``; a row's last output ``LATENCY``
    clocks after its end token (what the engine's drain counts on)."""
    rng = np.random.default_rng(sum(shape))
    codes = rng.choice([0, 1, 2, 7, 33, 127, INVALID], size=shape).astype(np.uint16)
    got, latencies = run_block(codes, SeparableMedian, gaps=[0, 0, 1, 0, 3])
    assert (got == separable_median5(codes)).all(), f"{got}\n{separable_median5(codes)}"
    assert latencies == [SeparableMedian.LATENCY] * shape[0]


def test_median3x3_block_lag_and_latency():
    """``Median3x3`` through the same driver: its ``ROW_LAG`` and ``LATENCY`` are what it does."""
    codes = np.random.default_rng(3).choice([0, 5, INVALID], size=(4, 5)).astype(np.uint16)
    got, latencies = run_block(codes, Median3x3, gaps=[0])
    assert (got == median3x3(codes)).all()
    assert latencies == [Median3x3.LATENCY] * 4


# --- the engine with the separable 5 x 5 median ------------------------------------------------------------------

from tests.test_depth_engine import (BUSY, CFG, G, SHAPE, assert_same, engine_tags, random_pair,  # noqa: E402
                                     run_engine, steps)
from golden.depth import depth_map                                                                   # noqa: E402
from hdl.depth.engine import schedule                                                                # noqa: E402

CFG5 = dataclasses.replace(CFG, median=5)


def test_engine_bit_exact():
    """SMALL_DEPTH with ``median=5`` on the small preset (1 in 4 reads granted), every pixel read once: the map
    equals ``golden.depth.depth_map``, which differs from the 3 x 3 median's; H + 2 passes; a reader that holds
    back stops the engine after ``out_rows`` rows."""
    left, right = random_pair(21)
    codes, clocks, reads, held = run_engine(left, right, config=CFG5, grant_mask=0b11, hold_clocks=4000)
    assert held == 4
    expected = depth_map(left, right, CFG5)
    assert_same(codes, expected)
    assert (expected != depth_map(left, right, CFG)).any()
    assert reads == (G.buf_depth, G.buf_depth)
    assert clocks > (SHAPE[0] + 2) * schedule(G, CFG5).pass_clocks


def test_engine_short_map_with_formal_invariants():
    """A 2-row buffer: both finishing passes clamp rows at the top and the bottom of the image, the pass counter
    counts to H + 2 = 4 once the map is done (a power of two: it must not wrap), and the engine's formal
    invariants (``rows_ready_trails_pass``: rows_ready = y - 2) hold on every clock of the map and the reads after
    it."""
    geometry = SensorGeometry(width=G.width, height=2 * G.scale)
    left, right = random_pair(5, (geometry.buf_height, geometry.buf_width))
    codes, *_ = run_engine(left, right, geometry=geometry, config=CFG5, grant_mask=0b1, platform="formal")
    assert_same(codes, depth_map(left, right, CFG5))


def test_engine_tag_change_and_torn_row():
    """A tag change at left row 5 and right row 7 and a torn right row 2 (busy at its sample): the invalid rows and
    the median over them (two rows of each side of a row) bit for bit with the golden map."""
    h = SHAPE[0]
    left_table, right_table = steps(h, 5), steps(h, 7)
    right_table[2] |= BUSY
    left, right = random_pair(31)
    tags = (engine_tags(left_table), engine_tags(right_table))
    assert tags[1][2] is None
    expected = depth_map(left, right, CFG5, row_tags=tags)
    codes, _, reads, _ = run_engine(left, right, config=CFG5, grant_mask=0b101, tag_tables=(left_table, right_table))
    assert_same(codes, expected)
    assert (expected != CFG.invalid).any() and (expected == CFG.invalid).any()


def test_map_time_at_800():
    """The 800 x 600 build with the separable 5 x 5 median: a pass 2 clocks longer (the median's 14 clocks to the
    last output against 12), one pass more (H + 2), still a map in 3 display frames of 1080p60."""
    from hdl.stereo_display import check_map_rate, map_clocks
    from spec.depth import DEPTH_800_BASE
    from spec.sensor import SENSOR_800
    from spec.video import CEA_1080P60
    five = dataclasses.replace(DEPTH_800_BASE, median=5)
    p3, p5 = schedule(SENSOR_800, DEPTH_800_BASE).pass_clocks, schedule(SENSOR_800, five).pass_clocks
    assert p5 == p3 + 2
    h = SENSOR_800.buf_height
    assert map_clocks(SENSOR_800, five) - map_clocks(SENSOR_800, DEPTH_800_BASE) == (h + 2) * (p5 + 3) - (h + 1) * (p3 + 3)
    assert check_map_rate(CEA_1080P60, SENSOR_800, five) == 3


@pytest.mark.slow
def test_three_path_engine_bit_exact():
    """The three-path engine (the row's codes replayed into the median after the backward pass) with ``median=5``:
    the replay's end token and the clock after it finish the row, before the drain ends."""
    from spec.depth import THREE_PATHS
    config = dataclasses.replace(CFG5, paths=THREE_PATHS, max_cost=CFG.max_cost * 3 // 2)
    geometry = SensorGeometry(width=G.width, height=5 * G.scale)
    left, right = random_pair(41, (geometry.buf_height, geometry.buf_width))
    codes, *_ = run_engine(left, right, geometry=geometry, config=config, grant_mask=0b1, platform="formal")
    assert_same(codes, depth_map(left, right, config))
