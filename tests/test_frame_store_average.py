"""The averaging capture into the DDR2 frame store: the MT9D112 model's frames through the capture path built with
``downscale="average"`` (8-bit grey, hdl/averaging_downscaler.py), its write port and status into the
``FrameStore``'s camera writer, MIG's model behind the arbiter (its protocol checker stopping the run on any
violation); the display side takes the pair and reads every row back. The frame read is the golden averaging
capture of the last frame sent (golden.capture.capture_frame), all 8 bits of every pixel."""

import numpy as np
from amaranth import ClockDomain, DomainRenamer, Module
from amaranth.lib import wiring
from amaranth.sim import Simulator

from frame_store_on_model import read_row, take_pair
from golden.capture import capture_frame
from hdl.capture_path import CapturePath
from hdl.frame_store.frame_store import FrameStore
from hdl.frame_store.layout import FrameStoreLayout
from sim.models.mig import MIGModel, layout_window, watch_violations
from sim.models.mt9d112.config import SensorConfig
from sim.models.mt9d112.sensor import MT9D112, SensorTiming, drive_amaranth
from spec.memory import MIG
from spec.sensor import SensorGeometry

GEOMETRY = SensorGeometry(width=80, height=10, scale=2, grey_bits=8, downscale="average")      # 40 x 5 pixels
LAYOUT = FrameStoreLayout(width=GEOMETRY.buf_width, height=GEOMETRY.buf_height, cameras=1, buffers=3, base=1024)
TIMING = SensorTiming(h_blank=4, v_blank_lines=1, frame_start=2, frame_end=3)
PCLK_HZ = 80e6


def run(images):
    """``images`` through camera a's averaging capture into the store; the frame the display reads after them."""
    m = Module()
    cam = ClockDomain("cam_a")
    m.domains += [cam, ClockDomain("pix"), ClockDomain("mem")]
    m.submodules.capture = capture = CapturePath(GEOMETRY, cameras=("a",), buffers=False)
    m.submodules.store = store = FrameStore(LAYOUT, GEOMETRY, streams=((0, True),), slots=2, cam_domains=("cam_a",),
                                            read_depth=16)
    mig = MIGModel(af_depth=32, wdf_depth=32, **layout_window(LAYOUT), init_clocks=40)
    m.submodules.mig = DomainRenamer("mem")(mig)
    wiring.connect(m, capture.cam_a.write, store.cameras[0].write)
    wiring.connect(m, capture.cam_a.status, store.cameras[0].status)
    wiring.connect(m, store.mig, mig.user)
    stream = MT9D112(SensorConfig(width=GEOMETRY.width, height=GEOMETRY.height), timing=TIMING, seed=1).stream(images)
    sent, out = [], {}

    async def camera(ctx):
        await drive_amaranth(ctx, stream, clk=cam.clk, pins=capture.cam_a.pins, pclk_hz=PCLK_HZ)
        for _ in range(40):                                   # PCLK runs on through the blanking
            ctx.set(cam.clk, 0)
            await ctx.delay(0.5 / PCLK_HZ)
            ctx.set(cam.clk, 1)
            await ctx.delay(0.5 / PCLK_HZ)
        sent.append(1)

    async def display(ctx):
        while not sent:
            await ctx.tick("pix")
        await ctx.tick("pix").repeat(100)
        await take_pair(ctx, store)
        stream = store.streams[0]
        rows = [await read_row(ctx, stream, y, y % 2, LAYOUT.width) for y in range(LAYOUT.height)]
        out["frame"] = np.array(rows)

    async def latency(ctx):
        ctx.set(mig.latency, 20)

    sim = Simulator(m)
    sim.add_clock(6.7e-9, domain="pix")
    sim.add_clock(1 / MIG.CLK0_HZ, domain="mem")
    sim.add_testbench(camera, background=True)
    sim.add_testbench(watch_violations(mig), background=True)
    sim.add_testbench(latency)
    sim.add_testbench(display)
    sim.run()
    return out["frame"]


def test_averaged_frames_go_through_the_store_whole():
    """Two frames (a bright one, then one over the whole range): the display reads the second's golden averaging
    capture, with its values above 31 (all 8 bits of the byte) intact."""
    rng = np.random.default_rng(6)
    bright = rng.integers(128, 256, (GEOMETRY.height, GEOMETRY.width, 3), dtype=np.uint8)
    second = rng.integers(0, 256, (GEOMETRY.height, GEOMETRY.width, 3), dtype=np.uint8)
    second[:2, :8] = 255                                    # a white corner: 255 in the first two pixels
    frame = run([bright, second])
    expected = capture_frame(second, GEOMETRY)
    np.testing.assert_array_equal(frame, expected)
    assert expected.max() == 255 and (expected > 31).mean() > 0.5
