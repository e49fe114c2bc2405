"""The frame store's camera writer behind the real capture (hdl/capture.py), fed by the MT9D112 model's streams
with the robustness tests' faults (sim.models.mt9d112.sensor.fault_cases): a frame is published exactly when the
golden capture model (golden/capture.py, written from the spec) calls it whole, with its pixels; every write stays
inside the buffers; a faulty frame leaves the previous pair held."""

import numpy as np
import pytest
from amaranth import ClockDomain, DomainRenamer, Module
from amaranth.lib import wiring
from amaranth.sim import Simulator

from golden.capture import capture_frame, capture_stream
from hdl.capture import CameraCapture
from hdl.frame_store.camera_writer import CameraWriter
from hdl.frame_store.layout import FrameStoreLayout
from hdl.frame_store.ownership import BufferOwnership
from sim.models.mt9d112.config import SensorConfig
from sim.models.mt9d112.sensor import MT9D112, SensorTiming, drive_amaranth, fault_cases
from spec.sensor import SensorGeometry

GEOMETRY = SensorGeometry(width=64, height=8)            # 16 x 2 buffer pixels
TIMING = SensorTiming(h_blank=4, v_blank_lines=1, frame_start=2, frame_end=3)
CONFIG = SensorConfig(width=GEOMETRY.width, height=GEOMETRY.height)
LAYOUT = FrameStoreLayout(width=GEOMETRY.buf_width, height=GEOMETRY.buf_height, cameras=1, buffers=3, base=32)
PCLK_HZ = 80e6


def run(stream):
    """The stream through capture -> writer (+ ownership); the memory's bytes, the write addresses, and the frame
    a reader takes at the end (``None``: no complete frame)."""
    m = Module()
    cam, mem = ClockDomain("cam_a"), ClockDomain("mem")
    m.domains += [cam, mem]
    capture = CameraCapture(GEOMETRY)
    m.submodules.capture = DomainRenamer("cam_a")(capture)
    m.submodules.writer = writer = CameraWriter(LAYOUT, 0, GEOMETRY, cam_domain="cam_a", mem_domain="mem")
    own = BufferOwnership(cameras=1, readers=1, buffers=LAYOUT.buffers)
    m.submodules.own = DomainRenamer("mem")(own)
    wiring.connect(m, capture.write, writer.write)
    wiring.connect(m, capture.status, writer.status)
    wiring.connect(m, writer.own, own.writers[0])
    memory, addresses, held = {}, [], {}
    done = []

    async def camera(ctx):
        await drive_amaranth(ctx, stream, clk=cam.clk, pins=capture.pins, pclk_hz=PCLK_HZ)
        for _ in range(40):                                   # PCLK keeps running in the blanking
            ctx.set(cam.clk, 0)
            await ctx.delay(0.5 / PCLK_HZ)
            ctx.set(cam.clk, 1)
            await ctx.delay(0.5 / PCLK_HZ)
        done.append(1)

    async def grants(ctx):
        reader = own.readers[0]
        while not done:
            ctx.set(writer.mem.grant, 0)
            if ctx.get(writer.mem.request):
                ctx.set(writer.mem.grant, 1)
                addr, data, mask = ctx.get(writer.mem.addr), ctx.get(writer.mem.data), ctx.get(writer.mem.mask)
                addresses.append(addr)
                for k in range(32):
                    if not (mask >> k) & 1:
                        memory[addr * 8 + k] = (data >> (8 * k)) & 0xFF
            await ctx.tick("mem")
        await ctx.tick("mem").repeat(30)
        ctx.set(reader.take, 1)
        await ctx.tick("mem")
        ctx.set(reader.take, 0)
        await ctx.tick("mem")
        held["buffer"] = ctx.get(reader.buffer[0]) if ctx.get(reader.valid) else None

    sim = Simulator(m)
    sim.add_clock(8e-9, domain="mem")
    sim.add_testbench(camera)
    sim.add_testbench(grants)
    sim.run()
    image = None
    if held["buffer"] is not None:
        base = LAYOUT.buffer_base(0, held["buffer"]) * 8
        image = np.array([[memory.get(base + y * LAYOUT.stride + x, -1) for x in range(LAYOUT.width)]
                          for y in range(LAYOUT.height)])
    return image, addresses


def pictures(seed):
    rng = np.random.default_rng(seed)
    return [rng.integers(0, 256, (GEOMETRY.height, GEOMETRY.width, 3), dtype=np.uint8) for _ in range(2)]


@pytest.mark.parametrize("case", list(fault_cases(GEOMETRY.width, GEOMETRY.height)))
def test_a_frame_is_published_exactly_when_it_is_whole(case):
    first, second = pictures(1)
    faults = fault_cases(GEOMETRY.width, GEOMETRY.height)[case]
    stream = MT9D112(CONFIG, timing=TIMING, seed=4).stream([first, second], faults=[None, faults])
    gold = capture_stream(stream.fv, stream.lv, stream.data, GEOMETRY)
    image, addresses = run(stream)
    assert all(LAYOUT.buffer_of(a) == LAYOUT.buffer_of(a + 3) == (0, LAYOUT.buffer_of(a)[1]) for a in addresses)
    whole = [f.ok for f in gold.frames]
    if whole[-1]:                       # the faulty frame is whole after all (the capture ignores its fault)
        np.testing.assert_array_equal(image, gold.buffer)
    elif len(whole) == 2 and whole[0]:  # the good frame stays published
        np.testing.assert_array_equal(image, capture_frame(first, GEOMETRY))
    else:                               # one frame, not whole (a reset mid-frame merges the two)
        assert image is None
