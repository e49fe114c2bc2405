"""BurstWriter: a camera's packed entries written into the buffer its writer owns, in the ``mem`` domain.

It takes the :class:`~hdl.frame_store.burst_packer.BurstPacker`'s entries from a FIFO, one at a time:

* ``START``: asks the ownership for a buffer (``own.start``) and expects row 0, word 0;
* ``BURST`` (a 64-bit memory word of a burst): when the writer owns a buffer and the entry is the expected word (the
  next in raster order, inside the layout), takes it; the first three words of a burst into a shift register, the
  fourth with them asks the arbiter to write the burst (``mem``) at ``buffer base + row * stride + burst * 32
  bytes`` (the expected burst's offset in the buffer is a register, stepped with the expected row and burst) and is
  taken in the clock after its grant (the request a register: it asks from the clock after the word is the
  expected head). A row's last word short of a burst's fourth is followed by masked words the
  writer makes itself (no entry taken) up to the burst's end. An entry other than the expected word is dropped and
  spoils the frame;
* ``END``: ends the frame (``own.finish``), ``complete`` when the entry says ``ok``, nothing spoiled it and every
  word of every row came in order -- so a published buffer holds one frame's every burst, each written once.

Addresses are built only from the owned buffer's base and the expected (in-range) row and burst, so nothing a camera
sends lands outside the buffer the ownership gave the writer, and nothing is written while it owns none.
"""

from amaranth import Array, Cat, Const, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec.memory import MIG

from .burst_packer import ENTRY_KINDS, WORD_BYTES, burst_entry_layout
from .layout import FrameStoreLayout
from .mem_port import BurstWriteSignature
from .ownership import WriterOwnershipSignature

__all__ = ["BurstWriter", "check_camera"]


def check_camera(layout, camera):
    """``ValueError`` unless ``camera`` is one of the layout's."""
    if not 0 <= camera < layout.cameras:
        raise ValueError(f"camera must be in 0..{layout.cameras - 1}, got {camera}")


class BurstWriter(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    layout : :class:`hdl.frame_store.layout.FrameStoreLayout`
    camera : int
        Whose buffers the writer writes.

    Attributes
    ----------
    entries : ``In(...)``
        A FIFO's read side: ``data`` (:func:`~hdl.frame_store.burst_packer.burst_entry_layout`) and ``rdy`` in,
        ``en`` out (the entry is taken).
    own : ``Out(WriterOwnershipSignature(layout.buffers))``
    mem : ``Out(BurstWriteSignature())``

    Clock domain: ``sync`` (the frame store renames it to ``mem``). Latency: an entry is taken in the clock it is
    offered (``START``, ``END``, a burst's first three words, a dropped word) or in the clock after its grant (a
    burst's fourth word); a row's last burst short of four words takes a clock for each word it lacks before its
    request.

    Raises
    ------
    ValueError
        ``camera`` outside the layout's cameras.
    """

    def __init__(self, layout=FrameStoreLayout(), camera=0):
        check_camera(layout, camera)
        self.layout, self.camera = layout, camera
        super().__init__({
            "entries": In(wiring.Signature({"data": Out(burst_entry_layout(layout)), "rdy": Out(1), "en": In(1)})),
            "own": Out(WriterOwnershipSignature(layout.buffers)),
            "mem": Out(BurstWriteSignature()),
        })

    def elaborate(self, platform):
        m = Module()
        lay, own, mem = self.layout, self.own, self.mem
        entry = self.entries.data
        words = MIG.BURST_LENGTH                            # entries (memory words) a burst
        row_words = -(-lay.row_bytes // WORD_BYTES)         # words the packer sends a row
        expect_row = Signal(range(lay.height + 1))
        row_in = Signal(init=1)                 # expect_row < height, registered where expect_row changes
        expect_word = Signal(range(lay.bursts_per_row * words))
        spoiled = Signal()
        padding = Signal()                      # the row's last burst lacks words: the writer makes them, masked
        drop = Signal()                         # the FIFO's head is the burst's fourth word, granted last clock
        bases = Array(Const(lay.buffer_base(self.camera, b), MIG.ADDR_WIDTH) for b in range(lay.buffers))
        offset = Signal(range(lay.buffer_words + 1))      # the expected burst's memory word in the buffer
        # The burst's first three words, the latest on top: the fourth (the entry's, or a made one) completes it.
        held = Signal(8 * WORD_BYTES * (words - 1))
        held_mask = Signal(WORD_BYTES * (words - 1))
        word_mask = Signal(WORD_BYTES)          # the entry's mask, all ones for a made word
        m.d.comb += word_mask.eq(entry.mask | padding.replicate(WORD_BYTES))
        expected = (entry.row == expect_row) & (entry.word == expect_word)
        in_frame = own.writing & row_in
        writable = in_frame & expected
        fourth = expect_word[:(words - 1).bit_length()] == words - 1
        m.d.comb += [
            mem.addr.eq(bases[own.buffer] + offset),
            mem.data.eq(Cat(held, entry.data)),
            mem.mask.eq(Cat(held_mask, word_mask)),
        ]

        def hold():                             # a burst's word into the shift register, the next word expected
            m.d.sync += [held.eq(Cat(held[8 * WORD_BYTES:], entry.data)),
                         held_mask.eq(Cat(held_mask[WORD_BYTES:], word_mask)), expect_word.eq(expect_word + 1)]

        # The request is a register (``asking``), so the mem domain's longest paths (a request through the arbiter
        # into MIG's command address and the readers' fetchers) start at a flip-flop: set in the clock a burst's
        # fourth word is the expected head (or the made words reach a burst's end), it asks from the next clock on,
        # the head kept, until the grant; the granted word is taken in the clock after its grant (``drop``: the
        # grant stays out of the FIFO's read-pointer path).
        asking = Signal()
        m.d.comb += mem.request.eq(asking)
        m.d.sync += drop.eq(0)
        with m.If(asking):
            with m.If(mem.grant):
                m.d.sync += [asking.eq(0), drop.eq(~padding), padding.eq(0)]
                self._next_burst(m, expect_word, expect_row, row_in, offset)
        with m.Elif(padding):
            with m.If(fourth):
                m.d.sync += asking.eq(in_frame)
            with m.Else():
                hold()
        with m.Elif(self.entries.rdy):
            with m.Switch(entry.kind):
                with m.Case(ENTRY_KINDS["START"]):
                    m.d.comb += [own.start.eq(1), self.entries.en.eq(1)]
                    m.d.sync += [expect_row.eq(0), row_in.eq(1), expect_word.eq(0), offset.eq(0), spoiled.eq(0)]
                with m.Case(ENTRY_KINDS["END"]):
                    m.d.comb += [own.finish.eq(1), self.entries.en.eq(1),
                                 own.complete.eq(entry.ok & ~spoiled & (expect_row == lay.height))]
                with m.Case(ENTRY_KINDS["BURST"]):
                    with m.If(drop):            # the fourth word granted last clock
                        m.d.comb += self.entries.en.eq(1)
                    with m.Elif(~writable):
                        m.d.comb += self.entries.en.eq(1)
                        m.d.sync += spoiled.eq(1)
                    with m.Elif(~fourth):
                        m.d.comb += self.entries.en.eq(1)
                        hold()
                        with m.If(expect_word == row_words - 1):
                            m.d.sync += padding.eq(1)
                    with m.Else():
                        m.d.sync += asking.eq(1)
                with m.Default():
                    m.d.comb += self.entries.en.eq(1)
                    m.d.sync += spoiled.eq(1)
        return m

    def _next_burst(self, m, expect_word, expect_row, row_in, offset):
        """The burst granted: the next burst expected (the next row's first after a row's last)."""
        lay = self.layout
        with m.If(expect_word == lay.bursts_per_row * MIG.BURST_LENGTH - 1):
            m.d.sync += [expect_word.eq(0), expect_row.eq(expect_row + 1), row_in.eq(expect_row != lay.height - 1),
                         offset.eq(offset + lay.stride_words - (lay.bursts_per_row - 1) * MIG.BURST_LENGTH)]
        with m.Else():
            m.d.sync += [expect_word.eq(expect_word + 1), offset.eq(offset + MIG.BURST_LENGTH)]
