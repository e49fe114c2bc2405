"""The whole frame store (two camera writers, the ownership, two display streams, the arbiter) against the MIG model
(sim/models/mig, its protocol checker stopping the run on any violation): a display frame reads the pair it took,
whole, while the cameras write the next frames -- no tear -- and the next take reads the newer pair."""

import numpy as np
import pytest
from amaranth import ClockDomain, DomainRenamer, Module
from amaranth.lib import wiring
from amaranth.sim import Simulator

from frame_store_on_model import read_row, take_pair
from frame_store_sources import Camera
from hdl.frame_store.frame_store import FrameStore
from hdl.frame_store.layout import FrameStoreLayout
from sim.models.mig import MIGModel, layout_window, watch_violations
from spec.memory import MIG
from spec.sensor import SMALL_SENSOR

LAYOUT = FrameStoreLayout(width=40, height=5, base=1024)
SLOTS = 2


def images(seed):
    rng = np.random.default_rng(seed)
    return [rng.integers(0, 32, (LAYOUT.height, LAYOUT.width), dtype=np.uint8) for _ in range(2)]


def design():
    m = Module()
    m.domains += [ClockDomain(d) for d in ("pix", "mem", "cam_a", "cam_b")]
    m.submodules.store = store = FrameStore(LAYOUT, SMALL_SENSOR, slots=SLOTS, read_depth=16)
    mig = MIGModel(af_depth=32, wdf_depth=32, **layout_window(LAYOUT),
                   init_clocks=40)
    m.submodules.mig = DomainRenamer("mem")(mig)
    wiring.connect(m, store.mig, mig.user)
    return m, store, mig


async def read_pair(ctx, store, asked, pause=None):
    """Take the latest pair, then fetch and read every row of both streams; the two images read. ``asked``: rows
    asked for so far per stream (the n-th lands in slot n mod SLOTS), updated. ``pause``: awaited after the first
    stream's second row."""
    await take_pair(ctx, store)
    out = []
    for i, stream in enumerate(store.streams):
        rows = []
        for y in range(LAYOUT.height):
            rows.append(await read_row(ctx, stream, y, asked[i] % SLOTS, LAYOUT.width))
            asked[i] += 1
            if pause is not None and (i, y) == (0, 1):
                await pause()
        out.append(np.array(rows, np.uint8))
    return out


def test_a_held_pair_is_read_whole_while_the_cameras_write():
    m, store, mig = design()
    pairs = [images(k) for k in range(3)]       # frame k of both cameras
    cameras_done, frames_written = [], []
    reads = {}

    def camera(c, domain):
        async def run(ctx):
            cam = Camera(ctx, store.cameras[c], domain)
            await ctx.tick(domain).repeat(60)
            for k, pair in enumerate(pairs):
                await cam.frame(pair[c])
                frames_written.append((c, k))
                await ctx.tick(domain).repeat(200)
                cameras_done.append((c, k))
        return run

    async def display(ctx):
        asked = [0, 0]
        reads["empty"] = await read_pair(ctx, store, asked)
        while (1, 0) not in frames_written:                                 # frame 0 of camera B ends
            await ctx.tick("pix")
        await ctx.tick("pix").repeat(300)

        async def frames_1_and_2_written():
            while len(cameras_done) < 6:
                await ctx.tick("pix")
        # Pair 0 held while frames 1 and 2 are written (frame 1 becomes the latest pair, frame 2 needs a buffer).
        reads[0] = await read_pair(ctx, store, asked, pause=frames_1_and_2_written)
        reads[2] = await read_pair(ctx, store, asked)

    sim = Simulator(m)
    sim.add_clock(6.7e-9, domain="pix")
    sim.add_clock(8e-9, domain="mem")
    sim.add_clock(12.5e-9, domain="cam_a")
    sim.add_clock(12.1e-9, domain="cam_b")
    sim.add_testbench(camera(0, "cam_a"), background=True)
    sim.add_testbench(camera(1, "cam_b"), background=True)
    sim.add_testbench(watch_violations(mig), background=True)

    async def latency(ctx):
        ctx.set(mig.latency, 20)
    sim.add_testbench(latency)
    sim.add_testbench(display)
    sim.run()
    assert all((image == 0).all() for image in reads["empty"])
    for k in (0, 2):
        for c in range(2):
            assert (reads[k][c] == pairs[k][c]).all(), f"pair {k}, camera {c}"


def simulate_cameras(frames, delays, reads_after, writes=None):
    """Both cameras send ``frames[c]`` (``(image, kwargs)`` each) starting ``delays[c]`` camera clocks late; once
    every frame is sent, the display takes a pair and reads it. ``writes``: a list that gets the address of every
    write command the store gives MIG."""
    m, store, mig = design()
    sent, out = [], {}

    async def commands(ctx):
        command = store.mig.command
        async for _, _, wren, cmd, addr in ctx.tick("mem").sample(command.wren, command.cmd, command.addr):
            if wren and cmd == MIG.CMD_WRITE and writes is not None:
                writes.append(addr)

    def camera(c, domain):
        async def run(ctx):
            cam = Camera(ctx, store.cameras[c], domain)
            await ctx.tick(domain).repeat(delays[c])
            for image, kwargs in frames[c]:
                await cam.frame(image, **kwargs)
                await ctx.tick(domain).repeat(200)
            sent.append(c)
        return run

    async def display(ctx):
        while len(sent) < 2:
            await ctx.tick("pix")
        await ctx.tick("pix").repeat(reads_after)
        out["pair"] = await read_pair(ctx, store, [0, 0])

    async def latency(ctx):
        ctx.set(mig.latency, 24)

    sim = Simulator(m)
    sim.add_clock(6.7e-9, domain="pix")
    sim.add_clock(8e-9, domain="mem")
    sim.add_clock(12.5e-9, domain="cam_a")
    sim.add_clock(12.5e-9, domain="cam_b")
    for c, domain in enumerate(("cam_a", "cam_b")):
        sim.add_testbench(camera(c, domain), background=True)
    sim.add_testbench(watch_violations(mig), background=True)
    sim.add_testbench(commands, background=True)
    sim.add_testbench(latency)
    sim.add_testbench(display)
    sim.run()
    return out["pair"]


def test_a_dropped_frame_does_not_shift_the_pairs():
    """Camera A (starting, and so finishing, a little before B) breaks its frame 1: frame 2 of A must be paired
    with frame 2 of B, not with B's frame 1 that was waiting for a partner."""
    pairs = [images(10 + k) for k in range(3)]
    a = [(pairs[0][0], {}), (pairs[1][0][:-1], {}), (pairs[2][0], {})]      # frame 1 of A a row short
    b = [(pair[1], {}) for pair in pairs]
    left, right = simulate_cameras([a, b], delays=[10, 40], reads_after=100)
    assert (left == pairs[2][0]).all() and (right == pairs[2][1]).all()


def test_a_camera_with_bad_frames_never_leaves_a_reader_a_half_written_buffer():
    """After a good pair, camera A sends a frame of short lines (38 of 40 pixels: only its last burst short, every
    burst there), then half a frame and stops; camera B sends good frames all along. Either of A's bad frames
    published would pair with B's frame of its number; the display must read pair 0, whole, and every write must
    lie inside a buffer. (A frame a line short: the dropped-frame test above.)"""
    pairs = [images(20 + k) for k in range(3)]
    a = [(pairs[0][0], {}), (pairs[1][0][:, :38], {}), (pairs[2][0][:2], {"done": False})]
    b = [(pair[1], {}) for pair in pairs]
    writes = []
    left, right = simulate_cameras([a, b], delays=[10, 40], reads_after=100, writes=writes)
    assert (left == pairs[0][0]).all() and (right == pairs[0][1]).all()
    assert writes and all(LAYOUT.buffer_of(w) is not None and LAYOUT.buffer_of(w + 3) == LAYOUT.buffer_of(w)
                          for w in writes)
