"""I2CMaster in the Amaranth simulator, driven command by command, against the project's register-file models
(sim/models/{i2c,mt9d112,ch7301c}/) and a bus monitor that measures the UM10204 intervals from the two lines.

The sync clock runs at 2 MHz here (the RTL derives every bus interval from ``clk_hz``; the bus still runs at
100 kHz in real time), so a byte costs ~210 clocks; the board's 100 MHz configuration is checked for timing
on Verilator and Icarus (tests/test_i2c_init.py) and by :class:`I2CTiming` below.
"""

import pytest

from sim.runners.amaranth import simulate

from hdl.i2c_master import Cmd, I2CMaster, I2CTiming
from sim.models.i2c.bus import I2CBench, amaranth_target_process
from sim.models.ch7301c.target import CH7301CModel
from sim.models.i2c.monitor import I2CBusMonitor
from sim.models.i2c.target import I2CTarget
from sim.models.mt9d112.target import MT9D112Model

CLK = 2_000_000
TIMEOUT_US = 400

# NXP UM10204 Rev. 7, table 10 (typed here independently of hdl/i2c_master.py), microseconds.
UM10204_US = {
    100_000: dict(low=4.7, high=4.0, su_sta=4.7, hd_sta=4.0, su_dat=0.25, vd_dat=3.45, su_sto=4.0, buf=4.7),
    400_000: dict(low=1.3, high=0.6, su_sta=0.6, hd_sta=0.6, su_dat=0.1, vd_dat=0.9, su_sto=0.6, buf=1.3),
}


def run_master(targets, script, *, clk=CLK, bus_hz=100_000, timeout_us=TIMEOUT_US, limit_s=0.05):
    """Run ``script(ctx, master, do)`` (an async testbench; ``do(cmd, wdata, rd_ack)`` issues one command and
    returns its result dict) with ``targets`` on the bus. Returns the bus monitor."""
    master = I2CMaster(clk_hz=clk, bus_hz=bus_hz, timeout_us=timeout_us)
    bench = I2CBench({"bus": master})
    monitor = I2CBusMonitor()
    target = amaranth_target_process(bench.bus.bus, targets, clk, bench.cycles, monitor)

    async def do(ctx, cmd, wdata=0, rd_ack=0):
        ctx.set(master.cmd, cmd)                              # offered before ready: accepted at once
        ctx.set(master.wdata, wdata)
        ctx.set(master.rd_ack, rd_ack)
        ctx.set(master.cmd_valid, 1)
        await ctx.tick().until(master.ready)
        ctx.set(master.cmd_valid, 0)
        await ctx.tick().until(master.done)
        return dict(nack=ctx.get(master.nack), rdata=ctx.get(master.rdata), arb=ctx.get(master.arb_lost),
                    timeout=ctx.get(master.timed_out), active=ctx.get(master.bus_active),
                    cycles=ctx.get(bench.cycles), scl_oe=ctx.get(master.i2c.scl.oe), sda_oe=ctx.get(master.i2c.sda.oe))

    finished = []

    async def bench_tb(ctx):
        await script(ctx, master, lambda *a, **k: do(ctx, *a, **k))
        assert ctx.get(bench.bus.bus.drive_high) == 0, "the master drove a line high"
        finished.append(True)

    simulate(bench, clocks={"sync": clk}, testbenches=[bench_tb], processes=[target], timeout_s=limit_s,
             timeout_message=f"the test script did not finish within {limit_s} s of simulated time")
    assert finished
    return monitor


def test_write_then_read_with_repeated_start():
    model = CH7301CModel()
    results = []

    async def script(ctx, master, do):
        for step in [(Cmd.START,), (Cmd.WRITE, 0xEC), (Cmd.WRITE, 0x1F), (Cmd.WRITE, 0x98), (Cmd.STOP,),
                     (Cmd.START,), (Cmd.WRITE, 0xEC), (Cmd.WRITE, 0x1F), (Cmd.START,), (Cmd.WRITE, 0xED),
                     (Cmd.READ, 0, 0), (Cmd.STOP,)]:
            results.append(await do(*step))

    mon = run_master([model], script)
    assert [r["nack"] for r in results] == [0] * 12
    assert not any(r["arb"] or r["timeout"] for r in results)
    assert results[10]["rdata"] == 0x98
    assert results[4]["active"] == 0 and results[8]["active"] == 1
    assert model.writes == [(0x1F, 0x98)] and model.reads == [(0x1F, 0x98)]
    assert mon.transactions == [[(0xEC, True), (0x1F, True), (0x98, True)],
                                [(0xEC, True), (0x1F, True), "Sr", (0xED, True), (0x98, False)]]
    assert mon.violations() == [] and mon.protocol_errors == []


def test_two_byte_read_acks_all_but_last():
    model = MT9D112Model(boot_s=0)
    got = []

    async def script(ctx, master, do):
        for step in [(Cmd.START,), (Cmd.WRITE, 0x78), (Cmd.WRITE, 0x30), (Cmd.WRITE, 0x00), (Cmd.START,),
                     (Cmd.WRITE, 0x79), (Cmd.READ, 0, 1), (Cmd.READ, 0, 0), (Cmd.STOP,)]:
            got.append(await do(*step))

    mon = run_master([model], script)
    assert (got[6]["rdata"] << 8) | got[7]["rdata"] == 0x1580
    assert mon.transactions[0][-2:] == [(0x15, True), (0x80, False)]   # master ACKs byte 1, NACKs byte 2


def test_nack_of_absent_address():
    got = []

    async def script(ctx, master, do):
        got.extend([await do(Cmd.START), await do(Cmd.WRITE, 0x50 << 1), await do(Cmd.STOP)])

    mon = run_master([CH7301CModel()], script)
    assert got[1]["nack"] == 1 and got[2]["active"] == 0
    assert mon.transactions == [[(0xA0, False)]]


def test_clock_stretching_is_honoured():
    model = CH7301CModel(stretch_s=40e-6)
    got = []

    async def script(ctx, master, do):
        for step in [(Cmd.START,), (Cmd.WRITE, 0xEC), (Cmd.WRITE, 0x49), (Cmd.WRITE, 0xC0), (Cmd.STOP,)]:
            got.append(await do(*step))

    mon = run_master([model], script)
    assert not any(r["nack"] for r in got)
    assert model.writes == [(0x49, 0xC0)] and model.stretches == 3
    assert mon.maximum["tLOW"] >= 40e-6 - 1e-9              # the target's stretch is on the bus
    assert mon.violations(require_all=False) == []           # high time still counted from SCL actually high


def test_scl_held_low_times_out():
    got = []

    async def script(ctx, master, do):
        got.append(await do(Cmd.START))

    run_master([CH7301CModel(hold_scl_low=True)], script)
    r = got[0]
    assert r["timeout"] == 1 and r["active"] == 0 and r["scl_oe"] == 0 and r["sda_oe"] == 0
    assert TIMEOUT_US <= r["cycles"] * 1e6 / CLK < TIMEOUT_US + 20


def test_sda_held_low_forever_times_out_after_bus_clear():
    got = []

    async def script(ctx, master, do):
        got.append(await do(Cmd.START))

    mon = run_master([CH7301CModel(hold_sda_low=True)], script)
    assert got[0]["timeout"] == 1 and got[0]["scl_oe"] == 0 and got[0]["sda_oe"] == 0
    assert mon.scl_rises == 9                                 # UM10204 3.1.16: nine clock pulses, then give up


def test_bus_clear_frees_a_stuck_target():
    model = CH7301CModel(hold_sda_pulses=4)                   # stuck mid-read: releases SDA after 4 clocks
    got = []

    async def script(ctx, master, do):
        for step in [(Cmd.START,), (Cmd.WRITE, 0xEC), (Cmd.WRITE, 0x36), (Cmd.WRITE, 0xA0), (Cmd.STOP,)]:
            got.append(await do(*step))

    mon = run_master([model], script)
    assert not any(r["timeout"] or r["nack"] or r["arb"] for r in got)
    assert model.writes == [(0x36, 0xA0)]
    assert mon.scl_rises == 4 + 1 + 3 * 9 + 1                 # clear pulses, its STOP, 3 bytes, STOP


class _Jammer(I2CTarget):
    """ACKs its address and first data byte, then holds SDA low: the master's next 1 bit must fail."""

    def on_write(self, index, byte):
        if index == 0:
            self.hold_sda_low = True
        return True


def test_sda_low_while_sending_a_one_is_arbitration_lost():
    got = []

    async def script(ctx, master, do):
        for step in [(Cmd.START,), (Cmd.WRITE, 0xEC), (Cmd.WRITE, 0x00), (Cmd.WRITE, 0xFF)]:
            got.append(await do(*step))

    run_master([_Jammer(0x76)], script)
    assert got[3]["arb"] == 1 and got[3]["active"] == 0 and got[3]["scl_oe"] == 0 and got[3]["sda_oe"] == 0


@pytest.mark.parametrize("bus_hz", [100_000, 400_000])
def test_derived_intervals_meet_um10204_at_100mhz(bus_hz):
    t = I2CTiming(100_000_000, bus_hz)
    spec = UM10204_US[bus_hz]
    us = lambda c: c / 100.0   # noqa: E731  (100 cycles per microsecond)
    assert us(t.low) >= spec["low"] and us(t.high) >= spec["high"]
    assert us(t.su_sta) >= spec["su_sta"] and us(t.hd_sta) >= spec["hd_sta"]
    assert us(t.su_sto) >= spec["su_sto"] and us(t.buf) >= spec["buf"]
    assert 0 < us(t.hold) <= spec["vd_dat"] and us(t.low - t.hold) >= spec["su_dat"]
    assert 100_000_000 / (t.low + t.high) <= bus_hz           # before the synchroniser adds its 2-3 cycles


def test_impossible_rates_are_refused():
    with pytest.raises(ValueError):
        I2CTiming(1_000_000, 400_000)                         # 1 us resolution cannot meet fast-mode tVD;DAT
    with pytest.raises(ValueError):
        I2CTiming(100_000_000, 3_400_000)                     # high-speed mode is not supported
    with pytest.raises(ValueError):
        I2CMaster(clk_hz=1_000_000, timeout_us=1)
