"""The left-right check's blocks against the golden stage (docs/depth.md, "left-right check"):
``LeftWinner`` (the left view's running minimum) and ``LeftRightFill`` (the check, the row store and the fill)."""

import numpy as np
import pytest

from golden.depth import background_fill, left_right_keep, left_winner
from hdl.depth.left_right_fill import LeftRightFill
from hdl.depth.left_winner import LeftWinner
from spec.depth import DepthConfig
from sim.runners.amaranth import simulate

WIDTH = 12
CONFIGS = [DepthConfig(disparities=8, lanes=4), DepthConfig(disparities=6, lanes=2),
           DepthConfig(disparities=4, lanes=4)]


def run_left_winner(cfg, total, spacing):
    """Rows of sums (D x H x W) through a LeftWinner, pixels ``spacing`` clocks apart: d_L (H x W)."""
    dut = LeftWinner(cfg, WIDTH)
    d, h, w = total.shape
    G, P = d // cfg.lanes, cfg.lanes
    got = np.full((h, w), -1)

    async def bench(ctx):
        for y in range(h):
            for x in range(w):
                for clock in range(spacing):
                    go = clock < G
                    ctx.set(dut.token, {"go": go, "group": clock if go else 0, "last": clock == G - 1,
                                        "first": x == 0, "x": x})
                    for k in range(P):
                        ctx.set(dut.sums[k], int(total[clock * P + k, y, x]) if go else 0)
                    await ctx.tick()
                    if ctx.get(dut.valid):
                        assert clock == 0, "d_L one clock after group 0"
                        got[y, ctx.get(dut.x)] = ctx.get(dut.d)
        ctx.set(dut.token, {"go": 0, "group": 0, "last": 0, "first": 0, "x": 0})
        await ctx.tick()
        if ctx.get(dut.valid):
            got[h - 1, ctx.get(dut.x)] = ctx.get(dut.d)

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    return got


@pytest.mark.parametrize("cfg", CONFIGS, ids=lambda c: f"D{c.disparities}x{c.lanes}")
def test_left_winner_matches_golden(cfg):
    rng = np.random.default_rng(cfg.disparities)
    total = rng.integers(0, 6, size=(cfg.disparities, 3, WIDTH))      # small range: many ties
    total[:, 2] = rng.integers(0, cfg.sum_max + 1, size=(cfg.disparities, WIDTH))
    total[:, 1, :] = total[:, 1, :].max()               # a row of ties only: every d_L 0
    G = cfg.disparities // cfg.lanes
    got = run_left_winner(cfg, total, G + 1)
    assert (got == left_winner(total)).all()


def run_fill(cfg, rows, stop=None):
    """Rows of (codes, d*, d_L) through a LeftRightFill as the engine drives it: a row's codes in ascending x every
    3 clocks (its d_L beside them, in descending x), from 3 clocks after the previous row's ``replay`` on (during
    that replay, each x after the replay has read it); ``start``; ``replay`` ``scan_clocks`` later. Returns per
    row the replay's outputs, (clocks after ``replay``, x, code). ``stop``: "scan" (3 clocks after the first row's
    ``start``) or "replay" (6 clocks after its ``replay``): that row gives None, and the next row is written an x
    a clock and started before that replay would have ended."""
    dut = LeftRightFill(cfg, WIDTH)
    out = []
    state = {"list": None, "since": 0}

    async def step(ctx, clocks=1):
        for _ in range(clocks):
            if state["list"] is not None and ctx.get(dut.valid):
                state["list"].append((state["since"], ctx.get(dut.x), ctx.get(dut.out_code)))
            await ctx.tick()
            state["since"] += 1

    async def pulse(ctx, port):
        ctx.set(port, 1)
        await step(ctx)
        ctx.set(port, 0)

    async def bench(ctx):
        gap = 2
        for r, (codes, dstar, dl) in enumerate(rows):
            await step(ctx, 2)
            for x in range(WIDTH):
                ctx.set(dut.code_valid, 1)
                ctx.set(dut.code_x, x)
                ctx.set(dut.code, int(codes[x]))
                ctx.set(dut.code_d, int(dstar[x]))
                ctx.set(dut.left_valid, 1)
                ctx.set(dut.left_x, WIDTH - 1 - x)
                ctx.set(dut.left_d, int(dl[WIDTH - 1 - x]))
                await step(ctx)
                ctx.set(dut.code_valid, 0)
                ctx.set(dut.left_valid, 0)
                await step(ctx, gap)
            await pulse(ctx, dut.start)
            if stop == "scan" and r == 0:
                await step(ctx, 2)
                await pulse(ctx, dut.stop)
                out.append(None)
                gap = 0
                continue
            await step(ctx, LeftRightFill.scan_clocks(WIDTH) - 1)
            state["list"], state["since"] = [], 0
            out.append(state["list"])
            await pulse(ctx, dut.replay)
            if stop == "replay" and r == 0:
                await step(ctx, 5)
                await pulse(ctx, dut.stop)
                out[-1] = state["list"] = None
                gap = 0
            else:
                gap = 2
        await step(ctx, LeftRightFill.replay_clocks(WIDTH) + 2)

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    return out


@pytest.mark.parametrize("cfg", CONFIGS[:2], ids=lambda c: f"D{c.disparities}x{c.lanes}")
def test_fill_matches_golden(cfg):
    rng = np.random.default_rng(7 + cfg.disparities)
    total = rng.integers(0, 8, size=(cfg.disparities, 4, WIDTH))
    total[:, 3] = 5                                   # all ties: d* = 0, d_L = 0: every valid code kept
    dstar = np.argmin(total, axis=0)
    codes = (dstar * cfg.fraction + rng.integers(-8, 9, size=dstar.shape)).clip(0, cfg.invalid - 1)
    codes[rng.random(codes.shape) < 0.3] = cfg.invalid
    codes[2] = cfg.invalid                            # a row without a valid code
    codes = codes.astype(np.uint16)
    keep = left_right_keep(total, codes, cfg)
    expected = background_fill(codes, keep, cfg)
    assert not keep.all() and keep.any()
    dl = left_winner(total)
    got = run_fill(cfg, [(codes[y], dstar[y], dl[y]) for y in range(4)])
    for y, row in enumerate(got):
        assert [x for _, x, _ in row] == list(range(WIDTH + 1))
        assert row[-1][0] == LeftRightFill.replay_clocks(WIDTH)
        assert [c for _, _, c in row[:-1]] == expected[y].tolist()
        assert all(b - a == 2 for (a, _, _), (b, _, _) in zip(row, row[1:]))


@pytest.mark.parametrize("stop", ["scan", "replay"])
def test_fill_stop_in_the_scan_and_the_replay(stop):
    """``stop`` in the scan or the replay: the block takes the next row's writes at once and replays that row."""
    cfg = CONFIGS[0]
    rng = np.random.default_rng(len(stop))
    total = rng.integers(0, 8, size=(cfg.disparities, 2, WIDTH))
    dstar = np.argmin(total, axis=0)
    codes = (dstar * cfg.fraction).astype(np.uint16)
    codes[rng.random(codes.shape) < 0.3] = cfg.invalid
    expected = background_fill(codes, left_right_keep(total, codes, cfg), cfg)
    dl = left_winner(total)
    got = run_fill(cfg, [(codes[y], dstar[y], dl[y]) for y in range(2)], stop)
    assert got[0] is None
    assert [c for _, _, c in got[1][:-1]] == expected[1].tolist()
