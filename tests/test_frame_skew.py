"""FrameSkewMeter: the skew it reports against the times the testbench put the two frame starts at."""

import pytest
from amaranth import Module
from amaranth.hdl import ClockDomain
from amaranth.sim import Simulator

from hdl.frame_skew import FrameSkewMeter

SYS_HZ, PCLK_HZ = 100e6, 80e6


def measure(offsets_s, *, line_clocks=50, max_clocks=2000, pclk_b_hz=PCLK_HZ):
    """Frame starts of camera A every 40 us and of camera B ``offsets_s[k]`` later (negative: earlier); returns
    the meter's (skew, aligned) after each pair."""
    dut = FrameSkewMeter(line_clocks=line_clocks, max_clocks=max_clocks)
    m = Module()
    m.domains += [ClockDomain("sync"), ClockDomain("cam_a"), ClockDomain("cam_b")]
    m.submodules.dut = dut
    sim = Simulator(m)
    sim.add_clock(1 / SYS_HZ, domain="sync")
    sim.add_clock(1 / PCLK_HZ, domain="cam_a")
    sim.add_clock(1 / pclk_b_hz, domain="cam_b", phase=3.1e-9)
    period = 40e-6
    results = []

    def strobe(pin, domain, times):
        async def bench(ctx):
            now = 0.0
            for t in times:
                await ctx.delay(t - now)
                await ctx.tick(domain)
                ctx.set(pin, 1)
                await ctx.tick(domain)
                ctx.set(pin, 0)
                now = t + 2.5 / PCLK_HZ
        return bench

    t_a = [5e-6 + k * period for k in range(len(offsets_s))]
    t_b = [t + o for t, o in zip(t_a, offsets_s)]
    sim.add_testbench(strobe(dut.start_a, "cam_a", t_a), background=True)
    sim.add_testbench(strobe(dut.start_b, "cam_b", t_b), background=True)

    async def reader(ctx):
        count = 0
        while len(results) < len(offsets_s):
            await ctx.tick("sync")
            if ctx.get(dut.status.count) != count:
                count = ctx.get(dut.status.count)
                results.append((ctx.get(dut.status.skew), ctx.get(dut.status.aligned)))
    sim.add_testbench(reader)
    sim.run_until(len(offsets_s) * period + 20e-6)
    return results


def test_skew_in_sync_clocks_both_signs():
    offsets = [0.0, 1e-6, -2.5e-6, 0.3e-6, -0.1e-6]
    got = measure(offsets)
    assert len(got) == len(offsets)
    for offset, (skew, _) in zip(offsets, got):
        # each start lands on its PCLK edge (1/80 MHz) and is sampled by sync (1/100 MHz): within 3 sync clocks
        assert abs(skew - offset * SYS_HZ) <= 3, (offset, skew)


def test_aligned_is_one_line_either_way():
    got = measure([0.2e-6, 0.8e-6, -0.8e-6, -0.2e-6], line_clocks=50)   # 20 and 80 sync clocks
    assert [aligned for _, aligned in got] == [1, 0, 0, 1]


def test_a_missing_start_is_abandoned_after_max_clocks():
    # B 30 us late: beyond max_clocks (20 us), so A's start is abandoned; B's start then opens a measurement that
    # the next A start (10 us later) completes: -10 us.
    got = measure([30e-6, 30e-6], max_clocks=2000)
    assert got and abs(got[0][0] + 1000) <= 3


def test_bad_parameters():
    with pytest.raises(ValueError, match="line_clocks"):
        FrameSkewMeter(line_clocks=0)
    with pytest.raises(ValueError, match="max_clocks"):
        FrameSkewMeter(line_clocks=10, max_clocks=5)
