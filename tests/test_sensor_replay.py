"""SensorReplay (sim/replay/sensor.py) and the Amaranth replay route's gated clocks (sim/testbench/system/rom_testbench.py).

The replay's pins are sampled at every rising edge of its PCLK domain and compared with the sensor model's stream
(the arrays ``sim.models.mt9d112.sensor.MT9D112.frame`` returns, not the packed ROM words), across the wrap to sample 0.
"""

import numpy as np
import pytest

from amaranth import ClockDomain, Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out
from amaranth.sim import Simulator

from spec.sensor import SMALL_SENSOR
from sim.models.mt9d112.sensor import MT9D112, SMALL_SENSOR_TIMING, SensorStream
from sim.models.mt9d112.config import SensorConfig
from sim.replay.sensor import SensorReplay, pack_stream


def _small_stream(seed=0):
    cfg = SensorConfig(width=SMALL_SENSOR.width, height=SMALL_SENSOR.height, rgb565=True, r_byte_first=True)
    rng = np.random.default_rng(7)
    image = rng.integers(0, 256, size=(SMALL_SENSOR.height, SMALL_SENSOR.width, 3), dtype=np.uint8)
    return MT9D112(cfg, timing=SMALL_SENSOR_TIMING, seed=seed).frame(image)


def test_pack_stream_packs_fv_lv_data():
    stream = SensorStream(np.array([0, 1, 1], np.uint8), np.array([0, 0, 1], np.uint8),
                          np.array([0x12, 0xFF, 0x00], np.uint8))
    assert pack_stream(stream).tolist() == [0x012, 0x2FF, 0x300]
    with pytest.raises(ValueError, match="pauses"):
        pack_stream(SensorStream(stream.fv, stream.lv, stream.data, {1: 1e-6}))


@pytest.mark.parametrize("words, message", [([], "at least one"), ([0, 1024], "10 bits"), ([-1], "10 bits")])
def test_replay_rejects_bad_roms(words, message):
    with pytest.raises(ValueError, match=message):
        SensorReplay(words, domain="sync")


def test_replay_puts_the_model_stream_on_the_pins_and_wraps():
    stream = _small_stream()
    n = len(stream)
    assert stream.fv.any() and stream.lv.any() and n > 1000
    m = Module()
    m.domains.pclk = ClockDomain()
    m.submodules.replay = replay = SensorReplay(pack_stream(stream).tolist(), domain="pclk")
    pins = replay.pins
    want = list(zip(stream.fv.tolist(), stream.lv.tolist(), stream.data.tolist()))
    extra = 50
    got, idle = [], []

    async def bench(ctx):
        for _ in range(3):                          # not running: pins 0, index held at 0
            await ctx.tick("pclk")
            idle.append((ctx.get(pins.fv), ctx.get(pins.lv), ctx.get(pins.data), ctx.get(replay.index)))
        ctx.set(replay.run, 1)
        for _ in range(n + extra):
            await ctx.tick("pclk")
            got.append((ctx.get(pins.fv), ctx.get(pins.lv), ctx.get(pins.data)))
        ctx.set(replay.run, 0)
        await ctx.tick("pclk")
        idle.append((ctx.get(pins.fv), ctx.get(pins.lv), ctx.get(pins.data), ctx.get(replay.index)))

    sim = Simulator(m)
    sim.add_clock(1e-8, domain="pclk")
    sim.add_testbench(bench)
    sim.run()
    assert idle == [(0, 0, 0, 0)] * 4
    assert got[:n] == want
    assert got[n:] == want[:extra]                  # the same frame period again from sample 0


def test_gated_clock_runs_its_domain_only_while_enabled():
    """RomReplayTestbench's clock gate: a counter in the gated domain stands still while the gate is closed and
    counts one per free-clock period while it is open; enable_clock opens and closes it while the free clock is
    low, so no pulse is lost or cut short (the counts are exact)."""
    from sim.testbench.system.rom_testbench import ClockGate, enable_clock

    class Bench(wiring.Component):
        count: Out(16)
        clock_en: In(wiring.Signature({"cam_a": Out(1)}))

        def __init__(self):
            super().__init__()
            self.free_domains = {"cam_a": ClockDomain("free_cam_a", reset_less=True)}

        def elaborate(self, platform):
            m = Module()
            cam = ClockDomain("cam_a", reset_less=True)
            m.domains += [self.free_domains["cam_a"], cam]
            m.submodules.gate = gate = ClockGate("free_cam_a", cam.clk)
            m.d.comb += gate.en.eq(self.clock_en.cam_a)
            m.d.cam_a += self.count.eq(self.count + 1)
            return m

    dut = Bench()
    counts = []

    async def bench(ctx):
        await ctx.delay(1.007e-6)                    # the gate closed; the free clock is high here
        counts.append(ctx.get(dut.count))
        await enable_clock(ctx, dut, "cam_a")
        await ctx.delay(1e-6)                        # 100 periods open
        counts.append(ctx.get(dut.count))
        await enable_clock(ctx, dut, "cam_a", on=False)
        await ctx.delay(1e-6)
        counts.append(ctx.get(dut.count))

    sim = Simulator(dut)
    sim.add_clock(1e-8, domain=dut.free_domains["cam_a"])
    sim.add_testbench(bench)
    sim.run()
    assert counts == [0, 100, 100]
