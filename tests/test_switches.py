"""SwitchControl in the Amaranth simulator: register selection, frame-boundary updates, documented latency."""

import random

import pytest
from amaranth import Module
from amaranth.hdl import DomainRenamer

from spec.board import CLOCKS
from hdl.switches import SWITCH_VALUE_BITS, SwitchControl
from sim.runners.amaranth import simulate

SW7 = 1 << SWITCH_VALUE_BITS


def _run(dut, bench, domain="sync"):
    simulate(dut, clocks={domain: CLOCKS.PIXEL_HZ}, testbenches=[bench])


def expected_registers(sw_by_cycle, frame_start_cycles, stages, n_cycles):
    """The documented behaviour, cycle by cycle: the registers after the clock edge ending cycle ``c``.

    A switch value set in cycle ``s`` (before edge ``s``) is loaded by a frame_start in cycle ``k`` when
    ``k >= s + stages + 1``; the disparity register takes the last such value with SW7 = 1, the
    rectification register the last with SW7 = 0, read as seven bits of two's complement (hdl/switches.py:
    SW6 = 1 is negative). Both start at 0.
    """
    disp, rect = 0, 0
    out = []
    for c in range(n_cycles):
        if c in frame_start_cycles:
            visible = [v for s, v in sw_by_cycle if s <= c - stages - 1]
            d_values = [v & (SW7 - 1) for v in visible if v & SW7]
            r_values = [v & (SW7 - 1) for v in visible if not v & SW7]
            # Values visible earlier were loaded into the pending registers; the latest of each kind counts.
            disp = d_values[-1] if d_values else 0
            rect = r_values[-1] if r_values else 0
            rect = rect - SW7 if rect & (SW7 >> 1) else rect
        out.append((disp, rect))
    return out


def test_selects_register_and_waits_for_frame_start():
    dut = SwitchControl()

    async def bench(ctx):
        ctx.set(dut.sw, SW7 | 22)            # thesis figure 4.15: disparity 22
        await ctx.tick().repeat(10)
        settings = (ctx.get(dut.settings.disparity), ctx.get(dut.settings.rectification))
        assert settings == (0, 0), "changed without frame_start"
        ctx.set(dut.frame_start, 1)
        await ctx.tick()
        ctx.set(dut.frame_start, 0)
        assert (ctx.get(dut.settings.disparity), ctx.get(dut.settings.rectification)) == (22, 0)
        ctx.set(dut.sw, 3)                   # SW7 = 0: rectification 3 (figure 4.14); disparity holds 22
        await ctx.tick().repeat(10)
        assert (ctx.get(dut.settings.disparity), ctx.get(dut.settings.rectification)) == (22, 0)
        ctx.set(dut.frame_start, 1)
        await ctx.tick()
        ctx.set(dut.frame_start, 0)
        assert (ctx.get(dut.settings.disparity), ctx.get(dut.settings.rectification)) == (22, 3)
        ctx.set(dut.sw, SW7 | 127)
        await ctx.tick().repeat(10)
        ctx.set(dut.frame_start, 1)
        await ctx.tick()
        assert (ctx.get(dut.settings.disparity), ctx.get(dut.settings.rectification)) == (127, 3)

    _run(dut, bench)


@pytest.mark.parametrize("stages", [2, 3])
def test_latency_boundary(stages):
    """A frame_start ``k`` clocks after a change loads it exactly when ``k >= stages + 1`` (the docstring)."""
    dut = SwitchControl(stages=stages)
    seen = {}

    async def bench(ctx):
        value = 0
        for k in range(stages + 4):
            value = 1 + (value % 100)
            ctx.set(dut.sw, SW7 | value)
            for _ in range(k):
                await ctx.tick()
            ctx.set(dut.frame_start, 1)
            await ctx.tick()
            ctx.set(dut.frame_start, 0)
            seen[k] = (ctx.get(dut.settings.disparity), value)
            await ctx.tick().repeat(stages + 3)          # let the value reach the pending register
            ctx.set(dut.frame_start, 1)
            await ctx.tick()
            ctx.set(dut.frame_start, 0)
            assert ctx.get(dut.settings.disparity) == value

    _run(dut, bench)
    for k, (got, value) in seen.items():
        if k >= stages + 1:
            assert got == value, f"frame_start {k} clocks after the change should load it"
        else:
            assert got != value, f"frame_start {k} clocks after the change is too early to load it"


@pytest.mark.parametrize("use_renamer", [False, True])
def test_random_switching_matches_documented_behaviour(use_renamer):
    """Random switch changes and frame starts; in the ``pix`` domain, by argument and by DomainRenamer.
    The registers change only on the clock after a frame_start and follow the documented latency."""
    rng = random.Random(5)
    n = 600
    sw_by_cycle = []
    t = 0
    while t < n:
        sw_by_cycle.append((t, rng.randrange(256)))
        t += rng.choice([1, 2, 3, 5, 20, 40])
    frame_starts = set(rng.sample(range(n), 60))
    expected = expected_registers(sw_by_cycle, frame_starts, 2, n)
    changes = dict(sw_by_cycle)

    if use_renamer:
        inner = SwitchControl()
        dut = DomainRenamer("pix")(inner)
    else:
        inner = dut = SwitchControl(domain="pix")
    top = Module()
    top.submodules.switches = dut
    got = []

    async def bench(ctx):
        for c in range(n):
            if c in changes:
                ctx.set(inner.sw, changes[c])
            ctx.set(inner.frame_start, c in frame_starts)
            await ctx.tick("pix")
            got.append((ctx.get(inner.settings.disparity), ctx.get(inner.settings.rectification)))

    simulate(top, clocks={"pix": CLOCKS.PIXEL_HZ}, testbenches=[bench])
    for c in range(1, n):
        if got[c] != got[c - 1]:
            assert c in frame_starts, f"registers changed at clock {c} without frame_start"
    assert got == expected
    assert len(set(got)) > 10


@pytest.mark.parametrize("switches, offset", [
    (0b0000000, 0), (0b0000011, 3), (0b0000101, 5), (0b0111111, 63),          # the thesis's meaning, 0..63
    (0b1111111, -1), (0b1110000, -16), (0b1000000, -64)])                      # SW6 = 1: negative
def test_signed_rectification_encoding(switches, offset):
    """SW7 = 0, SW6..SW0 = two's complement: the documented encoding, boundary values included."""
    dut = SwitchControl()

    async def bench(ctx):
        ctx.set(dut.sw, switches)
        await ctx.tick().repeat(4)
        ctx.set(dut.frame_start, 1)
        await ctx.tick()
        assert ctx.get(dut.settings.rectification) == offset
        assert ctx.get(dut.settings.disparity) == 0

    _run(dut, bench)


def test_bad_stages():
    with pytest.raises(ValueError):
        SwitchControl(stages=1)
