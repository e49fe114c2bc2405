"""The frame store's read tests' set-up, written once: a ``RowReader`` behind the ``MemoryArbiter`` and the MIG model
(``sim/models/mig``, preloaded with the buffers' contents, its checker stopping the run on any violation), in a
``pix`` and a ``mem`` domain. ``tests/test_frame_store_reader.py`` reads rows from it directly,
``tests/test_frame_store_window.py`` through a ``RowWindow`` it adds to the module."""

from amaranth import ClockDomain, DomainRenamer, Module
from amaranth.lib import wiring
from amaranth.sim import Simulator

from hdl.frame_store.arbiter import MemoryArbiter
from hdl.frame_store.row_reader import RowReader
from sim.models.mig import MIGModel, layout_window, memory_words, watch_violations
from spec.memory import MIG

__all__ = ["fill", "ReaderOnModel", "take_pair", "read_row"]


def fill(contents, layout, camera, buffer, image):
    """Put ``image`` into ``contents`` (byte address -> byte) where the layout puts a buffer (one byte a pixel)."""
    for y, row in enumerate(image):
        for x, value in enumerate(row):
            contents[layout.buffer_base(camera, buffer) * 8 + y * layout.stride + x] = int(value)


async def take_pair(ctx, store):
    """``store.take`` for a clock, then wait (in ``pix``) until the ``FrameStore`` says the latest pair is held."""
    ctx.set(store.take, 1)
    await ctx.tick("pix")
    ctx.set(store.take, 0)
    await ctx.tick("pix").until(store.taken)


async def read_row(ctx, stream, row, slot, width):
    """Ask read ``stream`` for buffer ``row``, wait until it lands, and read its ``width`` bytes from ring ``slot``
    (``pix`` clocks). Returns the bytes as a list."""
    await ctx.tick("pix").until(stream.fetch.rdy)
    ctx.set(stream.fetch.row, row)
    ctx.set(stream.fetch.en, 1)
    await ctx.tick("pix")
    ctx.set(stream.fetch.en, 0)
    if not ctx.get(stream.landed):
        await ctx.tick("pix").until(stream.landed)
    out = []
    for x in range(width):
        ctx.set(stream.read.slot, slot)
        ctx.set(stream.read.x, x)
        await ctx.tick("pix")
        out.append(ctx.get(stream.read.data))
    return out


class ReaderOnModel:
    """``m``: a module with ``pix`` and ``mem`` domains holding ``reader`` (a ``RowReader`` of ``camera``'s buffers,
    ``slots`` row slots, a returning FIFO of ``depth`` words) on a one-reader arbiter (urgent) and the MIG model
    over the layout's buffers holding ``contents`` (byte address -> byte), read latency ``latency``. The reader holds
    ``hold`` = (valid, buffer) from the start."""

    def __init__(self, layout, camera, contents, *, hold, latency, slots, depth):
        self.hold = hold
        self.m = m = Module()
        m.domains += [ClockDomain("pix"), ClockDomain("mem")]
        m.submodules.reader = self.reader = RowReader(layout, camera, slots=slots, depth=depth)
        arbiter = MemoryArbiter(writers=0, readers=1, urgent=1)
        m.submodules.arbiter = DomainRenamer("mem")(arbiter)
        wiring.connect(m, self.reader.mem, arbiter.readers[0])
        self.model = MIGModel(af_depth=32, wdf_depth=32, **layout_window(layout), init_clocks=20,
                              init=memory_words(contents))
        self.latency = latency
        m.submodules.mig = DomainRenamer("mem")(self.model)
        wiring.connect(m, arbiter.mig, self.model.user)

    def run(self, *testbenches, pix_period=6.7e-9):
        """Simulate until every one of ``testbenches`` (async functions of ``ctx``) has returned."""
        reader, model = self.reader, self.model

        async def set_up(ctx):
            ctx.set(reader.hold.valid, int(self.hold[0]))
            ctx.set(reader.hold.buffer, self.hold[1])
            ctx.set(model.latency, self.latency)

        sim = Simulator(self.m)
        sim.add_clock(pix_period, domain="pix")
        sim.add_clock(1 / MIG.CLK0_HZ, domain="mem")
        sim.add_testbench(set_up)
        sim.add_testbench(watch_violations(model), background=True)
        for bench in testbenches:
            sim.add_testbench(bench)
        sim.run()
