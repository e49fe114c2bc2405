"""``BankTiming``: when MIG's controller may issue the command at the head of its address FIFO -- open rows,
read/write turnarounds, refresh."""

from amaranth.hdl import Array, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out, Signature

from spec.memory import MIG

__all__ = ["BankTiming", "HeadSignature"]


class HeadSignature(Signature):
    """The command at the head of the address FIFO, as the controller shows it: ``valid``, ``read`` (else a
    write), ``bank``, ``row``."""

    def __init__(self):
        super().__init__({"valid": Out(1), "read": Out(1), "bank": Out(MIG.BANK_BITS), "row": Out(MIG.ROW_BITS)})


class BankTiming(wiring.Component):
    """The controller's timing state: an open-row policy over the 4 banks (a row stays open until another row of
    its bank or a refresh needs the bank), the turnarounds between reads and writes, and a refresh every
    ``trefi`` clocks. Each cost is paid before the command that causes it, as idle clocks:

    * a row miss: ``MIG.TRP_CLK`` (precharge, only when the bank has another row open) + ``MIG.TRCD_CLK``
      (activate);
    * a write after a read: ``MIG.RTW_CLK``; a read after a write: ``MIG.WTR_CLK``;
    * a refresh, due every ``trefi`` clocks from ``enable`` and taken at the next burst boundary:
      ``MIG.TRP_CLK`` (precharge all) + ``trfc``, and every bank closed.

    Parameters
    ----------
    trefi, trfc : int
        Refresh interval and refresh cycle time in clocks.

    Members
    -------
    enable : In(1)
        ``phy_init_done``: the refresh timer runs from it.
    head : In(HeadSignature)
        The head command.
    boundary : In(1)
        The controller is between bursts (it may start the head command this clock).
    start : In(1)
        The controller starts the head command's burst this clock.
    ready : Out(1)
        The head command meets every timing rule this clock (it starts if its data is there).
    refreshing : Out(1)
        A refresh is in progress (for waveforms).

    Clock domain ``sync`` (clk0).
    """

    def __init__(self, *, trefi=MIG.TREFI_CLK, trfc=MIG.TRFC_CLK):
        if trefi <= MIG.TRP_CLK + trfc:
            raise ValueError(f"refresh interval {trefi} clocks is not longer than a refresh")
        self._trefi, self._trfc = trefi, trfc
        super().__init__({
            "enable": In(1), "head": In(HeadSignature()), "boundary": In(1), "start": In(1),
            "ready": Out(1), "refreshing": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        longest = MIG.TRP_CLK + max(self._trfc, MIG.TRCD_CLK + max(MIG.WTR_CLK, MIG.RTW_CLK))
        busy = Signal(range(longest + 1))
        refresh_timer = Signal(range(self._trefi), init=self._trefi - 1)
        refresh_due = Signal()
        open_valid = Signal(MIG.BANKS)
        open_row = Array(Signal(MIG.ROW_BITS, name=f"open_row_{b}") for b in range(MIG.BANKS))
        last_valid, last_read = Signal(), Signal()
        in_refresh = Signal()
        m.d.comb += self.refreshing.eq(in_refresh)

        with m.If(self.enable):
            m.d.sync += refresh_timer.eq(Mux(refresh_timer == 0, self._trefi - 1, refresh_timer - 1))
            with m.If(refresh_timer == 0):
                m.d.sync += refresh_due.eq(1)

        bank, row, read = self.head.bank, self.head.row, self.head.read
        bank_open = open_valid.bit_select(bank, 1)
        miss = ~bank_open | (open_row[bank] != row)
        turn = last_valid & (last_read != read)
        penalty = (Mux(miss, Mux(bank_open, MIG.TRP_CLK, 0) + MIG.TRCD_CLK, 0)
                   + Mux(turn, Mux(read, MIG.WTR_CLK, MIG.RTW_CLK), 0))

        with m.If(busy != 0):
            m.d.sync += busy.eq(busy - 1)
            with m.If(busy == 1):
                m.d.sync += in_refresh.eq(0)
        with m.Elif(self.boundary & self.enable):
            with m.If(refresh_due):
                m.d.sync += [busy.eq(MIG.TRP_CLK + self._trfc - 1), refresh_due.eq(0), open_valid.eq(0),
                             in_refresh.eq(1)]
            with m.Elif(self.head.valid & (miss | turn)):
                m.d.sync += [busy.eq(penalty - 1), open_valid.bit_select(bank, 1).eq(1), open_row[bank].eq(row),
                             last_valid.eq(1), last_read.eq(read)]
            with m.Else():
                m.d.comb += self.ready.eq(self.head.valid)
        with m.If(self.start):
            m.d.sync += [last_valid.eq(1), last_read.eq(read)]
        return m
