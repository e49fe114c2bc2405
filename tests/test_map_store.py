"""The depth maps in the frame store (docs/frame_store.md, "Depth maps in the store"): the depth engine's maps drained
by ``MapWriter`` into the store's map buffers on the MIG model, and read back through ``MapWindow`` as the compositor
reads the engine's ring (``sim/testbench/map_store.py``), small size, Amaranth's simulator.

Every display frame shows one whole golden map (``golden.depth.depth_map``) or, before the first, no row: the latest
map published before the frame's take; an abandoned map (the engine started again before its end) is never shown;
a map longer than several display frames leaves the frames meanwhile on the last whole one.
"""

import numpy as np
import pytest
from amaranth.sim import Simulator

from golden.depth import depth_map
from sim.models.mig import watch_violations
from hdl.map_window import MapWindow
from sim.testbench.map_store import MapStoreBench
from spec.depth import SMALL_DEPTH
from spec.memory import MIG
from spec.sensor import SMALL_SENSOR
from dataclasses import replace

G = SMALL_SENSOR
W, H = G.buf_width, G.buf_height
PUBLISH = 80            # pix clocks from the writer's end to the map held by a take, at most


def pairs(seeds):
    out = []
    for seed in seeds:
        rng = np.random.default_rng(seed)
        out.append((rng.integers(0, 32, (H, W)), rng.integers(0, 32, (H, W))))
    return out


def run(config, images, maps, *, frame_clocks=500, grant_mask=0, abandon_at=None, tail_frames=2, pace=1,
        init_clocks=20):
    """Run the maps ``maps`` (pair indices, in order) on the bench; the map ``abandon_at`` = (i, rows): map i is
    started again (on the next map's pair) once ``rows`` of its rows are ready. A display frame every
    ``frame_clocks`` pix clocks reads every row it gets. Returns (events, shown): events in simulated order,
    ("published", pair) and ("take", frame); shown[frame] the codes the frame read (None: no row)."""
    bench = MapStoreBench(G, config, images, pace=pace, init_clocks=init_clocks)
    window, events, shown, state = bench.window, [], [], {"done": False}

    async def control(ctx):
        ctx.set(bench.model.latency, 20)
        ctx.set(bench.grant_mask, grant_mask)
        await ctx.tick("pix").repeat(40)
        for i, p in enumerate(maps):
            ctx.set(bench.pair, p)
            ctx.set(bench.start, 1)
            await ctx.tick("pix")
            ctx.set(bench.start, 0)
            if abandon_at is not None and abandon_at[0] == i:
                await ctx.tick("pix").until(bench.engine.result.rows_ready >= abandon_at[1])
                continue
            await ctx.tick("pix").until(bench.writer.busy == 0)
            await ctx.tick("pix").repeat(PUBLISH)
            events.append(("published", p))
        state["done"] = True

    async def display(ctx):
        frame, tail = 0, 0
        while tail < tail_frames:
            tail += state["done"]
            events.append(("take", frame))
            ctx.set(window.take, 1)
            await ctx.tick("pix")
            ctx.set(window.take, 0)
            await ctx.tick("pix").until(window.taken)
            spent, codes = 0, np.zeros((H, W), int)
            ctx.set(window.result.rows_released, 0)
            for r in range(H):
                waited = 0
                while ctx.get(window.result.rows_ready) <= r and waited < 120:
                    await ctx.tick("pix")
                    waited += 1
                spent += waited
                if ctx.get(window.result.rows_ready) <= r:
                    assert r == 0, f"frame {frame}: row {r} never landed"
                    codes = None
                    break
                for x in range(W):
                    ctx.set(window.result.addr, (r % 4) * W + x)
                    await ctx.tick("pix")
                    codes[r, x] = ctx.get(window.result.data)
                ctx.set(window.result.rows_released, r + 1)
                spent += W
            shown.append(codes)
            await ctx.tick("pix").repeat(max(1, frame_clocks - spent - W * H))
            frame += 1

    sim = Simulator(bench.m)
    sim.add_clock(6.7e-9, domain="pix")
    sim.add_clock(1 / MIG.CLK0_HZ, domain="mem")
    sim.add_testbench(watch_violations(bench.model), background=True)
    sim.add_testbench(control)
    sim.add_testbench(display)
    sim.run()
    return events, shown


def expected_per_frame(events):
    """Per frame, the pairs whose map may be shown: the last published before its take (None before the first), or
    the one published just after (the take raced its publication)."""
    latest, out = None, {}
    for i, e in enumerate(events):
        if e[0] == "published":
            latest = e[1]
        else:
            after = next((f[1] for f in events[i + 1:] if f[0] == "published"), None)
            out[e[1]] = {latest, after}
    return out


def check(config, images, events, shown):
    goldens = [depth_map(left, right, config) for left, right in images]
    expected = expected_per_frame(events)
    seen = []
    for frame, codes in enumerate(shown):
        if codes is None:
            which = None
        else:
            which = next((k for k, gold in enumerate(goldens) if np.array_equal(codes, gold)), "torn")
        assert which != "torn", f"frame {frame} shows no whole golden map"
        assert which in expected[frame], f"frame {frame} shows map {which}, expected one of {expected[frame]}"
        seen.append(which)
    return seen


def test_maps_through_the_store_whole_and_the_latest_shown():
    """Two maps of two pairs, each spanning several display frames (a writer slower than the engine: the engine
    waits for room in its ring, so a row released early would be overwritten before it is written), the memory
    ready only after the first map is computed (the writer waits for room in the store's 8-entry FIFO: a burst lost
    would leave the map unpublished): the frames show nothing before the first, then always the latest whole map."""
    images = pairs((1, 2))
    events, shown = run(SMALL_DEPTH, images, [0, 1], frame_clocks=700, grant_mask=0x01, pace=24, init_clocks=3200)
    seen = check(SMALL_DEPTH, images, events, shown)
    assert seen[0] is None and seen[-1] == 1 and 0 in seen
    assert seen.count(0) >= 2, f"a map should span several display frames: {seen}"


@pytest.mark.slow
def test_an_abandoned_map_is_never_shown_and_two_byte_codes():
    """Map 0 of pair 0; map 1 of pair 1 abandoned halfway (the engine started again on pair 0); map 2 of pair 1 with
    codes of 9 bits (two bytes a code in the store)."""
    config = replace(SMALL_DEPTH, fraction_bits=5)
    assert config.code_bits == 9
    images = pairs((3, 4))
    events, shown = run(config, images, [0, 1, 0, 1], abandon_at=(1, H // 2), frame_clocks=600, grant_mask=0x03)
    seen = check(config, images, events, shown)
    assert seen[-1] == 1
    published_at = [i for i, e in enumerate(events) if e[0] == "published"]
    assert len(published_at) == 3


def test_the_layout_puts_the_maps_after_the_cameras_buffers_in_every_bank():
    """Three map buffers of two-byte codes over banks 0, 1, 2, from the first word after the cameras' buffers;
    the memory model's window covers them; ``buffer_of`` names a map buffer ``(cameras, b)``."""
    from hdl.frame_store.layout import FrameStoreLayout
    lay = FrameStoreLayout(width=40, height=6, base=64, maps=3, map_bits=9)
    maps = lay.map_layout
    assert (maps.cameras, maps.buffers, maps.pixel_bytes, maps.bursts_per_row, maps.stride) == (1, 3, 2, 3, 96)
    assert [maps.bank_of(0, b) for b in range(3)] == [0, 1, 2]
    cameras_words = 2 * lay.buffer_words                 # banks 0 and 2 hold two camera buffers each
    assert maps.base == lay.base + cameras_words
    assert lay.bank_words == cameras_words + maps.buffer_words
    for b in range(3):
        first = maps.buffer_base(0, b)
        assert lay.buffer_of(first) == (2, b) and lay.buffer_of(first + maps.buffer_words - 1) == (2, b)
        assert all(lay.buffer_base(c, k) + lay.buffer_words <= first or lay.buffer_base(c, k) >= first
                   + maps.buffer_words for c in range(2) for k in range(3))
    assert FrameStoreLayout(width=40, height=6).map_layout is None


def test_the_pair_is_taken_only_when_the_engine_and_the_writer_are_idle():
    """``maps="store"``: the display takes the camera pair at a display frame's start only when the last map is
    whole, so a map spanning several display frames reads one pair; it takes the latest whole map at every display
    frame's start. Here no row ever lands, so the first map never ends: the first frame takes the pair and starts
    the engine, the next two do not take it (their map takes still come)."""
    from spec.video import SMALL_TIMING
    from hdl.stereo_display import StereoDisplay
    dut = StereoDisplay(SMALL_TIMING, G, config=SMALL_DEPTH, memory="ddr2", maps="store")
    seen = {"take": [], "map_take": [], "busy": []}

    async def bench(ctx):
        ctx.set(dut.timing.y, SMALL_TIMING.v_active)          # vertical blanking: the compositor reads nothing
        for stream in (*dut.streams, dut.map_stream):
            ctx.set(stream.fetch.rdy, 1)
        await ctx.tick().repeat(4)
        for _ in range(3):
            ctx.set(dut.timing.frame_start, 1)
            seen["take"].append(ctx.get(dut.take))
            seen["map_take"].append(ctx.get(dut.map_take))
            await ctx.tick()
            ctx.set(dut.timing.frame_start, 0)
            await ctx.tick().repeat(6)
            answers = (dut.taken, dut.map_taken) if seen["take"][-1] else (dut.map_taken,)
            for port in answers:
                ctx.set(port, 1)
            await ctx.tick()
            for port in answers:
                ctx.set(port, 0)
            await ctx.tick().repeat(300)
            seen["busy"].append(ctx.get(dut.map_writer.busy))

    sim = Simulator(dut)
    sim.add_clock(6.7e-9)
    sim.add_testbench(bench)
    sim.run()
    assert seen == {"take": [1, 0, 0], "map_take": [1, 1, 1], "busy": [1, 1, 1]}


def test_the_map_window_maps_a_ring_address_to_its_slot_and_column():
    """``MapWindow``: ring address ``k W + x`` reads column ``x`` of slot ``first + k`` (mod the slots), ``first`` the
    stream's slot of the map's row 0 -- with rows 12 codes wide (not a power of two: a column taken from the
    address's low bits would be wrong) and maps of 2 rows, so the second map's row 0 is in slot 2."""
    from spec.sensor import SensorGeometry
    g = SensorGeometry(width=48, height=8, scale=4)
    w, h = g.buf_width, g.buf_height
    dut = MapWindow(g, 8, slots=4)
    seen = []

    async def bench(ctx):
        ctx.set(dut.stream.fetch.rdy, 1)
        for first in (0, h):
            ctx.set(dut.take, 1)
            await ctx.tick()
            ctx.set(dut.take, 0)
            ctx.set(dut.taken, 1)
            await ctx.tick()
            ctx.set(dut.taken, 0)
            for addr in range(4 * w):
                ctx.set(dut.result.addr, addr)
                seen.append((first, addr, ctx.get(dut.stream.read.slot), ctx.get(dut.stream.read.x)))
            await ctx.tick().repeat(12)                     # the map's rows asked for

    sim = Simulator(dut)
    sim.add_clock(6.7e-9)
    sim.add_testbench(bench)
    sim.run()
    assert len(seen) == 2 * 4 * w
    for first, addr, slot, x in seen:
        assert (slot, x) == ((first + addr // w) % 4, addr % w), (first, addr, slot, x)
