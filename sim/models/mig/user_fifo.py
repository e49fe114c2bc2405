"""``UserFifo``: one of MIG's user-side FIFOs (the address FIFO or the write-data FIFO) with its almost-full flag."""

from amaranth.hdl import Module
from amaranth.lib import wiring
from amaranth.lib.fifo import SyncFIFO
from amaranth.lib.wiring import In, Out

from spec.memory import MIG

__all__ = ["UserFifo"]


class UserFifo(wiring.Component):
    """A synchronous FIFO whose ``afull`` is high when ``afull_offset`` or fewer entries are free (the FIFO36
    ALMOSTFULL flag with ALMOST_FULL_OFFSET 15 of MIG's ``ddr2_usr_addr_fifo.v`` / ``ddr2_usr_wr.v``).

    Parameters
    ----------
    width : int
        Entry width.
    depth : int
        Entries (MIG: 1024 addresses, 512 write-data words).
    afull_offset : int
        ``afull`` is high when this many entries or fewer are free.

    Members
    -------
    w_data, w_en : In
        One entry written per clock with ``w_en``. A write into a full FIFO is dropped (the protocol checker's
        almost-full slack rule makes that impossible for a design that keeps the rule).
    afull : Out(1)
        From the clock after the write that leaves ``afull_offset`` or fewer entries free.
    r_data, r_rdy, r_en, level
        The read side (``r_data`` valid while ``r_rdy``; ``r_en`` takes it) and the number of entries.

    Clock domain ``sync`` (clk0).

    Raises
    ------
    ValueError
        ``depth`` not larger than ``afull_offset`` + 1.
    """

    def __init__(self, *, width, depth, afull_offset=MIG.AFULL_OFFSET):
        if depth <= afull_offset + 1:
            raise ValueError(f"a FIFO of {depth} entries cannot have an almost-full offset of {afull_offset}")
        self._width, self._depth, self._afull_offset = width, depth, afull_offset
        super().__init__({
            "w_data": In(width), "w_en": In(1), "afull": Out(1),
            "r_data": Out(width), "r_rdy": Out(1), "r_en": In(1), "level": Out(range(depth + 1)),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.fifo = fifo = SyncFIFO(width=self._width, depth=self._depth)
        m.d.comb += [
            fifo.w_data.eq(self.w_data), fifo.w_en.eq(self.w_en),
            self.r_data.eq(fifo.r_data), self.r_rdy.eq(fifo.r_rdy), fifo.r_en.eq(self.r_en),
            self.level.eq(fifo.level),
            self.afull.eq(fifo.level >= self._depth - self._afull_offset),
        ]
        return m
