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


def run(config, images, maps, *, frame_clocks=500, grant_mask=0, abandon_at=None, tail_frames=2, pace=1):
    """Run the maps ``maps`` (pair indices, in order) on the bench; the map ``abandon_at`` = (i, rows): map i is
    started again (on the next map's pair) once ``rows`` of its rows are ready. A display frame every
    ``frame_clocks`` pix clocks reads every row it gets. Returns (events, shown): events in simulated order,
    ("published", pair) and ("take", frame); shown[frame] the codes the frame read (None: no row)."""
    bench = MapStoreBench(G, config, images, pace=pace)
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
    """Two maps of two pairs, each spanning several display frames (the engine's reads stalled): the frames show
    nothing before the first, then always the latest whole map."""
    images = pairs((1, 2))
    events, shown = run(SMALL_DEPTH, images, [0, 1], frame_clocks=700, grant_mask=0x03)
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
    events, shown = run(config, images, [0, 1, 0, 1], abandon_at=(1, H // 2), frame_clocks=600)
    seen = check(config, images, events, shown)
    assert seen[-1] == 1
    published_at = [i for i, e in enumerate(events) if e[0] == "published"]
    assert len(published_at) == 3
