"""The frame store's camera writer (packer, asynchronous FIFO, burst writer) with the buffer ownership, at small size
in Amaranth's simulator: what lands in the memory, and which buffer is published, for well-formed and malformed
camera streams. The expected memory is built from the layout's rules (docs/frame_store.md), not from the RTL."""

import random

import numpy as np
import pytest
from amaranth import ClockDomain, DomainRenamer, Module
from amaranth.lib import wiring
from amaranth.sim import Simulator

from frame_store_sources import Camera
from hdl.frame_store.camera_writer import CameraWriter
from hdl.frame_store.layout import FrameStoreLayout
from hdl.frame_store.ownership import BufferOwnership
from spec.sensor import SMALL_SENSOR

LAYOUT = FrameStoreLayout(width=40, height=5, cameras=1, buffers=3, base=64)


def design(layout=LAYOUT):
    m = Module()
    m.domains.cam_a = ClockDomain()
    m.domains.mem = ClockDomain()
    m.submodules.writer = writer = CameraWriter(layout, 0, SMALL_SENSOR, cam_domain="cam_a", mem_domain="mem")
    own = BufferOwnership(cameras=1, readers=1, buffers=layout.buffers)
    m.submodules.own = DomainRenamer("mem")(own)
    wiring.connect(m, writer.own, own.writers[0])
    return m, writer, own


def run(frames, layout=LAYOUT, grant_rate=0.5, seed=1, take_after=None, masks=None):
    """Simulate the writer on ``frames`` (a list of ``(image, kwargs)``); the memory's bytes (address -> 8 bytes),
    the writes' addresses, the buffer a reader takes after each frame (``None``: no pair). ``masks``: a list the
    writes' byte masks are appended to."""
    m, writer, own = design(layout)
    memory, addresses, taken = {}, [], []
    rng = random.Random(seed)
    done = []

    async def camera(ctx):
        cam = Camera(ctx, writer, "cam_a")
        for image, kwargs in frames:
            await cam.frame(image, **kwargs)
            await ctx.tick("cam_a").repeat(40)
            done.append(len(done))
        await ctx.tick("cam_a").repeat(40)

    async def mem(ctx):
        reader = own.readers[0]
        seen = 0
        while True:
            grant = rng.random() < grant_rate
            ctx.set(writer.mem.grant, 0)
            if ctx.get(writer.mem.request) and grant:
                ctx.set(writer.mem.grant, 1)
                addr, data, mask = ctx.get(writer.mem.addr), ctx.get(writer.mem.data), ctx.get(writer.mem.mask)
                addresses.append(addr)
                if masks is not None:
                    masks.append(mask)
                for word in range(4):
                    old = memory.setdefault(addr + word, [0] * 8)
                    for b in range(8):
                        k = word * 8 + b
                        if not (mask >> k) & 1:
                            old[b] = (data >> (8 * k)) & 0xFF
            if len(done) > seen:
                seen = len(done)
                ctx.set(reader.take, 1)
                await ctx.tick("mem")
                ctx.set(reader.take, 0)
                await ctx.tick("mem")
                taken.append(ctx.get(reader.buffer[0]) if ctx.get(reader.valid) else None)
                continue
            await ctx.tick("mem")

    sim = Simulator(m)
    sim.add_clock(12.5e-9, domain="cam_a")
    sim.add_clock(8e-9, domain="mem")
    sim.add_testbench(camera)
    sim.add_testbench(mem, background=True)
    sim.run()
    return memory, addresses, taken


def buffer_image(memory, layout, buffer):
    """The buffer's rows as the layout places them (one byte a pixel, ``stride`` bytes apart)."""
    out = np.zeros((layout.height, layout.width), np.uint8)
    for y in range(layout.height):
        for x in range(layout.width):
            address = layout.buffer_base(0, buffer) * 8 + y * layout.stride + x
            out[y, x] = memory.get(address // 8, [0] * 8)[address % 8]
    return out


def image(seed, layout=LAYOUT):
    return np.random.default_rng(seed).integers(1, 32, (layout.height, layout.width), dtype=np.uint8)


def test_frames_land_at_their_rows_and_are_published():
    a, b = image(1), image(2)
    masks = []
    memory, addresses, taken = run([(a, {}), (b, {"gap": 2})], masks=masks)
    assert taken[0] is not None and taken[1] is not None and taken[0] != taken[1]
    assert (buffer_image(memory, LAYOUT, taken[0]) == a).all()
    assert (buffer_image(memory, LAYOUT, taken[1]) == b).all()
    # Every burst written once a frame, burst-aligned, 2 bursts a row (the second masked beyond 40 bytes).
    assert len(addresses) == 2 * LAYOUT.height * LAYOUT.bursts_per_row
    assert all(addr % 4 == 0 for addr in addresses)
    # A row's first burst whole; its second the packer's one word (bytes 32..39) and three words the writer makes,
    # masked.
    assert masks == [0, ~0xFF & 0xFFFFFFFF] * (2 * LAYOUT.height)


def _inside_buffers(addresses, layout=LAYOUT):
    return all(layout.buffer_of(addr) is not None and layout.buffer_of(addr + 3) == layout.buffer_of(addr)
               for addr in addresses)


@pytest.mark.parametrize("case", ["short_frame", "long_line", "not_ok", "no_frame_done", "stops"])
def test_malformed_frame_is_never_published(case):
    good, bad = image(3), image(4)
    if case == "short_frame":
        frames = [(good, {}), (bad[:-2], {})]
    elif case == "long_line":
        frames = [(good, {}), (np.hstack([bad, bad[:, :9]]), {})]
    elif case == "not_ok":
        frames = [(good, {}), (bad, {"ok": False})]
    elif case == "no_frame_done":
        frames = [(good, {}), (bad, {"done": False}), (image(5)[:-1], {})]
    else:
        frames = [(good, {}), (bad[:2], {"done": False})]
    memory, addresses, taken = run(frames)
    assert _inside_buffers(addresses)
    first = taken[0]
    assert (buffer_image(memory, LAYOUT, first) == good).all()
    assert all(t == first for t in taken), f"a malformed frame was published: {taken}"
    assert (buffer_image(memory, LAYOUT, first) == good).all(), "the published buffer was written over"


def test_writer_skips_the_held_buffer():
    """Four frames, the reader taking the latest after each: each frame goes to a buffer other than the one the
    reader holds while it is written, and the held frame stays intact."""
    images = [image(10 + i) for i in range(4)]
    memory, addresses, taken = run([(im, {}) for im in images], grant_rate=1.0)
    assert None not in taken
    assert all(taken[k] != taken[k - 1] for k in range(1, 4))
    assert (buffer_image(memory, LAYOUT, taken[3]) == images[3]).all()
    assert (buffer_image(memory, LAYOUT, taken[2]) == images[2]).all()
    assert _inside_buffers(addresses)
