"""``MIGModel``: a simulation model of Xilinx MIG 3.x's DDR2 user interface (Virtex-5) with the memory behind it."""

from amaranth.hdl import Cat, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.mig_user import MIGUserSignature
from spec.memory import MIG

from .checker import ProtocolChecker
from .controller import Controller
from .memory_window import MemoryWindow, check_init, check_storage, check_window
from .read_return import ReadReturn
from .user_fifo import UserFifo
from .violations import ViolationSignature

__all__ = ["MIGModel", "memory_words", "layout_window", "READ_LATENCY_RANGE", "INIT_CLOCKS", "DATA_GRACE",
           "DEFAULT_WINDOW_WORDS", "AF_SLACK", "WDF_SLACK"]

#: The read latency's range in clk0 (docs/memory.md, "The read latency"): a read written into an idle controller
#: whose row is open returns its first word this many clocks later, drawn per run within the range.
READ_LATENCY_RANGE = (16, 32)
#: ``phy_init_done`` after the PHY's 200 us wait at 125 MHz (calibration adds more on the board).
INIT_CLOCKS = 200 * MIG.CLK0_HZ // 1_000_000
#: Clocks of ``app_af_afull`` high in which one more command per clock still fits: the 15 free entries it
#: rises with (synchronous FIFO36: the flag the clock after the write).
AF_SLACK = MIG.AFULL_OFFSET
#: The same for ``app_wdf_afull``: its multirate FIFO36 raises the flag a clock late, so a word written on that
#: clock leaves 14.
WDF_SLACK = MIG.AFULL_OFFSET - MIG.WDF_AFULL_ASSERT_CLK
#: Clocks a write command may wait at the head of the address FIFO for its burst's data (the model's; MIG does
#: not wait, docs/memory.md).
DATA_GRACE = 4
#: The default window: 2 cameras x 3 buffers x 800 x 600 bytes, in 64-bit memory words.
DEFAULT_WINDOW_WORDS = 2 * 3 * 800 * 600 // 8


def _check(af_depth, wdf_depth, latency_range, slacks, init_clocks, data_grace):
    lo, hi = latency_range
    if not 3 <= lo <= hi:
        raise ValueError(f"read latency range {latency_range}: must be 3 <= low <= high")
    for slack, most in zip(slacks, (AF_SLACK, WDF_SLACK)):
        if not 0 <= slack <= most:
            raise ValueError(f"almost-full slack {slack}: must be 0 .. {most} (MIG's room once almost full is seen)")
    if init_clocks < 1 or data_grace < 0:
        raise ValueError("init_clocks must be at least 1 and data_grace at least 0")
    for name, depth in (("af_depth", af_depth), ("wdf_depth", wdf_depth)):
        if depth & (depth - 1) or depth <= MIG.AFULL_OFFSET + 1:
            raise ValueError(f"{name} {depth}: must be a power of 2 above {MIG.AFULL_OFFSET + 1}")


class MIGModel(wiring.Component):
    """MIG's user interface as the design relies on it (docs/memory.md), for simulation only.

    The address FIFO and the write-data FIFO with their almost-full flags (:class:`UserFifo`); a controller taking
    one BL4 burst per command in order (:class:`Controller`) with open-row, turnaround and refresh costs
    (:class:`BankTiming`); the memory contents over a window of the part (:class:`MemoryWindow`); the read words in
    command order, each a fixed latency after its command plus the costs it waited for, without backpressure
    (:class:`ReadReturn`); ``phy_init_done`` after ``init_clocks``; and a protocol checker
    (:class:`ProtocolChecker`) whose first violation is held on ``violation`` for the harness to stop on.

    Parameters
    ----------
    af_depth, wdf_depth : int
        The FIFOs' depths (MIG: 1024 and 512); powers of 2 above ``MIG.AFULL_OFFSET`` + 1.
    window_base, window_words : int
        The memory window, in 64-bit memory words (burst-aligned).
    window_banks : int
        1: the window is ``window_base`` .. ``window_base + window_words - 1``; 2 .. 4: those words of each of the
        first ``window_banks`` banks (:class:`MemoryWindow`), for a design whose buffers lie in several banks.
    init_clocks : int
        Clocks from reset to ``phy_init_done``.
    latency_range : (int, int)
        The allowed read latencies (clocks); the run's own is the ``latency`` input.
    af_slack, wdf_slack : int
        Clocks of ``app_af_afull`` / ``app_wdf_afull`` high in which one more command / data word per clock is
        allowed: at most :data:`AF_SLACK` (15) / :data:`WDF_SLACK` (14), the room MIG's FIFOs have then.
    data_grace : int
        Clocks a write command may wait for its data at the head of the address FIFO.
    trefi, trfc : int
        Refresh interval and refresh cycle time (clocks).
    storage : str
        The memory window's storage (:class:`MemoryWindow`): ``"memory"`` (an Amaranth Memory: Amaranth's
        simulator) or ``"verilog"`` (for the compiled backends: append ``STORAGE_VERILOG`` to the exported
        Verilog; exporting the full window as an Amaranth Memory takes minutes).
    init : dict
        With ``"memory"`` storage: the window's initial contents, 64-bit memory word address -> value (byte ``k``
        in bits ``8 k`` up; :func:`memory_words` makes it from bytes); other words 0.

    Members
    -------
    user : In(MIGUserSignature)
        MIG's user interface, the controller's side (``wiring.connect`` it to the design's ``Out`` member).
    latency : In
        This run's read latency in clocks, within ``latency_range``: an input so a compiled simulation draws it
        per run without a rebuild; sampled until ``phy_init_done`` rises, fixed from then on (as calibration
        fixes MIG's). :func:`sim.models.mig.draw_latency` draws it from a seed.
    read_ready : In(1), init 1
        Simulation only: the design is ready to take a read word (MIG has no such signal; a harness whose design
        has a readiness drives it, so a read word the design cannot take is a violation).
    violation : Out(ViolationSignature)
        The first violation (:mod:`sim.models.mig.violations`).
    refreshing : Out(1)
        A refresh is in progress (for waveforms).

    Clock domain ``sync``: clk0 (a design whose MIG side is in its ``mem`` domain places the model there with
    ``DomainRenamer``). A reset starts the model afresh; the memory contents are kept (the board's are garbage
    after a reset: a design must not read what it did not write since).

    Raises
    ------
    ValueError
        Inconsistent parameters.
    """

    def __init__(self, *, af_depth=MIG.AF_DEPTH, wdf_depth=MIG.WDF_DEPTH, window_base=0,
                 window_words=DEFAULT_WINDOW_WORDS, window_banks=1, init_clocks=INIT_CLOCKS,
                 latency_range=READ_LATENCY_RANGE, af_slack=AF_SLACK, wdf_slack=WDF_SLACK, data_grace=DATA_GRACE,
                 trefi=MIG.TREFI_CLK, trfc=MIG.TRFC_CLK, storage="memory", init=None):
        _check(af_depth, wdf_depth, latency_range, (af_slack, wdf_slack), init_clocks, data_grace)
        check_window(window_base, window_words, window_banks)
        check_storage(storage)
        self.storage, self.init = storage, check_init(window_base, window_words, storage, init, window_banks)
        self.af_depth, self.wdf_depth = af_depth, wdf_depth
        self.window_base, self.window_words, self.window_banks = window_base, window_words, window_banks
        self.init_clocks, self.latency_range = init_clocks, tuple(latency_range)
        self.af_slack, self.wdf_slack, self.data_grace = af_slack, wdf_slack, data_grace
        self.trefi, self.trfc = trefi, trfc
        self._latency_bits = max(latency_range[1].bit_length(), 2)
        super().__init__({
            "user": In(MIGUserSignature()),
            "latency": In(self._latency_bits, init=latency_range[0]),
            "read_ready": In(1, init=1),
            "violation": Out(ViolationSignature()),
            "refreshing": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        user = self.user
        now = Signal(32)
        m.d.sync += now.eq(now + 1)
        init_count = Signal(range(self.init_clocks + 1))
        init_done = Signal()
        with m.If(~init_done):
            m.d.sync += init_count.eq(init_count + 1)
        m.d.comb += [init_done.eq(init_count == self.init_clocks), user.phy_init_done.eq(init_done)]
        latency = Signal(self._latency_bits, init=self.latency_range[0])
        with m.If(~init_done):
            m.d.sync += latency.eq(self.latency)

        m.submodules.af = af = UserFifo(width=MIG.CMD_WIDTH + MIG.ADDR_WIDTH, depth=self.af_depth)
        m.submodules.wdf = wdf = UserFifo(width=MIG.MASK_WIDTH + MIG.DATA_WIDTH, depth=self.wdf_depth,
                                          assert_latency=MIG.WDF_AFULL_ASSERT_CLK,
                                          deassert_latency=MIG.WDF_AFULL_DEASSERT_CLK)
        m.submodules.controller = ctrl = Controller(
            latency_bits=self._latency_bits, data_grace=self.data_grace, trefi=self.trefi, trfc=self.trfc)
        m.submodules.memory = memory = MemoryWindow(base=self.window_base, words=self.window_words,
                                                    banks=self.window_banks, storage=self.storage, init=self.init)
        m.submodules.read_return = ret = ReadReturn(depth=1 << (self.latency_range[1] + 4).bit_length())
        m.submodules.checker = checker = ProtocolChecker(
            window_base=self.window_base, window_words=self.window_words, window_banks=self.window_banks,
            af_slack=self.af_slack, wdf_slack=self.wdf_slack,
            latency_range=self.latency_range, wdf_depth=self.wdf_depth, latency_bits=self._latency_bits)

        m.d.comb += [
            af.w_data.eq(Cat(user.command.cmd, user.command.addr)), af.w_en.eq(user.command.wren),
            user.command.afull.eq(af.afull),
            wdf.w_data.eq(Cat(user.write.data, user.write.mask)), wdf.w_en.eq(user.write.wren),
            user.write.afull.eq(wdf.afull),
            ctrl.enable.eq(init_done), ctrl.latency.eq(latency), ctrl.now.eq(now),
            ctrl.af_data.eq(af.r_data), ctrl.af_rdy.eq(af.r_rdy), af.r_en.eq(ctrl.af_en),
            ctrl.wdf_data.eq(wdf.r_data), ctrl.wdf_level.eq(wdf.level), wdf.r_en.eq(ctrl.wdf_en),
            ret.now.eq(now), user.read.data.eq(ret.data), user.read.valid.eq(ret.valid),
            self.refreshing.eq(ctrl.refreshing),
            checker.init_done.eq(init_done), checker.write_wren.eq(user.write.wren),
            checker.af_afull.eq(af.afull), checker.wdf_afull.eq(wdf.afull),
            checker.read_valid.eq(ret.valid), checker.read_ready.eq(self.read_ready),
            checker.latency.eq(latency), checker.data_missing.eq(ctrl.data_missing),
            checker.missing_addr.eq(ctrl.missing_addr), checker.now.eq(now),
        ]
        wiring.connect(m, ctrl.mem, memory.port)
        wiring.connect(m, ctrl.ret, ret.push)
        wiring.connect(m, wiring.flipped(self.violation), checker.violation)
        m.d.comb += [checker.command.cmd.eq(user.command.cmd), checker.command.addr.eq(user.command.addr),
                     checker.command.wren.eq(user.command.wren)]
        return m


def layout_window(layout):
    """``MIGModel``'s window keywords for a frame store's buffers (:class:`hdl.frame_store.layout.FrameStoreLayout`:
    the same words from ``base`` in each bank it uses)."""
    return dict(window_base=layout.base, window_words=layout.bank_words, window_banks=layout.banks_used)


def memory_words(contents):
    """``MIGModel``'s ``init`` from bytes: ``contents`` maps a byte address to its byte; the words they fall in
    (64-bit memory words, ``app_af_addr``'s unit), the other bytes of a word 0."""
    words = {}
    for address, value in contents.items():
        words[address // 8] = words.get(address // 8, 0) | (int(value) & 0xFF) << (8 * (address % 8))
    return words
