# amaranth: UnusedElaboratable=no
"""The right-to-left path block (hdl/depth/reverse_path.py) against golden/depth.py on Amaranth's simulator: rows of
costs replayed in descending x give golden.depth.path_cost(cost, "right_to_left") bit for bit, and the stored
carries come back added; the path starts at x = W - 1 and nowhere else; the widths hold the largest values."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from golden.depth import path_cost
from hdl.depth.reverse_path import ReversePath
from spec.depth import SMALL_DEPTH, THREE_PATHS, DepthConfig
from sim.runners.amaranth import simulate

CONFIGS = [SMALL_DEPTH, DepthConfig(disparities=6, lanes=2, p1=7, p2=200)]


def token(group, last, x=0, first=0, go=1):
    return {"go": go, "group": group, "last": last, "first": first, "x": x}


def run_rows(cfg, width, rows, *, other_paths=2, spacing=None, claim_first=0):
    """Each row of ``rows`` = (cost D x W, carry D x W): its carries stored in pixel order, then its costs replayed
    from x = W - 1 down to 0 at ``spacing`` clocks per pixel (the path's loop by default), the next row's carries
    stored while the replay's last pixel is still in the pipeline. ``claim_first``: the token's ``first`` bit as
    the reverse pass sends it (the block must ignore it). Returns [(L, total)], each D x W."""
    dut = ReversePath(cfg, width=width, other_paths=other_paths)
    groups, lanes = cfg.disparities // cfg.lanes, cfg.lanes
    spacing = ReversePath.loop_clocks(cfg) if spacing is None else spacing
    got = [(np.full((cfg.disparities, width), -1), np.full((cfg.disparities, width), -1)) for _ in rows]
    row_of = {}

    async def bench(ctx):
        def collect(index):
            t = ctx.get(dut.out_token)
            if t.go:
                for k in range(lanes):
                    d = t.group * lanes + k
                    got[index][0][d, t.x] = ctx.get(dut.l[k])
                    got[index][1][d, t.x] = ctx.get(dut.total[k])

        for index, (cost, carry) in enumerate(rows):
            for x in range(width):
                for g in range(groups):
                    ctx.set(dut.store_token, token(g, g == groups - 1, x=x))
                    for k in range(lanes):
                        ctx.set(dut.carry[k], int(carry[g * lanes + k, x]))
                    await ctx.tick()
                    collect(row_of.get("replaying", index))
            ctx.set(dut.store_token, token(0, 0, go=0))
            row_of["replaying"] = index
            for clock in range(width * spacing + ReversePath.LATENCY + 1):
                step, g = divmod(clock, spacing)
                if step < width and g < groups:
                    x = width - 1 - step
                    ctx.set(dut.token, token(g, g == groups - 1, x=x, first=claim_first))
                    for k in range(lanes):
                        ctx.set(dut.cost[k], int(cost[g * lanes + k, x]))
                else:
                    ctx.set(dut.token, token(0, 0, go=0))
                await ctx.tick()
                collect(index)

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    return got


def expected(cfg, cost, carry):
    l_rl = path_cost(cost[:, None, :], "right_to_left", cfg)[:, 0]
    return l_rl, l_rl + carry


def edgy(top):
    return st.one_of(st.integers(0, top), st.sampled_from([0, 1, top - 1, top]))


@settings(max_examples=8, deadline=None)
@given(st.data())
def test_rows_bit_exact(data):
    """Two rows back to back at the loop's spacing: L_rl equals the golden right-to-left path of each row (the
    second row starts afresh at its last column), and total = the stored carry + L_rl."""
    cfg = data.draw(st.sampled_from(CONFIGS))
    width = data.draw(st.integers(cfg.disparities, cfg.disparities + 4))
    rows = []
    for _ in range(2):
        cost = np.array(data.draw(st.lists(st.lists(edgy(cfg.census_bits), min_size=width, max_size=width),
                                           min_size=cfg.disparities, max_size=cfg.disparities)))
        carry = np.array(data.draw(st.lists(st.lists(edgy(2 * cfg.path_max), min_size=width, max_size=width),
                                            min_size=cfg.disparities, max_size=cfg.disparities)))
        rows.append((cost, carry))
    claim = data.draw(st.integers(0, 1))
    for (cost, carry), (l_got, total_got) in zip(rows, run_rows(cfg, width, rows, claim_first=claim)):
        l_rl, total = expected(cfg, cost, carry)
        assert (l_got == l_rl).all()
        assert (total_got == total).all()


def test_start_at_the_last_column_only():
    """The boundary of the path's start: at x = W - 1 L_rl = C (the previous row's vectors ignored), at x = W - 2
    the recursion already runs (a cost row whose steps differ from C alone). A block that restarts at x = W - 2 as
    well, or not at W - 1, gives other values."""
    cfg, width = SMALL_DEPTH, 10
    rng = np.random.default_rng(3)
    first = (rng.integers(0, cfg.census_bits + 1, (cfg.disparities, width)), np.zeros((cfg.disparities, width)))
    cost = np.zeros((cfg.disparities, width), dtype=np.int64)
    cost[:, -1] = np.arange(cfg.disparities) * 5          # a slope at x = W - 1 ...
    cost[:, -2] = cfg.census_bits - np.arange(cfg.disparities)      # ... and the opposite one at W - 2
    (_, _), (l_got, _) = run_rows(cfg, width, [first, (cost, np.zeros_like(cost))])
    l_rl, _ = expected(cfg, cost, np.zeros_like(cost))
    assert (l_got[:, -1] == cost[:, -1]).all()
    assert (l_got[:, -2] != cost[:, -2]).any()
    assert (l_got == l_rl).all()


def test_largest_values_do_not_wrap():
    """The top of every range: one cheap disparity (cost 0 at d = 0, N elsewhere) drives the other disparities'
    L_rl up to N + P2 within three pixels, and with the forward paths' largest carry, 2 (N + P2), the total reaches
    3 (N + P2) = sum_max of three paths, which ``total`` holds without wrapping."""
    cfg = DepthConfig(disparities=8, lanes=4)
    width = 9
    cost = np.full((cfg.disparities, width), cfg.census_bits)
    cost[0] = 0
    carry = np.full((cfg.disparities, width), 2 * cfg.path_max)
    dut = ReversePath(cfg, width=width)
    assert dut.sum_bits == DepthConfig(disparities=8, lanes=4, paths=THREE_PATHS).sum_bits
    (l_got, total_got), = run_rows(cfg, width, [(cost, carry)])
    l_rl, total = expected(cfg, cost, carry)
    assert l_rl.max() == cfg.path_max and total.max() == 3 * cfg.path_max
    assert (l_got == l_rl).all() and (total_got == total).all()


def test_slower_spacing_and_parameters():
    """Pixels further apart than the loop give the same values; bad parameters are one-line ValueErrors."""
    cfg, width = DepthConfig(disparities=6, lanes=2, p1=7, p2=200), 7
    rng = np.random.default_rng(11)
    cost = rng.integers(0, cfg.census_bits + 1, (cfg.disparities, width))
    carry = rng.integers(0, 2 * cfg.path_max + 1, (cfg.disparities, width))
    (l_got, total_got), = run_rows(cfg, width, [(cost, carry)], spacing=ReversePath.loop_clocks(cfg) + 3)
    l_rl, total = expected(cfg, cost, carry)
    assert (l_got == l_rl).all() and (total_got == total).all()
    for kwargs, message in ((dict(config=DepthConfig(disparities=6, lanes=4)), "lanes"),
                            (dict(width=5), "width"), (dict(other_paths=0), "other_paths")):
        kwargs = {"config": SMALL_DEPTH, "width": 16, **kwargs}
        with pytest.raises(ValueError, match=message):
            ReversePath(kwargs.pop("config"), **kwargs)


def test_census_windows_filled_from_the_right_give_the_same_costs():
    """The reverse pass's census (docs/depth.md, scheme a'): windows filled column by column from the right hold
    every signature with its bits mirrored within each window row (the census of the mirrored image, mirrored
    back); the signatures differ, the Hamming costs do not, since both sides' bits are permuted alike. Mirroring
    one side only changes the costs."""
    from golden.depth import census, matching_cost
    cfg = SMALL_DEPTH
    rng = np.random.default_rng(5)
    left, right = (rng.integers(0, 1 << cfg.pixel_bits, (12, 16)) for _ in range(2))
    h, w = left.shape

    def costs(sig_left, sig_right):
        out = np.full((cfg.disparities, h, w), cfg.census_bits)
        for d in range(cfg.disparities):
            out[d, :, :w - d] = np.bitwise_count(sig_right[:, :w - d] ^ sig_left[:, d:])
        return out

    mirrored = {name: census(np.fliplr(image), cfg)[:, ::-1] for name, image in (("l", left), ("r", right))}
    plain = {"l": census(left, cfg), "r": census(right, cfg)}
    assert (mirrored["l"] != plain["l"]).any()
    assert (costs(mirrored["l"], mirrored["r"]) == matching_cost(left, right, cfg)).all()
    assert (costs(mirrored["l"], plain["r"]) != matching_cost(left, right, cfg)).any()


#: L_rl at x = W - 1 is C there; at x = W - 2 (C = 2 there) the recursion's terms meet at their thresholds. P1 = 5,
#: P2 = 20, D = 8 in two groups of 4 lanes (d = 3 | 4 across the groups). (L' = C(W - 1), min(...) - M' by hand.)
PENALTY_ROWS = [
    # M' = 3, M' + P2 = 23. d = 1: L'(1) = L'(0) + P1 (tie, 8); d = 2: L'(2) = L'(1) + P1 + 1 (the P1 term wins
    # by one, 13); d = 5: L'(5) = M' + P2 (tie, 23); d = 7 (no d + 1): L'(7) = M' + P2 + 1 (P2 wins by one, 23).
    ([3, 8, 14, 33, 48, 23, 48, 24], [0, 5, 10, 16, 20, 20, 20, 20]),
    # M' = 0, M' + P2 = 20. d = 0 (no d - 1): L'(0) = L'(1) + P1 (tie, 11); d = 1: L'(1) = L'(2) + P1 + 1 (the
    # d + 1 term wins by one, 5); d = 4: L'(3) + P1 = M' + P2 (tie, 20) and L'(5) + P1 = M' + P2 + 1; d = 6:
    # L'(5) + P1 = M' + P2 + 1 (P2 wins by one, 20).
    ([11, 6, 0, 15, 48, 16, 48, 48], [11, 5, 0, 5, 20, 16, 20, 20]),
]


def test_penalties_at_their_thresholds():
    """The right-to-left recursion's P1 and P2 terms exactly at their thresholds and one past (``PENALTY_ROWS``):
    values by hand, the golden model and the RTL alike."""
    cfg, width = DepthConfig(disparities=8, lanes=4, p1=5, p2=20), 9
    rows, hand = [], []
    for last, terms in PENALTY_ROWS:
        cost = np.zeros((cfg.disparities, width), dtype=np.int64)
        cost[:, -1], cost[:, -2] = last, 2
        rows.append((cost, np.zeros_like(cost)))
        hand.append((np.array(last), 2 + np.array(terms)))
    for (cost, _), (l_got, total_got), (at_last, at_next) in zip(rows, run_rows(cfg, width, rows), hand):
        l_rl, _ = expected(cfg, cost, np.zeros_like(cost))
        assert (l_rl[:, -1] == at_last).all() and (l_rl[:, -2] == at_next).all()
        assert (l_got[:, -2:] == l_rl[:, -2:]).all() and (total_got[:, -2:] == l_rl[:, -2:]).all()
