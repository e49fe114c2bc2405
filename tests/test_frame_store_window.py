# amaranth: UnusedElaboratable=no
"""A frame buffer's read port served from a frame-store stream (RowWindow on a RowReader, behind the arbiter and the
MIG model of sim/models/mig, its checker stopping the run on any violation): the bytes a consumer reads are the image's -- what the block-RAM
frame buffer would give at the same addresses -- for the display's pattern (each row on several lines, never
refused) and the depth engine's (a clamped row offset, waiting for its grants)."""

import numpy as np
import pytest
from amaranth import DomainRenamer
from amaranth.lib import wiring

from frame_store_on_model import ReaderOnModel, fill
from hdl.frame_store.layout import FrameStoreLayout
from hdl.frame_store.row_window import RowWindow
from spec.sensor import SensorGeometry

#: 20 x 10 buffer pixels: a row is not a power of two of bytes, nor a whole number of 16-byte words.
G = SensorGeometry(width=80, height=40)
#: 4 x 40 buffer pixels: more rows than the window's request and landing counters count before they wrap.
TALL = SensorGeometry(width=16, height=160)
SLOTS = 3
#: Pix clocks a read waits for its grant at most (a row lands in tens of clocks).
GRANT_TIMEOUT = 2000


def simulate(consumer_bench, *, seed=0, geometry=G, max_step=1):
    """Run ``consumer_bench(ctx, window)`` on a window over the image (random, ``seed``) in camera 0's held buffer.
    Returns the image, the dict the bench returns, and ``"asked"``: the rows the window asked the stream for, in
    order, until the bench returned, but in the clocks of ``restart`` (the window before it asks in them: the
    window starts in the next clock)."""
    g = geometry
    layout = FrameStoreLayout(width=g.buf_width, height=g.buf_height, cameras=1, buffers=3)
    image = np.random.default_rng(seed).integers(0, 1 << g.grey_bits, (g.buf_height, g.buf_width), dtype=np.uint8)
    contents = {}
    fill(contents, layout, 0, 2, image)
    bench = ReaderOnModel(layout, 0, contents, hold=(True, 2), latency=19, slots=SLOTS, depth=16)
    bench.m.submodules.window = window = DomainRenamer("pix")(RowWindow(g, slots=SLOTS, max_step=max_step))
    wiring.connect(bench.m, window.stream, bench.reader.stream)
    result, asked = {}, []

    async def consumer(ctx):
        result.update(await consumer_bench(ctx, window))
        result["asked"] = asked

    async def watch(ctx):
        fetch = window.stream.fetch
        while "asked" not in result:
            if ctx.get(fetch.en) and not ctx.get(window.restart):
                asked.append(ctx.get(fetch.row))
            await ctx.tick("pix")

    bench.run(consumer, watch)
    return image, result


async def restart(ctx, window, first_row, step=None):
    ctx.set(window.first_row, first_row)
    if step is not None:
        ctx.set(window.row_step, step)
    ctx.set(window.restart, 1)
    await ctx.tick("pix")
    ctx.set(window.restart, 0)


def test_display_pattern_is_never_refused():
    """Rows 0..H-1, each read on 2 lines of W active clocks and 40 blanking clocks, after a vertical blanking of 10
    lines: every read granted, every byte the image's."""
    scale, blank, lines_before = 2, 40, 10

    async def bench(ctx, window):
        await restart(ctx, window, 0)
        await ctx.tick("pix").repeat(lines_before * (G.buf_width * scale + blank))
        port, out, missed = window.consumer, [], 0
        for y in range(G.buf_height):
            for _ in range(scale):
                row = []
                for x in range(G.buf_width):
                    for _ in range(scale):
                        ctx.set(port.port.addr, y * G.buf_width + x)
                        ctx.set(port.request, 1)
                        await ctx.tick("pix")
                        missed += ctx.get(window.missed)
                        row.append(ctx.get(port.port.data))
                ctx.set(port.request, 0)
                ctx.set(port.port.addr, 0)
                await ctx.tick("pix").repeat(blank)
                out.append(row[::scale])
        return {"rows": out, "missed": missed}

    image, result = simulate(bench)
    assert result["missed"] == 0
    assert (np.array(result["rows"]) == np.repeat(image, 2, axis=0)).all()


async def read_rows_granted(ctx, port, sources, width):
    """Read rows ``sources`` of ``width`` pixels through ``port``, each pixel requested until granted (failing after
    ``GRANT_TIMEOUT`` clocks); the request is dropped after the last. Returns the rows read."""
    out = []
    for source in sources:
        row = []
        for x in range(width):
            ctx.set(port.port.addr, source * width + x)
            ctx.set(port.request, 1)
            for _ in range(GRANT_TIMEOUT):
                granted = ctx.get(port.grant)
                await ctx.tick("pix")
                if granted:
                    break
            else:
                raise AssertionError(f"row {source} column {x} never granted")
            row.append(ctx.get(port.port.data))
        out.append(row)
    ctx.set(port.request, 0)
    return out


@pytest.mark.parametrize("offset", [-3, 0, 4])
def test_engine_pattern_waits_for_its_rows(offset):
    """Rows min(max(y + offset, 0), H - 1) for y = 0..H-1, each pixel requested until granted: the image's rows."""
    h, w = G.buf_height, G.buf_width
    sources = [min(max(y + offset, 0), h - 1) for y in range(h)]

    async def bench(ctx, window):
        await restart(ctx, window, sources[0])
        out = await read_rows_granted(ctx, window.consumer, sources, w)
        return {"rows": out}

    image, result = simulate(bench, seed=abs(offset))
    assert (np.array(result["rows"]) == image[sources]).all()


def test_a_frame_taller_than_the_counters_wrap():
    """Rows 0..H-1 of a 40-row buffer, straight through: the window's counters (request numbers modulo a few times
    its slots) wrap several times in one frame, and every row is still granted and the image's."""
    h, w = TALL.buf_height, TALL.buf_width

    async def bench(ctx, window):
        await restart(ctx, window, 0)
        return {"rows": await read_rows_granted(ctx, window.consumer, range(h), w)}

    image, result = simulate(bench, seed=3, geometry=TALL)
    assert (np.array(result["rows"]) == image).all()


def test_restart_in_the_middle_starts_a_new_window():
    """A consumer reads rows 0..3, restarts from row 5 at once (rows of the first window still arriving) and reads
    5..H-1, then restarts from row 1 and reads 1..3: every byte the image's."""
    h, w = G.buf_height, G.buf_width
    plan = [(0, [0, 1, 2, 3]), (5, list(range(5, h))), (1, [1, 2, 3])]

    async def bench(ctx, window):
        out = []
        for first, rows in plan:
            await restart(ctx, window, first)
            out += await read_rows_granted(ctx, window.consumer, rows, w)
        return {"rows": out}

    image, result = simulate(bench, seed=7)
    assert (np.array(result["rows"]) == image[[r for _, rows in plan for r in rows]]).all()


def test_every_second_row_asks_for_those_rows_only():
    """Step 2 from row 0: the window asks the stream for rows 0, 2, ..., H - 2 only (half a frame's rows) and the
    consumer reads them, each granted and the image's."""
    h, w = G.buf_height, G.buf_width
    rows = list(range(0, h, 2))

    async def bench(ctx, window):
        await restart(ctx, window, 0, step=2)
        return {"rows": await read_rows_granted(ctx, window.consumer, rows, w)}

    image, result = simulate(bench, seed=11, max_step=2)
    assert result["asked"] == rows
    assert (np.array(result["rows"]) == image[rows]).all()


def test_steps_of_2_and_1_after_each_other():
    """Restarts with step 2, 1, 2 (rows of the window before still arriving at each): rows 0, 2, 4, 6, then 3..H-1,
    then 1, 3, 5, 7: every byte the image's, and the stream asked for no row the steps skip."""
    h, w = G.buf_height, G.buf_width
    plan = [(0, 2, [0, 2, 4, 6]), (3, 1, list(range(3, h))), (1, 2, [1, 3, 5, 7])]

    async def bench(ctx, window):
        out = []
        for first, step, rows in plan:
            await restart(ctx, window, first, step)
            out += await read_rows_granted(ctx, window.consumer, rows, w)
        return {"rows": out}

    image, result = simulate(bench, seed=5, max_step=2)
    assert (np.array(result["rows"]) == image[[r for _, _, rows in plan for r in rows]]).all()
    assert 1 not in result["asked"][:result["asked"].index(3)]   # the first window (step 2) skips row 1


def test_a_read_of_a_skipped_row_is_refused():
    """Step 2 from row 0, rows 0, 2 and 4 landed (the window's three slots): a read of row 1 or row 3 -- inside the
    window's addresses, between two landed rows -- is never granted (not below the window either); then rows 0 and 4
    are granted and the image's."""
    w = G.buf_width

    async def bench(ctx, window):
        await restart(ctx, window, 0, step=2)
        await ctx.tick("pix").repeat(GRANT_TIMEOUT)                 # every slot landed
        port, refused, below = window.consumer, [], []
        for row, x in ((1, 5), (3, 0), (1, w - 1), (3, w - 1)):
            ctx.set(port.port.addr, row * w + x)
            ctx.set(port.request, 1)
            granted = 0
            for _ in range(50):
                granted |= ctx.get(port.grant)
                below.append(ctx.get(window.below))
                await ctx.tick("pix")
            refused.append(not granted)
        ctx.set(port.request, 0)
        out = await read_rows_granted(ctx, port, [0, 4], w)
        return {"refused": refused, "below": any(below), "rows": out}

    image, result = simulate(bench, seed=9, max_step=2)
    assert result["refused"] == [True] * 4 and not result["below"]
    assert (np.array(result["rows"]) == image[[0, 4]]).all()


def test_a_step_needs_a_step_port_and_max_step_is_checked():
    assert "row_step" not in RowWindow(G, slots=SLOTS).signature.members
    assert "row_step" in RowWindow(G, slots=SLOTS, max_step=2).signature.members
    with pytest.raises(ValueError, match="positive integer"):
        RowWindow(G, slots=SLOTS, max_step=0)
