"""``Controller``: the MIG model's command engine -- takes commands from the address FIFO in order, writes bursts
from the write-data FIFO into the memory window, reads bursts out of it into the read return."""

from amaranth.hdl import Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out, Signature

from spec.memory import MIG

from .bank_timing import BankTiming
from .memory_window import MemoryPortsSignature

__all__ = ["Controller"]


class Controller(wiring.Component):
    """One BL4 burst per command, two user words on two consecutive clocks, a command at most every 2 clocks (2T
    command timing, BL4: the data bus's rate). A command starts when :class:`BankTiming` allows it and, for a
    write, when both of its words are in the write-data FIFO; a write whose words are not there ``data_grace``
    clocks after its timing allowed it is reported (``data_missing``): MIG itself does not wait, it reads the
    write-data FIFO a fixed time after taking the command.

    Parameters
    ----------
    addr_width, data_width : int
        ``app_af_addr``'s and a user word's widths.
    latency_bits : int
        Width of ``latency``.
    data_grace : int
        Clocks a write may wait for its data.
    trefi, trfc : int
        :class:`BankTiming`'s refresh interval and cycle time.

    Members
    -------
    enable : In(1)
        ``phy_init_done``.
    latency : In
        The read latency L (clocks, at least 3): a read taken from the FIFO's head the clock after it was
        written, with no cost to pay, has its first word on the read return L clocks after the clock it was
        written in (the return's ``due`` times are ``now``-based).
    now : In(32)
        The model's clock counter.
    af_data, af_rdy, af_en
        The address FIFO's read side: ``af_data`` is {addr, cmd}.
    wdf_data, wdf_level, wdf_en
        The write-data FIFO's read side: ``wdf_data`` is {mask, data}.
    mem : Out(MemoryPortsSignature)
        The memory window's ports.
    ret : Out(Signature)
        A read word for the read return: ``data``, ``due`` (the clock it must be on ``rd_data_valid``), ``en``.
    data_missing : Out(1), missing_addr : Out
        A write command's data did not come in time (one clock).
    refreshing : Out(1)
        :class:`BankTiming`'s.

    Clock domain ``sync`` (clk0).
    """

    def __init__(self, *, addr_width=MIG.ADDR_WIDTH, data_width=MIG.DATA_WIDTH, latency_bits=6, data_grace=4,
                 trefi=MIG.TREFI_CLK, trfc=MIG.TRFC_CLK):
        self._addr_width, self._data_width, self._grace = addr_width, data_width, data_grace
        self._trefi, self._trfc = trefi, trfc
        mask_width = data_width // 8
        super().__init__({
            "enable": In(1), "latency": In(latency_bits), "now": In(32),
            "af_data": In(MIG.CMD_WIDTH + addr_width), "af_rdy": In(1), "af_en": Out(1),
            "wdf_data": In(mask_width + data_width), "wdf_level": In(16), "wdf_en": Out(1),
            "mem": Out(MemoryPortsSignature(addr_width, data_width)),
            "ret": Out(Signature({"data": Out(data_width), "due": Out(32), "en": Out(1)})),
            "data_missing": Out(1), "missing_addr": Out(addr_width), "refreshing": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.timing = timing = BankTiming(trefi=self._trefi, trfc=self._trfc)
        cmd, addr = self.af_data[:MIG.CMD_WIDTH], self.af_data[MIG.CMD_WIDTH:]
        is_read = cmd == MIG.CMD_READ
        second = Signal()                              # the clock of a burst's second word
        cur_addr, cur_read = Signal(self._addr_width), Signal()
        waited = Signal(range(self._grace + 2))
        data_ready = is_read | (self.wdf_level >= MIG.WORDS_PER_BURST)
        start = Signal()
        m.d.comb += [
            timing.enable.eq(self.enable), timing.boundary.eq(~second),
            timing.head.valid.eq(self.af_rdy & self.enable), timing.head.read.eq(is_read),
            timing.head.bank.eq(addr[MIG.COL_BITS + MIG.ROW_BITS:]),
            timing.head.row.eq(addr[MIG.COL_BITS:MIG.COL_BITS + MIG.ROW_BITS]),
            start.eq(timing.ready & data_ready), timing.start.eq(start),
            self.af_en.eq(start), self.refreshing.eq(timing.refreshing),
        ]
        with m.If(start):
            m.d.sync += [second.eq(1), cur_addr.eq(addr), cur_read.eq(is_read), waited.eq(0)]
        with m.Elif(second):
            m.d.sync += second.eq(0)
        with m.Elif(timing.ready & ~data_ready):
            m.d.sync += waited.eq(waited + (waited <= self._grace))
            m.d.comb += [self.data_missing.eq(waited == self._grace), self.missing_addr.eq(addr)]

        # the word of this clock: the head's first word as its burst starts, the second word the clock after
        word_addr = Mux(second, cur_addr | 2, addr)
        word_read = Mux(second, cur_read, is_read)
        active = start | second
        dw = self._data_width
        m.d.comb += [
            self.mem.raddr.eq(word_addr), self.mem.waddr.eq(word_addr),
            self.mem.wdata.eq(self.wdf_data[:dw]), self.mem.wmask.eq(self.wdf_data[dw:]),
            self.mem.we.eq(active & ~word_read), self.wdf_en.eq(active & ~word_read),
        ]
        returning = Signal()                           # a read word comes out of the memory this clock
        m.d.sync += returning.eq(active & word_read)
        m.d.comb += [self.ret.en.eq(returning), self.ret.data.eq(self.mem.rdata),
                     self.ret.due.eq(self.now + self.latency - 2)]
        return m
