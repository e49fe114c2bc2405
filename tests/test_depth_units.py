# amaranth: UnusedElaboratable=no
"""The depth engine's arithmetic blocks against golden/depth.py, with hypothesis: cost (Hamming), the path
recursion (any previous vector in range, and whole lines of the recurrent path), the winner with validity.
Values at the ends of their ranges are drawn on purpose: nothing may wrap (docs/depth.md: no saturation is
needed because every width holds its largest value)."""

import dataclasses
import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from golden.depth import census, path_cost, path_step, winner
from hdl.depth.census import CensusWindow
from hdl.depth.matching_cost import MatchingCost
from hdl.depth.reverse_path import ReversePath
from hdl.depth.sgm_path import SgmPath
from hdl.depth.winner import Winner
from spec.depth import DEPTH, DEPTH_800_BASE, DEPTH_800_THREE, SMALL_DEPTH, THREE_PATHS, DepthConfig
from sim.runners.amaranth import simulate

WIDTH = 16
CONFIGS = [SMALL_DEPTH, DepthConfig(disparities=6, lanes=2, p1=7, p2=200)]


def token(group, last, x=0, first=0, go=1):
    return {"go": go, "group": group, "last": last, "first": first, "x": x}


def edgy(top):
    """Integers 0..top, often at the ends."""
    return st.one_of(st.integers(0, top), st.sampled_from([0, 1, top - 1, top]))


#: 3 x 3 windows of 8-bit grey and their signatures by hand (bit k = raster position k, centre skipped, set iff the
#: pixel is darker than the centre): each neighbour one below, equal to and one above the centre, at 128, 255 and 0.
CENSUS_WINDOWS = [
    ([[127, 128, 129], [0, 128, 255], [128, 127, 129]], 0b01001001),
    ([[254, 255, 255], [255, 255, 254], [0, 255, 255]], 0b00110001),
    ([[0, 1, 0], [1, 0, 0], [255, 0, 1]], 0),
]


@pytest.mark.parametrize("window, expected", CENSUS_WINDOWS)
def test_census_threshold_8_bit(window, expected):
    """The census comparison at its threshold (a neighbour one darker than the centre sets its bit, an equal or
    one brighter one does not) with 8-bit grey at the ends of the range: by hand, the golden model and the RTL."""
    cfg = DepthConfig(disparities=2, lanes=2, census_width=3, census_height=3, pixel_bits=8)
    image = np.array(window)
    assert int(census(image, cfg)[1, 1]) == expected
    dut = CensusWindow(cfg, grey_bits=8)
    got = []

    async def bench(ctx):
        for x in range(3):
            ctx.set(dut.shift, 1)
            for y in range(3):
                ctx.set(dut.column[y], int(image[y, x]))
            await ctx.tick()
        ctx.set(dut.shift, 0)
        await ctx.tick()
        got.append(ctx.get(dut.census))

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    assert got == [expected]


AD_CONFIGS = [dataclasses.replace(SMALL_DEPTH, pixel_bits=8, ad_clip=16, ad_shift=1),
              dataclasses.replace(SMALL_DEPTH, pixel_bits=8, ad_clip=255),
              dataclasses.replace(SMALL_DEPTH, ad_clip=5, ad_shift=2)]


def cost_rule(cfg, right, left, inside, right_grey=0, left_grey=0):
    """docs/depth.md's cost of one candidate: Hamming + min(|dI|, ad_clip) >> ad_shift, cost_max outside."""
    if not inside:
        return cfg.cost_max
    return bin(right ^ left).count("1") + (min(abs(right_grey - left_grey), cfg.ad_clip) >> cfg.ad_shift)


@pytest.mark.parametrize("cfg", [SMALL_DEPTH, DEPTH] + AD_CONFIGS)
@settings(max_examples=3, deadline=None)
@given(data=st.data())
def test_matching_cost(cfg, data):
    """The cost block against the rule, with and without the AD term; grey differences drawn around the clip
    (ad_clip - 1, ad_clip, ad_clip + 1) and at the ends of the range, lanes outside the image."""
    n, top = cfg.census_bits, (1 << cfg.pixel_bits) - 1
    words = st.one_of(st.integers(0, 2 ** n - 1), st.sampled_from([0, 2 ** n - 1]))
    steps = st.sampled_from([0, 1, cfg.ad_clip - 1, cfg.ad_clip, cfg.ad_clip + 1, top])
    cases = []
    for _ in range(data.draw(st.integers(1, 6))):
        right_grey = data.draw(st.one_of(st.integers(0, top), st.sampled_from([0, top])))
        near = st.builds(lambda s, sign: min(max(right_grey + sign * s, 0), top), steps, st.sampled_from([-1, 1]))
        lanes = data.draw(st.lists(st.tuples(words, st.one_of(st.integers(0, top), near)),
                                   min_size=cfg.lanes, max_size=cfg.lanes))
        cases.append((data.draw(words), right_grey, lanes, data.draw(st.integers(0, 2 ** cfg.lanes - 1))))
    dut = MatchingCost(cfg)
    got = []

    async def bench(ctx):
        for i in range(len(cases) + MatchingCost.LATENCY):
            if i < len(cases):
                right, right_grey, lanes, inside = cases[i]
                ctx.set(dut.right, right)
                ctx.set(dut.inside, inside)
                if cfg.ad_clip:
                    ctx.set(dut.right_grey, right_grey)
                for k, (left, left_grey) in enumerate(lanes):
                    ctx.set(dut.left[k], left)
                    if cfg.ad_clip:
                        ctx.set(dut.left_grey[k], left_grey)
            await ctx.tick()
            if i >= MatchingCost.LATENCY - 1 and len(got) < len(cases):
                got.append([ctx.get(dut.cost[k]) for k in range(cfg.lanes)])

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    assert len(got) == len(cases)
    for (right, right_grey, lanes, inside), costs in zip(cases, got):
        assert costs == [cost_rule(cfg, right, left, inside >> k & 1, right_grey, left_grey)
                         for k, (left, left_grey) in enumerate(lanes)]


def run_vertical_pixel(cfg, prev, cost):
    """One pixel through the vertical path (``prev`` from outside): its L vector and its M."""
    dut = SgmPath(cfg, recurrent=False, width=WIDTH)
    groups = cfg.disparities // cfg.lanes
    out = {}

    async def bench(ctx):
        def present(group):     # ``prev``: a group's word in the clock before the group's input
            for k in range(cfg.lanes):
                ctx.set(dut.prev[k], prev[group * cfg.lanes + k] if group < groups else 0)

        ctx.set(dut.prev_min, min(prev))
        present(0)
        await ctx.tick()
        values = []
        for i in range(groups + SgmPath.result_clocks(cfg) + 2):
            present(i + 1)
            if i < groups:
                ctx.set(dut.token, token(i, i == groups - 1))
                for k in range(cfg.lanes):
                    ctx.set(dut.cost[k], cost[i * cfg.lanes + k])
            else:
                ctx.set(dut.token, token(0, 0, go=0))
            await ctx.tick()
            if ctx.get(dut.l_token.go):
                values += [ctx.get(dut.l[k]) for k in range(cfg.lanes)]
            if ctx.get(dut.m_valid):
                out["m"] = ctx.get(dut.m)
        out["l"] = values

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    return out["l"], out["m"]


@settings(max_examples=15, deadline=None)
@given(st.data())
def test_vertical_path_step(data):
    """Any previous vector in 0..N + P2 and any costs 0..N: L equals the golden step, M its minimum."""
    cfg = data.draw(st.sampled_from(CONFIGS))
    prev = data.draw(st.lists(edgy(cfg.path_max), min_size=cfg.disparities, max_size=cfg.disparities))
    cost = data.draw(st.lists(edgy(cfg.census_bits), min_size=cfg.disparities, max_size=cfg.disparities))
    values, minimum = run_vertical_pixel(cfg, prev, cost)
    expected = path_step(np.array(cost)[:, None], np.array(prev)[:, None], cfg.p1, cfg.p2)[:, 0]
    assert values == expected.tolist()
    assert minimum == expected.min()


@settings(max_examples=10, deadline=None)
@given(st.data())
def test_horizontal_path_line(data):
    """A line of pixels through the recurrent path at its closest spacing (``loop_clocks``): equal to the
    golden horizontal path; ``first`` restarts it."""
    cfg = data.draw(st.sampled_from(CONFIGS))
    n = data.draw(st.integers(1, 6))
    cost = np.array(data.draw(st.lists(st.lists(edgy(cfg.census_bits), min_size=n, max_size=n),
                                       min_size=cfg.disparities, max_size=cfg.disparities)))
    restart = data.draw(st.integers(0, n - 1))
    dut = SgmPath(cfg, recurrent=True, width=WIDTH)
    groups, spacing = cfg.disparities // cfg.lanes, SgmPath.loop_clocks(cfg)
    got = np.zeros_like(cost)

    async def bench(ctx):
        for clock in range(n * spacing + SgmPath.result_clocks(cfg) + 2):
            x, g = divmod(clock, spacing)
            if x < n and g < groups:
                ctx.set(dut.token, token(g, g == groups - 1, x=x, first=x in (0, restart)))
                for k in range(cfg.lanes):
                    ctx.set(dut.cost[k], int(cost[g * cfg.lanes + k, x]))
            else:
                ctx.set(dut.token, token(0, 0, go=0))
            await ctx.tick()
            t = ctx.get(dut.l_token)
            if t.go:
                for k in range(cfg.lanes):
                    got[t.group * cfg.lanes + k, t.x] = ctx.get(dut.l[k])

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    parts = [cost[:, None, :restart], cost[:, None, restart:]] if restart else [cost[:, None, :]]
    expected = np.concatenate([path_cost(part, "left_to_right", cfg)[:, 0] for part in parts], axis=1)
    assert (got == expected).all()


def run_winner(cfg, lh, lv, x=7, vertical_bits=None):
    """One pixel's groups through the Winner (``vertical_bits``: its vertical input's width): (code, x)."""
    dut = Winner(cfg, WIDTH, vertical_bits=vertical_bits)
    groups = cfg.disparities // cfg.lanes
    out = {}

    async def bench(ctx):
        for i in range(groups + Winner.latency(cfg) + 2):
            if i < groups:
                ctx.set(dut.token, token(i, i == groups - 1, x=x))
                for k in range(cfg.lanes):
                    ctx.set(dut.horizontal[k], lh[i * cfg.lanes + k])
                    ctx.set(dut.vertical[k], lv[i * cfg.lanes + k])
            else:
                ctx.set(dut.token, token(0, 0, go=0))
            await ctx.tick()
            if ctx.get(dut.valid):
                assert "code" not in out, "one valid pulse per pixel"
                out["code"], out["x"] = ctx.get(dut.code), ctx.get(dut.x)
                out["clock"] = i

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    assert out["clock"] == groups - 1 + Winner.latency(cfg) - 1
    return out["code"], out["x"]


def golden_code(cfg, lh, lv):
    codes, _ = winner((np.array(lh) + np.array(lv))[:, None, None], cfg)
    return int(codes[0, 0])


@settings(max_examples=15, deadline=None)
@given(st.data())
def test_winner(data):
    """Smallest sum, smallest d on ties, the sub-pixel fit, invalid above max_cost or at D - 1; sums up to
    2 (N + P2)."""
    cfg = data.draw(st.sampled_from(CONFIGS + [DepthConfig(disparities=8, lanes=4, max_cost=0),
                                               DepthConfig(disparities=8, lanes=4, fraction_bits=0)]))
    top = cfg.path_max
    lh = data.draw(st.lists(st.sampled_from([0, 1, 2, top]) | st.integers(0, top), min_size=cfg.disparities,
                            max_size=cfg.disparities))
    lv = data.draw(st.lists(st.sampled_from([0, 1, top]) | st.integers(0, top), min_size=cfg.disparities,
                            max_size=cfg.disparities))
    assert run_winner(cfg, lh, lv) == (golden_code(cfg, lh, lv), 7)


def _sums(cfg, at, fill=None):
    """Per-disparity sums: ``fill`` (the largest sum) except {d: S} in ``at``; split into the two inputs (the first
    at most ``path_max``)."""
    fill = cfg.sum_max if fill is None else fill
    total = [at.get(d, fill) for d in range(cfg.disparities)]
    lh = [min(t, cfg.path_max) for t in total]
    return lh, [t - h for t, h in zip(total, lh)]


# D = 8, 4 lanes (SMALL_DEPTH): groups 0..3 and 4..7. (name, winner's sums {d: S}, max_cost, expected code)
WINNER_CASES = [
    ("last lane of a group: S(d + 1) from the next group", {3: 10, 2: 30, 4: 20}, 120, 16 * 3 + 4),
    ("first lane of a group: S(d - 1) from the previous one", {4: 10, 3: 20, 5: 30}, 120, 16 * 4 - 4),
    ("next group's lane 0 is not a better winner", {3: 10, 4: 10, 2: 30}, 120, 16 * 3 + 8),
    ("d = 0: no fraction", {0: 5, 1: 6}, 120, 0),
    ("d = D - 1: invalid", {7: 5, 6: 9}, 120, 128),
    ("d = D - 2, flat to the right: + 1/2", {6: 5, 7: 5, 5: 9}, 120, 16 * 6 + 8),
    ("steep right: -1/2", {2: 5, 1: 6}, 120, 16 * 2 - 8),
    ("half up: +0.5/16 -> 1", {2: 4, 1: 20, 3: 19}, 120, 16 * 2 + 1),
    ("half up: -0.5/16 -> 0", {2: 4, 1: 19, 3: 20}, 120, 16 * 2),
    ("S* = max_cost: valid", {2: 40, 1: 60, 3: 50}, 40, 16 * 2 + 4),
    ("S* = max_cost + 1: invalid", {2: 41, 1: 61, 3: 51}, 40, 128),
    ("the largest sums", {2: 0, 1: 288, 3: 287}, 120, 16 * 2),
]


@pytest.mark.parametrize("name, at, max_cost, expected", WINNER_CASES, ids=[c[0] for c in WINNER_CASES])
def test_winner_boundaries(name, at, max_cost, expected):
    """Deterministic cases at the ends of the fit and of the validity rule, RTL and golden model alike."""
    cfg = DepthConfig(disparities=8, lanes=4, max_cost=max_cost)
    lh, lv = _sums(cfg, at)
    assert golden_code(cfg, lh, lv) == expected
    assert run_winner(cfg, lh, lv) == (expected, 7)


# Uniqueness k = 60: valid iff 64 S* <= 60 S2, S2 = the best sum 2 or more disparities from d*.
UNIQUENESS_CASES = [
    ("64 S* = k S2 (15 vs 16): valid", {2: 15, 1: 20, 3: 20, 5: 16}, 32),
    ("S* one past (16 vs 16): invalid", {2: 16, 1: 21, 3: 21, 5: 16}, 128),
    ("d* + 1 is no second best", {2: 15, 1: 20, 3: 15, 5: 16}, 32 + 8),
    ("d* - 1 is no second best", {2: 15, 1: 16, 3: 24, 6: 16}, 32 - 7),
    ("d* - 2 is one", {2: 15, 0: 15, 1: 20, 3: 20}, 128),
    ("across groups: d* = 3, d = 4 excluded, d = 5 counted", {3: 15, 4: 15, 2: 30, 5: 16}, 48 + 8),
    ("across groups: d = 5 one past", {3: 15, 4: 15, 2: 30, 5: 15}, 128),
    ("across groups: d* = 4, d = 3 excluded, d = 2 counted", {4: 15, 3: 16, 5: 30, 2: 15}, 128),
]


@pytest.mark.parametrize("name, at, expected", UNIQUENESS_CASES, ids=[c[0] for c in UNIQUENESS_CASES])
def test_uniqueness_boundaries(name, at, expected):
    """The confidence rule exactly at its threshold and one past, and which disparities count as S2, RTL and
    golden model alike."""
    cfg = DepthConfig(disparities=8, lanes=4, uniqueness=60)
    lh, lv = _sums(cfg, at)
    assert golden_code(cfg, lh, lv) == expected
    assert run_winner(cfg, lh, lv) == (expected, 7)


#: The 800 x 600 configurations' thresholds: DEPTH_800_BASE (D = 128, two paths) and DEPTH_800_THREE (the third
#: path's variant: max_cost 180, sums up to 3 (N + P2) = 432, the winner's vertical input the carried S2 = L_lr +
#: L_tb, ``ReversePath.carry_bits`` wide). (name, config, {d: S}, the other sums, expected code)
_THREE = dataclasses.replace(DEPTH_800_THREE, disparities=8, lanes=4)
_UNIQUE = dataclasses.replace(_THREE, uniqueness=60, max_cost=432)
CASES_800 = [
    ("three paths: S* = max_cost 180 valid", _THREE, {3: 180}, 300, 16 * 3),
    ("three paths: S* = max_cost + 1 invalid", _THREE, {3: 181}, 300, _THREE.invalid),
    ("three paths: 64 S* = k S2 at the top of the sums (405 vs 432) valid", _UNIQUE, {2: 405, 1: 420, 3: 420}, 432,
     16 * 2),
    ("three paths: S* one past (406 vs 432) invalid", _UNIQUE, {2: 406, 1: 420, 3: 420}, 432, _THREE.invalid),
] + [case for cfg, fill, label in ((DEPTH_800_BASE, 250, "two paths"), (DEPTH_800_THREE, 300, "three paths"))
   for case in (
    (f"{label}, D = 128: d* = D - 2 valid", cfg, {125: 100, 126: 50, 127: 100}, fill, 16 * 126),
    (f"{label}, D = 128: d* = D - 1 invalid (code 2048)", cfg, {126: 100, 127: 50}, fill, 2048),
    (f"{label}, D = 128, k = 64 (off): S2 = S* valid", cfg, {10: 100, 50: 100}, fill, 16 * 10),
    (f"{label}, D = 128, k = 63: S2 = S* invalid", dataclasses.replace(cfg, uniqueness=63), {10: 100, 50: 100}, fill,
     2048))]


@pytest.mark.parametrize("name, cfg, at, fill, expected", CASES_800, ids=[c[0] for c in CASES_800])
def test_800_winner_boundaries(name, cfg, at, fill, expected):
    """The 800 x 600 configurations' thresholds exactly at the threshold and one past: max_cost 180 = 60 per path
    and the confidence rule at the top of the three-path sums; at D = 128, for two and three paths, the last
    disparity, the 12-bit invalid code and the confidence rule at k = 64 (off) against 63. RTL (the winner with the
    engine's widths for the configuration's paths) and golden model alike; the rest of the sums ``fill``."""
    vertical_bits = ReversePath(cfg, width=cfg.disparities).carry_bits if cfg.paths == THREE_PATHS else None
    lh, lv = _sums(cfg, at, fill=fill)
    assert max(lv) < 1 << (vertical_bits or cfg.path_bits) and cfg.sum_max == 144 * len(cfg.paths)
    assert golden_code(cfg, lh, lv) == expected
    assert run_winner(cfg, lh, lv, vertical_bits=vertical_bits)[0] == expected


@pytest.mark.parametrize("margin", [2, 8, 40])
def test_row_ring_tag_sample_timing(margin):
    """RowRing's two tag samples (docs/depth.md, "Row tags"): a tag source that answers busy for row r only to the
    ask in clock last_read(r) + margin makes row r torn (rows 0, 3, ...); busy for every other ask of r from its
    first read on leaves it whole (rows 1, 4, ...); busy for the asks of r before its first read makes it torn
    (rows 2, 5, ...). So the start sample is asked before the first read, the end sample exactly ``margin``
    clocks after the last; ``tagged`` counts a row ``margin`` + 3 clocks after its last read. Random grants;
    margin 40 is more than a 16-pixel row takes (the ring then holds the next row's last read back)."""
    from hdl.depth.row_ring import RowRing
    from spec.sensor import SMALL_SENSOR

    g = SMALL_SENSOR
    w, h = g.buf_width, g.buf_height
    dut = RowRing(g, 8, tag_margin=margin)
    rng = np.random.default_rng(margin)
    first, last, torn, counted = {}, {}, {}, {}

    def busy_for(row, t):
        mode = row % 3
        if mode == 0:
            return row in last and t == last[row] + margin
        if mode == 1:
            return row in first and not (row in last and t == last[row] + margin)
        return row not in first

    async def bench(ctx):
        ctx.set(dut.limit, h)
        ctx.set(dut.start, 1)
        await ctx.tick()
        ctx.set(dut.start, 0)
        answer, tagged = 0, 0
        for t in range(20 * w * h):
            grant = int(rng.integers(0, 3) != 0)
            ctx.set(dut.buffer.grant, grant)
            ctx.set(dut.tags.busy, answer)
            ctx.set(dut.tags.tag, 5)
            ask = ctx.get(dut.tags.row)
            if ctx.get(dut.buffer.request) and grant:
                row = ctx.get(dut.fetch_row)
                first.setdefault(row, t)
                if ctx.get(dut.fetch_col) == w - 1:
                    last[row] = t
            answer = int(busy_for(ask, t))
            await ctx.tick()
            if ctx.get(dut.tagged) != tagged:
                tagged = ctx.get(dut.tagged)
                torn[tagged - 1] = (ctx.get(dut.torn) >> ((tagged - 1) % 8)) & 1
                counted[tagged - 1] = t + 1
            if tagged == h:
                break

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    assert sorted(torn) == list(range(h))
    assert {r: torn[r] for r in range(h)} == {r: int(r % 3 != 1) for r in range(h)}
    assert all(counted[r] - last[r] == margin + 3 for r in range(h))


def test_min_tree_first_smallest():
    """``min_tree`` of 3, 4 and 16 (value, index) items: the smallest value and the first index holding it, for
    every vector of 3 and 4 values in 0..2 (each tie) and random 16-item vectors with ties, one vector a clock."""
    from amaranth import C, Module, Signal

    from hdl.depth.reduce import min_tree, tree_stages

    rng = np.random.default_rng(5)
    sizes = (3, 4, 16)
    vectors = list(itertools.product(range(3), repeat=4)) + [tuple(rng.integers(0, 4, 4)) for _ in range(30)]
    wide = [tuple(rng.integers(0, 6, 16)) for _ in range(len(vectors))]
    m = Module()
    ins = {n: [Signal(4, name=f"in{n}_{k}") for k in range(n)] for n in sizes}
    outs = {n: min_tree(m, [(v, C(k, range(n))) for k, v in enumerate(ins[n])], f"tree{n}") for n in sizes}
    got = {n: [] for n in sizes}

    async def bench(ctx):
        for t in range(len(vectors) + 2):
            if t < len(vectors):
                for n, values in ((3, vectors[t][:3]), (4, vectors[t]), (16, wide[t])):
                    for s, v in zip(ins[n], values):
                        ctx.set(s, int(v))
            await ctx.tick()
            for n in sizes:
                got[n].append((ctx.get(outs[n][0]), ctx.get(outs[n][1])))

    simulate(m, clocks={"sync": 1e8}, testbenches=[bench])
    for n in sizes:
        lag = tree_stages(n)
        for t, values in enumerate(vectors if n < 16 else wide):
            values = list(values)[:n]
            expected = (min(values), values.index(min(values)))
            assert got[n][t + lag - 1] == expected, (n, values, got[n][t + lag - 1])
