"""RowFetcher: a reader's rows fetched from the buffer it holds, burst by burst, in the ``mem`` domain, never more
than its receiving FIFO can take (docs/frame_store.md, "Readers").

Requests (row numbers) come from a FIFO; for each, the fetcher asks the arbiter for the row's bursts in order
(``buffer base + row * stride + burst * 32 bytes``: the row's offset in the buffer, a register set when the request
is taken and stepped a burst at a time, plus the held buffer's base) and writes the words MIG returns, two a burst,
into ``words`` (the write side of a FIFO of ``depth`` words). MIG cannot be held back, so a read is requested only
when the FIFO has room for every word outstanding and the burst's two (*credits*), decided a clock ahead (a
register): ``level + outstanding + 4 <= depth`` in the clock before, which allows for the 2 words a burst granted in
that clock adds; ``level`` is the FIFO's own count, which only overstates the words in it while the other side's
reads reach it.
While the reader holds no pair (before the first complete pair), a row's bursts are not read: two zero words each
go into the FIFO instead, once nothing is outstanding, so the words still come one row after another.
"""

from amaranth import Array, Const, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.shift_add import times
from spec.memory import MIG

from .layout import FrameStoreLayout
from .mem_port import BurstReadSignature

__all__ = ["RowFetcher"]


class RowFetcher(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    layout : :class:`hdl.frame_store.layout.FrameStoreLayout`
    camera : int
        Whose buffers it reads.
    depth : int
        The receiving FIFO's depth in words (at least 2).

    Attributes
    ----------
    requests : ``In(...)``
        A FIFO's read side: ``row`` and ``rdy`` in, ``en`` out.
    hold : ``In(...)``
        ``valid`` and ``buffer``: the pair the reader holds, this camera's buffer (the ownership's reader port).
    mem : ``Out(BurstReadSignature())``
    words : ``Out(...)``
        A FIFO's write side: ``data``, ``en`` out; ``level`` (its word count) in.
    outstanding : ``Out(range(depth + 1))``
        Words requested and not yet returned.

    Clock domain: ``sync`` (the reader renames it to ``mem``). Latency: a request is taken in the clock after the
    previous row's last burst is granted; a burst is asked for a clock after the room for it is seen; words go into the FIFO in the clock MIG returns them.

    Raises
    ------
    ValueError
        ``camera`` outside the layout, ``depth`` below 2.
    """

    def __init__(self, layout=FrameStoreLayout(), camera=0, depth=32):
        if not 0 <= camera < layout.cameras:
            raise ValueError(f"camera must be in 0..{layout.cameras - 1}, got {camera}")
        if depth < MIG.WORDS_PER_BURST:
            raise ValueError(f"depth must hold a burst's {MIG.WORDS_PER_BURST} words, got {depth}")
        self.layout, self.camera, self.depth = layout, camera, depth
        bits = max(1, (layout.buffers - 1).bit_length())
        super().__init__({
            "requests": In(wiring.Signature({"row": Out(range(layout.height)), "rdy": Out(1), "en": In(1)})),
            "hold": In(wiring.Signature({"valid": Out(1), "buffer": Out(bits)})),
            "mem": Out(BurstReadSignature()),
            "words": Out(wiring.Signature({"data": Out(MIG.DATA_WIDTH), "en": Out(1),
                                           "level": In(range(depth + 1))})),
            "outstanding": Out(range(depth + 1)),
        })

    def elaborate(self, platform):
        m = Module()
        lay, mem, words = self.layout, self.mem, self.words
        busy = Signal()
        offset = Signal(range(lay.buffer_words + 1))  # the burst's memory word in the buffer: row * stride + burst * 4
        burst = Signal(range(lay.bursts_per_row))
        zero_second = Signal()                  # the second zero word of a burst not read
        outstanding = self.outstanding
        bases = Array(Const(lay.buffer_base(self.camera, b), MIG.ADDR_WIDTH) for b in range(lay.buffers))
        # Room for a burst, a clock late: the words outstanding and in the FIFO grow by at most 2 in a clock (a
        # burst granted, or a zero word written), so room for that much more and the burst's own 2 then means
        # room for the burst's 2 now.
        room = Signal()
        m.d.sync += room.eq(words.level + outstanding + 2 * MIG.WORDS_PER_BURST <= self.depth)
        m.d.comb += [
            mem.addr.eq(bases[self.hold.buffer] + offset),
            self.requests.en.eq(~busy & self.requests.rdy),
        ]
        # ``last``: the burst is the row's last, a register stepped with ``burst`` (no comparison after a grant).
        last = Signal()
        with m.If(self.requests.en):
            m.d.sync += [busy.eq(1), offset.eq(times(self.requests.row, lay.stride_words)), burst.eq(0),
                         last.eq(lay.bursts_per_row == 1)]

        done = Signal()                         # the burst is granted (or its zero words are in)
        with m.If(busy & ~zero_second):
            with m.If(self.hold.valid):
                m.d.comb += mem.request.eq(room)
                m.d.comb += done.eq(mem.grant)
            with m.Elif(room & (outstanding == 0)):
                m.d.comb += [words.data.eq(0), words.en.eq(1)]
                m.d.sync += zero_second.eq(1)
        with m.If(zero_second):
            m.d.comb += [words.data.eq(0), words.en.eq(1), done.eq(1)]
            m.d.sync += zero_second.eq(0)
        with m.If(done):
            m.d.sync += [burst.eq(burst + 1), offset.eq(offset + MIG.BURST_LENGTH),
                         last.eq(burst == lay.bursts_per_row - 2)]
            with m.If(last):
                m.d.sync += busy.eq(0)

        with m.If(mem.valid):
            m.d.comb += [words.data.eq(mem.data), words.en.eq(1)]
        granted = mem.request & mem.grant
        m.d.sync += outstanding.eq(outstanding + (granted << 1) - mem.valid)
        return m
