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


def simulate(consumer_bench, *, seed=0, geometry=G):
    g = geometry
    layout = FrameStoreLayout(width=g.buf_width, height=g.buf_height, cameras=1, buffers=3)
    image = np.random.default_rng(seed).integers(0, 1 << g.grey_bits, (g.buf_height, g.buf_width), dtype=np.uint8)
    contents = {}
    fill(contents, layout, 0, 2, image)
    bench = ReaderOnModel(layout, 0, contents, hold=(True, 2), latency=19, slots=SLOTS, depth=16)
    bench.m.submodules.window = window = DomainRenamer("pix")(RowWindow(g, slots=SLOTS))
    wiring.connect(bench.m, window.stream, bench.reader.stream)
    result = {}

    async def consumer(ctx):
        result.update(await consumer_bench(ctx, window))

    bench.run(consumer)
    return image, result


async def restart(ctx, window, first_row):
    ctx.set(window.first_row, first_row)
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
