# amaranth: UnusedElaboratable=no
"""Birchfield and Tomasi's AD term in the RTL (docs/depth.md, "cost"; ``DepthConfig.ad_sampling`` "bt_left" and
"bt") against rules written here in exact fractions and against golden.depth.depth_map: the census window's range
of its centre pixel, the cost block's term at its thresholds (the range's ends and the clip) and at random, and the
engine's map bit for bit (two paths by default; the diagonal with the left-right check and three paths slow)."""

import dataclasses
from fractions import Fraction
from math import floor

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from golden.depth import depth_map
from hdl.depth import DepthEngine
from hdl.depth.census import CensusWindow
from hdl.depth.matching_cost import MatchingCost
from spec.depth import DIAGONAL_PATHS, SMALL_DEPTH, THREE_PATHS
from sim.runners.amaranth import simulate
from tests.test_depth_engine import assert_same, run_engine
from tests.test_depth_engine_ad import AD, G8, low_contrast_pair

TOP = 255


def interpolated(row, x):
    """(Imin, Imax) of pixel x of a grey row, as fractions: the smallest and largest of the pixel and the points
    half way to its neighbours (the row's ends clamped)."""
    centre = Fraction(row[x])
    values = [centre] + [(centre + row[min(max(n, 0), len(row) - 1)]) / 2 for n in (x - 1, x + 1)]
    return min(values), max(values)


def dissimilarity(grey, row, x):
    """max(0, grey - Imax, Imin - grey) against pixel x of ``row``."""
    low, high = interpolated(row, x)
    return max(Fraction(0), grey - high, low - grey)


def bt_term(cfg, right_row, right_x, left_row, left_x):
    """The AD term of docs/depth.md: floor(min(dis, ad_clip) / 2**ad_shift), dis the one-sided (right pixel against
    the left row) or the symmetric dissimilarity."""
    dis = dissimilarity(right_row[right_x], left_row, left_x)
    if cfg.ad_sampling == "bt":
        dis = min(dis, dissimilarity(left_row[left_x], right_row, right_x))
    return floor(min(dis, cfg.ad_clip) / (1 << cfg.ad_shift))


def range_ports(row, x):
    """The range ports' values (2x units) of pixel x of a row: twice (Imin, Imax)."""
    low, high = interpolated(row, x)
    return {"low": int(2 * low), "high": int(2 * high)}


# ---- CensusWindow: the centre's range ----------------------------------------------------------------------------

#: Middle rows (west, centre, east) of a 3 x 3 window: ties, each neighbour the extreme, and the ends of 8 bits.
RANGE_ROWS = [(10, 10, 31), (31, 10, 10), (0, 255, 0), (255, 0, 255), (0, 0, 0), (255, 255, 255), (7, 8, 9),
              (9, 8, 7), (200, 100, 100), (100, 100, 200), (1, 0, 255), (254, 255, 0)]


@pytest.mark.parametrize("width", [3, 5])
def test_census_window_range(width):
    """Windows 3 and 5 wide, a middle row shifted in a column at a time: after each shift the centre's range (2x
    units) is twice (Imin, Imax) of the centre and its row neighbours, with the census."""
    cfg = dataclasses.replace(AD, census_width=width, census_height=3, ad_sampling="bt")
    row = [v for triple in RANGE_ROWS for v in triple]
    dut = CensusWindow(cfg, grey_bits=8)
    got = []

    async def bench(ctx):
        for x in range(len(row) + 2):
            ctx.set(dut.shift, x < len(row))
            for y in range(3):
                ctx.set(dut.column[y], row[min(x, len(row) - 1)] if y == 1 else 0)
            await ctx.tick()
            got.append((ctx.get(dut.centre_range.low), ctx.get(dut.centre_range.high)))

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    rx = width // 2
    for x in range(rx + 1, len(row) - rx - 1):      # centre x: shown 2 clocks after the shift of column x + rx
        expected = range_ports(row, x)
        assert got[x + rx + 1] == (expected["low"], expected["high"]), x


# ---- MatchingCost: the term ----------------------------------------------------------------------------------------

BT_CONFIGS = [dataclasses.replace(SMALL_DEPTH, pixel_bits=8, ad_clip=16, ad_shift=1, ad_sampling="bt"),
              dataclasses.replace(SMALL_DEPTH, pixel_bits=8, ad_clip=16, ad_shift=0, ad_sampling="bt_left"),
              dataclasses.replace(SMALL_DEPTH, pixel_bits=8, ad_clip=255, ad_sampling="bt"),
              dataclasses.replace(SMALL_DEPTH, pixel_bits=8, ad_clip=24, ad_shift=2, ad_sampling="bt")]


def run_cost(cfg, cases):
    """Each case: (right row, right x, [(left row, left x)] a lane), census all zero and every lane inside: the
    cost block's outputs (the AD term alone)."""
    dut = MatchingCost(cfg)
    got = []

    async def bench(ctx):
        ctx.set(dut.inside, (1 << cfg.lanes) - 1)
        for i in range(len(cases) + MatchingCost.LATENCY):
            if i < len(cases):
                right_row, right_x, lanes = cases[i]
                ctx.set(dut.right_grey, right_row[right_x])
                if cfg.ad_sampling == "bt":
                    ctx.set(dut.right_range, range_ports(right_row, right_x))
                for k, (left_row, left_x) in enumerate(lanes):
                    ctx.set(dut.left_grey[k], left_row[left_x])
                    ctx.set(dut.left_range[k], range_ports(left_row, left_x))
            await ctx.tick()
            if i >= MatchingCost.LATENCY - 1 and len(got) < len(cases):
                got.append([ctx.get(dut.cost[k]) for k in range(cfg.lanes)])

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    return got


#: golden's boundary scene (tests/test_depth_golden.py): left row 10 10 31 (x' = 1: Imin 10, Imax 20.5), a flat
#: right grey; ad_clip 16, shift 0: 0 on [10, 20.5], 1 at 9 and at 22 (21.5 - 20.5), 15 at 36, 16 from 37 (the
#: clip at 36.5).
BOUNDARY = [(19, 0), (20, 0), (21, 0), (22, 1), (9, 1), (10, 0), (36, 15), (37, 16), (38, 16), (200, 16)]


@pytest.mark.parametrize("sampling", ["bt_left", "bt"])
def test_bt_term_at_its_boundaries(sampling):
    """The golden model's boundary cases in the cost block: the range's ends (0 at the end, 1 one past it on
    either side) and the clip (15 one before, 16 at and past it); the symmetric form with a flat right row (its
    range is its grey) is the same."""
    cfg = dataclasses.replace(SMALL_DEPTH, pixel_bits=8, ad_clip=16, ad_sampling=sampling)
    left = [10, 10, 31]
    cases = [([grey] * 3, 1, [(left, 1)] * cfg.lanes) for grey, _ in BOUNDARY]
    assert [costs[0] for costs in run_cost(cfg, cases)] == [term for _, term in BOUNDARY]


def test_bt_term_takes_the_smaller_direction():
    """Left flat 20, right 10 10 30 at x = 1: the right pixel is 10 below the left range (10), the left pixel
    within the right range 10 .. 20 (0): one-sided 10, symmetric 0; and the roles swapped, 10 both ways."""
    cases = [([10, 10, 30], 1, [([20] * 3, 1)] * 4), ([20] * 3, 1, [([10, 10, 30], 1)] * 4)]
    for sampling, expected in (("bt_left", [10, 0]), ("bt", [0, 0])):
        cfg = dataclasses.replace(SMALL_DEPTH, pixel_bits=8, ad_clip=16, ad_sampling=sampling)
        assert [costs[0] for costs in run_cost(cfg, cases)] == expected


def rows(draw, size=3):
    """A grey row, often at the ends of the range or flat."""
    grey = st.one_of(st.integers(0, TOP), st.sampled_from([0, 1, TOP - 1, TOP]))
    return draw(st.one_of(st.lists(grey, min_size=size, max_size=size), grey.map(lambda g: [g] * size)))


@pytest.mark.parametrize("cfg", BT_CONFIGS)
@settings(max_examples=4, deadline=None)
@given(data=st.data())
def test_bt_term(cfg, data):
    """The cost block's term against the fraction rule, every lane a different left row; one case of each
    example nudged to sit at the clip (the right grey 2 ad_clip half-units past the left range's top)."""
    cases = []
    for _ in range(data.draw(st.integers(1, 5))):
        right = rows(data.draw)
        lanes = [(rows(data.draw), 1) for _ in range(cfg.lanes)]
        cases.append((right, 1, lanes))
    left = lanes[0][0]
    high = interpolated(left, 1)[1]
    for step in (-1, 0, 1):
        grey = floor(high + cfg.ad_clip) + step
        if grey <= TOP:
            cases.append(([grey] * 3, 1, lanes))
    got = run_cost(cfg, cases)
    for (right, right_x, lanes), costs in zip(cases, got):
        assert costs == [bt_term(cfg, right, right_x, row, x) for row, x in lanes]


# ---- The engine ----------------------------------------------------------------------------------------------------

def check(left, right, config, **kwargs):
    """The engine's map equals the golden map, and differs from the map of the plain AD term (so an engine that
    computed |I_R - I_L| would fail)."""
    codes, *_ = run_engine(left, right, geometry=G8, config=config, **kwargs)
    assert_same(codes, depth_map(left, right, config))
    assert (codes != depth_map(left, right, dataclasses.replace(config, ad_sampling="pixel"))).any()


def test_bt_engine_bit_exact():
    """Two paths, the symmetric term 16 >> 1, 1 in 4 reads granted."""
    check(*low_contrast_pair(1), dataclasses.replace(AD, ad_sampling="bt"), grant_mask=0b11)


@pytest.mark.slow
def test_bt_left_engine_diagonal_left_right_bit_exact():
    """The one-sided term 24 >> 2 with the diagonal, the left-right check and the 7 x 7 median."""
    config = dataclasses.replace(AD, ad_sampling="bt_left", ad_clip=24, ad_shift=2, paths=DIAGONAL_PATHS,
                                 max_cost=136, left_right=True, median=7)
    check(*low_contrast_pair(4), config)


@pytest.mark.slow
def test_bt_engine_three_paths_bit_exact():
    """Three paths: the candidates' ranges from the census shift register, forward and backward."""
    config = dataclasses.replace(AD, ad_sampling="bt", paths=THREE_PATHS, max_cost=AD.max_cost * 3 // 2)
    check(*low_contrast_pair(2), config)


def test_bt_needs_row_neighbours_in_the_window():
    with pytest.raises(ValueError, match="census_width"):
        DepthEngine(G8, dataclasses.replace(AD, ad_sampling="bt", census_width=1))
