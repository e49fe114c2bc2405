"""``ProtocolChecker``: every breach of MIG's user-interface contract the model can see, as a held violation
code (:mod:`sim.models.mig.violations`)."""

from amaranth.hdl import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out, Signature

from spec.memory import MIG

from .memory_window import window_index
from .violations import Violation, ViolationSignature

__all__ = ["ProtocolChecker"]


class ProtocolChecker(wiring.Component):
    """Watches the user's side of the interface and holds the first violation (code, address, clock) until reset.
    When several happen on one clock, the first in :class:`Violation`'s order is reported.

    * before ``phy_init_done``: no command, no write-data word;
    * a command: ``cmd`` 000 or 001; ``addr`` burst-aligned (``addr[1:0]`` = 0), within the part
      (``MIG.MEMORY_WORDS``) and the model's window;
    * almost full: a command (a data word) may be written on the first ``af_slack`` (``wdf_slack``) clocks of a
      stretch of ``app_af_afull`` (``app_wdf_afull``) high, not later: one entry per clock fits the entries
      free when the flag is first seen, whatever the controller drains;
    * data before address (AR 24146, BL4): a write command is written no earlier than its burst's first data
      word: the k-th write command (from 0) needs 2 k + 1 data words written by its clock (its own clock
      included);
    * ``data_missing`` (the controller's: a burst's data did not come), ``read_valid`` while the design's
      ``read_ready`` is low, a read latency outside ``latency_range`` at ``phy_init_done``.

    Parameters
    ----------
    addr_width : int
        ``app_af_addr``'s width.
    window_base, window_words, window_banks : int
        The model's memory window (64-bit words; :class:`~sim.models.mig.memory_window.MemoryWindow`).
    af_slack, wdf_slack : int
        Clocks of almost full in which a write is still allowed.
    latency_range : (int, int)
        The read latency's allowed range.
    wdf_depth : int
        The write-data FIFO's depth (the data-before-address count's range).
    latency_bits : int
        Width of ``latency``.

    Members
    -------
    init_done, command, write_wren, af_afull, wdf_afull, read_valid, read_ready, latency, data_missing,
    missing_addr, now : In
        What the checker watches.
    violation : Out(ViolationSignature)
        The first violation.

    Clock domain ``sync`` (clk0).
    """

    def __init__(self, *, addr_width=MIG.ADDR_WIDTH, window_base=0, window_words=MIG.MEMORY_WORDS, window_banks=1,
                 af_slack=MIG.AFULL_OFFSET, wdf_slack=MIG.AFULL_OFFSET - MIG.WDF_AFULL_ASSERT_CLK,
                 latency_range=(16, 32), wdf_depth=MIG.WDF_DEPTH, latency_bits=6):
        self._addr_width = addr_width
        self._window = (window_base, window_words, window_banks)
        self._slacks, self._latency_range, self._wdf_depth = (af_slack, wdf_slack), latency_range, wdf_depth
        super().__init__({
            "init_done": In(1),
            "command": In(Signature({"cmd": Out(MIG.CMD_WIDTH), "addr": Out(addr_width), "wren": Out(1)})),
            "write_wren": In(1), "af_afull": In(1), "wdf_afull": In(1),
            "read_valid": In(1), "read_ready": In(1), "latency": In(latency_bits),
            "data_missing": In(1), "missing_addr": In(addr_width), "now": In(32),
            "violation": Out(ViolationSignature(addr_width)),
        })

    @staticmethod
    def _afull_too_long(m, afull, wren, slack):
        """A write on a clock when ``afull`` has been high for ``slack`` clocks or more before it."""
        high_for = Signal(range(slack + 1))
        with m.If(~afull):
            m.d.sync += high_for.eq(0)
        with m.Elif(high_for != slack):
            m.d.sync += high_for.eq(high_for + 1)
        return wren & afull & (high_for == slack)

    def _data_ahead(self, m, write_cmd):
        """The data-before-address rule: a write command without its first data word."""
        credit = Signal(range(-2, self._wdf_depth + 2))    # data words written - 2 x write commands written
        with_word = credit + self.write_wren
        m.d.sync += credit.eq(with_word - 2 * write_cmd)
        return write_cmd & (with_word < 1)

    def elaborate(self, platform):
        m = Module()
        cmd, addr, wren = self.command.cmd, self.command.addr, self.command.wren
        known = (cmd == MIG.CMD_WRITE) | (cmd == MIG.CMD_READ)
        in_part = addr < MIG.MEMORY_WORDS
        in_window, _ = window_index(addr, *self._window)
        init_prev = Signal()
        m.d.sync += init_prev.eq(self.init_done)
        lo, hi = self._latency_range
        checks = [   # (condition, code, address), in Violation's order
            (wren & ~self.init_done, Violation.COMMAND_BEFORE_INIT, addr),
            (self.write_wren & ~self.init_done, Violation.DATA_BEFORE_INIT, 0),
            (wren & ~known, Violation.UNKNOWN_COMMAND, addr),
            (wren & (addr[:2] != 0), Violation.UNALIGNED_ADDRESS, addr),
            (wren & ~in_part, Violation.ADDRESS_OUTSIDE_PART, addr),
            (wren & ~in_window, Violation.ADDRESS_OUTSIDE_WINDOW, addr),
            (self._afull_too_long(m, self.af_afull, wren, self._slacks[0]), Violation.COMMAND_AFULL, addr),
            (self._afull_too_long(m, self.wdf_afull, self.write_wren, self._slacks[1]), Violation.DATA_AFULL, 0),
            (self._data_ahead(m, wren & (cmd == MIG.CMD_WRITE)), Violation.COMMAND_BEFORE_DATA, addr),
            (self.data_missing, Violation.WRITE_DATA_MISSING, self.missing_addr),
            (self.read_valid & ~self.read_ready, Violation.READ_NOT_TAKEN, 0),
            (self.init_done & ~init_prev & ((self.latency < lo) | (self.latency > hi)),
             Violation.LATENCY_OUT_OF_RANGE, 0),
        ]
        with m.If(self.violation.code == Violation.NONE):
            for n, (condition, code, where) in enumerate(checks):
                with (m.If if n == 0 else m.Elif)(condition):
                    m.d.sync += [self.violation.code.eq(code), self.violation.addr.eq(where),
                                 self.violation.cycle.eq(self.now)]
        return m
