"""``UserFifo``: one of MIG's user-side FIFOs (the address FIFO or the write-data FIFO) with its almost-full flag."""

from amaranth.hdl import Cat, Module, Signal
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
    assert_latency, deassert_latency : int
        Clocks ``afull`` follows the fill level late when it rises and when it falls: 0 and 0 for a synchronous
        FIFO36 (the address FIFO), 1 and 3 for a multirate one (the write-data FIFO, UG190 table 4-16).

    Members
    -------
    w_data, w_en : In
        One entry written per clock with ``w_en``. A write into a full FIFO is dropped (the protocol checker's
        almost-full slack rule makes that impossible for a design that keeps the rule).
    afull : Out(1)
        From the clock after the write that leaves ``afull_offset`` or fewer entries free (plus
        ``assert_latency``).
    r_data, r_rdy, r_en, level
        The read side (``r_data`` valid while ``r_rdy``; ``r_en`` takes it) and the number of entries.

    Clock domain ``sync`` (clk0).

    Raises
    ------
    ValueError
        ``depth`` not larger than ``afull_offset`` + 1, or ``deassert_latency`` < ``assert_latency``.
    """

    def __init__(self, *, width, depth, afull_offset=MIG.AFULL_OFFSET, assert_latency=0, deassert_latency=0):
        if depth <= afull_offset + 1:
            raise ValueError(f"a FIFO of {depth} entries cannot have an almost-full offset of {afull_offset}")
        if not 0 <= assert_latency <= deassert_latency:
            raise ValueError("almost-full latencies: 0 <= assert_latency <= deassert_latency")
        self._width, self._depth, self._afull_offset = width, depth, afull_offset
        self._latency = (assert_latency, deassert_latency)
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
        ]
        level_afull = fifo.level >= self._depth - self._afull_offset
        history = [level_afull]                       # history[k]: the level's flag k clocks ago
        for k in range(self._latency[1]):
            history.append(Signal(name=f"afull_{k + 1}_ago"))
            m.d.sync += history[-1].eq(history[-2])
        lo, hi = self._latency
        m.d.comb += self.afull.eq(Cat(*history[lo:hi + 1]).any())
        return m
