"""The frame store's row reader (request FIFO, fetcher with credits, returning FIFO, ring of row slots) behind the
memory arbiter and the MIG model (sim/models/mig, its checker stopping the run on any violation): the rows a consumer asks for land in
their slots with the bytes the layout puts in the held buffer, whatever the ratio of the clocks."""

import numpy as np
import pytest

from frame_store_on_model import ReaderOnModel, fill
from hdl.frame_store.layout import FrameStoreLayout

LAYOUT = FrameStoreLayout(width=48, height=7, cameras=2, buffers=3, base=128)
#: Pix clocks the consumer waits, at most, for its rows (a row lost in a FIFO never lands).
TIMEOUT_CLOCKS = 5000


def run(rows, *, pix_period=6.7e-9, depth=8, slots=3, hold=(True, 1), seed=0):
    """Ask for ``rows`` of camera 1 one after another (at most ``slots`` ahead of the ones read), read every pixel
    of each landed row; the rows read."""
    images = {b: np.random.default_rng(b).integers(0, 256, (LAYOUT.height, LAYOUT.width), dtype=np.uint8)
              for b in range(LAYOUT.buffers)}
    contents = {}
    for b, image in images.items():
        fill(contents, LAYOUT, 1, b, image)
        fill(contents, LAYOUT, 0, b, 255 - image)
    bench = ReaderOnModel(LAYOUT, 1, contents, hold=hold, latency=16 + seed % 17, slots=slots, depth=depth)
    reader = bench.reader
    got = []

    async def consumer(ctx):
        asked, landed = 0, 0
        for _ in range(TIMEOUT_CLOCKS):
            if len(got) == len(rows):
                break
            if asked < len(rows) and asked - len(got) < slots and ctx.get(reader.stream.fetch.rdy):
                ctx.set(reader.stream.fetch.row, rows[asked])
                ctx.set(reader.stream.fetch.en, 1)
                asked += 1
            else:
                ctx.set(reader.stream.fetch.en, 0)
            await ctx.tick("pix")
            landed += ctx.get(reader.stream.landed)
            ctx.set(reader.stream.fetch.en, 0)
            if landed > len(got):
                slot = len(got) % slots
                row = []
                for x in range(LAYOUT.width):              # the byte one clock after its address
                    ctx.set(reader.stream.read.slot, slot)
                    ctx.set(reader.stream.read.x, x)
                    await ctx.tick("pix")
                    landed += ctx.get(reader.stream.landed)
                    row.append(ctx.get(reader.stream.read.data))
                got.append(row)

    bench.run(consumer, pix_period=pix_period)
    assert len(got) == len(rows), f"{len(rows) - len(got)} rows never landed"
    return np.array(got, np.uint8), images


@pytest.mark.parametrize("pix_period", [6.7e-9, 40e-9], ids=["pix_fast", "pix_slow"])
def test_rows_land_with_the_held_buffer_s_bytes(pix_period):
    rows = [0, 1, 2, 3, 6, 5, 6, 0]
    got, images = run(rows, pix_period=pix_period)
    assert (got == images[1][rows]).all()


def test_no_pair_held_reads_zeros():
    got, _ = run([2, 3], hold=(False, 0))
    assert (got == 0).all()
