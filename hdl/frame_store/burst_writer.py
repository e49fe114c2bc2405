"""BurstWriter: a camera's packed entries written into the buffer its writer owns, in the ``mem`` domain.

It takes the :class:`~hdl.frame_store.burst_packer.BurstPacker`'s entries from a FIFO, one at a time:

* ``START``: asks the ownership for a buffer (``own.start``) and expects row 0, burst 0;
* ``BURST``: when the writer owns a buffer and the entry is the expected burst (the next in raster order, inside
  the layout), asks the arbiter to write it (``mem``) at ``buffer base + row * stride + burst * 32 bytes`` (the
  expected burst's offset in the buffer is a register, stepped with the expected row and burst) and takes the next
  entry when granted; otherwise drops it and spoils the frame. The check is a register, made in the clock the entry
  is first offered and used from the next (the entry stays at the FIFO's head until taken, and nothing it checks
  changes until an entry is taken), so the arbiter's request is a flip-flop, not the row and burst comparisons;
* ``END``: ends the frame (``own.finish``), ``complete`` when the entry says ``ok``, nothing spoiled it and every
  burst of every row came in order -- so a published buffer holds one frame's every burst, each written once.

Addresses are built only from the owned buffer's base and the expected (in-range) row and burst, so nothing a camera
sends lands outside the buffer the ownership gave the writer, and nothing is written while it owns none.
"""

from amaranth import Array, Const, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec.memory import MIG

from .burst_packer import ENTRY_KINDS, burst_entry_layout
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
    offered (``START``, ``END``), in the clock after (a dropped burst), or when granted, from the clock after it is
    offered (a burst it writes). An entry offered must stay at the head, unchanged, until taken (a FIFO's read side).

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
        expect_row = Signal(range(lay.height + 1))
        expect_burst = Signal(range(lay.bursts_per_row))
        spoiled = Signal()
        bases = Array(Const(lay.buffer_base(self.camera, b), MIG.ADDR_WIDTH) for b in range(lay.buffers))
        offset = Signal(range(lay.buffer_words + 1))      # the expected burst's memory word in the buffer
        expected = (entry.row == expect_row) & (entry.burst == expect_burst)
        writable = own.writing & expected & (expect_row < lay.height)
        # The head entry's check, a clock late: ``checked`` says ``may_write`` is this entry's (it was offered in the
        # clock before and not taken, so it and the writer's state are as they were).
        may_write, checked = Signal(), Signal()
        m.d.sync += [may_write.eq(writable), checked.eq(self.entries.rdy & ~self.entries.en)]
        m.d.comb += [
            mem.addr.eq(bases[own.buffer] + offset),
            mem.data.eq(entry.data),
            mem.mask.eq(entry.mask),
        ]
        with m.If(self.entries.rdy):
            with m.Switch(entry.kind):
                with m.Case(ENTRY_KINDS["START"]):
                    m.d.comb += [own.start.eq(1), self.entries.en.eq(1)]
                    m.d.sync += [expect_row.eq(0), expect_burst.eq(0), offset.eq(0), spoiled.eq(0)]
                with m.Case(ENTRY_KINDS["END"]):
                    m.d.comb += [own.finish.eq(1), self.entries.en.eq(1),
                                 own.complete.eq(entry.ok & ~spoiled & (expect_row == lay.height))]
                with m.Case(ENTRY_KINDS["BURST"]):
                    with m.If(checked):
                        m.d.comb += [mem.request.eq(may_write), self.entries.en.eq(~may_write | mem.grant)]
                        with m.If(~may_write):
                            m.d.sync += spoiled.eq(1)
                        with m.Elif(mem.grant):
                            with m.If(expect_burst == lay.bursts_per_row - 1):
                                m.d.sync += [expect_burst.eq(0), expect_row.eq(expect_row + 1),
                                             offset.eq(offset + lay.stride_words
                                                       - (lay.bursts_per_row - 1) * MIG.BURST_LENGTH)]
                            with m.Else():
                                m.d.sync += [expect_burst.eq(expect_burst + 1),
                                             offset.eq(offset + MIG.BURST_LENGTH)]
                with m.Default():
                    m.d.comb += self.entries.en.eq(1)
                    m.d.sync += spoiled.eq(1)
        return m
