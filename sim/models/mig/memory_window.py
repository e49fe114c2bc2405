"""``MemoryWindow``: the DDR2 contents the MIG model keeps, a window of the part's address space."""

from amaranth.hdl import ClockSignal, Instance, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from spec.memory import MIG

__all__ = ["MemoryWindow", "MemoryPortsSignature", "check_window", "window_index", "STORAGE_MODULE",
           "STORAGE_VERILOG"]

#: The Verilog module of the compiled backends' storage (``storage="verilog"``): the same array as the Amaranth
#: Memory of ``storage="memory"`` -- zeros at start, a read word one clock after its address (the old word when
#: it is written on that clock), byte-enabled writes -- written by hand because Amaranth spells a memory's
#: initial contents out bit by bit when it exports it (minutes at the full window). A harness appends this text
#: to the exported Verilog of any design holding the model (``export_verilog(...) + STORAGE_VERILOG``).
STORAGE_MODULE = "mig_model_storage"
STORAGE_VERILOG = f"""
// The MIG model's memory window (sim/models/mig/memory_window.py): simulation only.
module {STORAGE_MODULE} #(parameter DEPTH = 1, parameter ABITS = 1, parameter WIDTH = 128) (
  input clk,
  input [ABITS-1:0] raddr,
  output reg [WIDTH-1:0] rdata,
  input [ABITS-1:0] waddr,
  input [WIDTH-1:0] wdata,
  input [WIDTH/8-1:0] wen
);
  reg [WIDTH-1:0] words [0:DEPTH-1];
  integer i, b;
  initial begin
    for (i = 0; i < DEPTH; i = i + 1) words[i] = {{WIDTH{{1'b0}}}};
    rdata = {{WIDTH{{1'b0}}}};
  end
  always @(posedge clk) begin
    rdata <= words[raddr];
    for (b = 0; b < WIDTH / 8; b = b + 1)
      if (wen[b]) words[waddr][8 * b +: 8] <= wdata[8 * b +: 8];
  end
endmodule
"""


def check_storage(storage):
    """Raise ``ValueError`` for a storage other than ``"memory"`` and ``"verilog"``."""
    if storage not in ("memory", "verilog"):
        raise ValueError(f"storage {storage!r}: must be 'memory' or 'verilog'")


def check_window(base, words, banks=1):
    """Raise ``ValueError`` unless the window ``base`` .. ``base + words - 1`` (64-bit memory words) is
    burst-aligned, non-empty and within the part, and, over ``banks`` > 1 banks, within a bank (1 .. 4)."""
    if base % MIG.BURST_LENGTH or words % MIG.BURST_LENGTH or words <= 0 \
            or base < 0 or base + words > MIG.MEMORY_WORDS:
        raise ValueError(f"memory window {base}+{words} words: must be burst-aligned, non-empty and within "
                         f"the part's {MIG.MEMORY_WORDS} words")
    if not 1 <= banks <= MIG.BANKS or (banks > 1 and base + words > MIG.BANK_WORDS):
        raise ValueError(f"memory window {base}+{words} words in {banks} banks: 1 .. {MIG.BANKS} banks, a window "
                         f"of several within a bank's {MIG.BANK_WORDS} words")


def in_window(address, base, words, banks=1):
    """Whether memory word ``address`` lies in the window (Python integers)."""
    if banks == 1:
        return base <= address < base + words
    bank, offset = divmod(address, MIG.BANK_WORDS)
    return bank < banks and base <= offset < base + words


def window_index(addr, base, words, banks=1):
    """Gateware: whether the address ``addr`` (a value) lies in the window -- ``base`` .. ``base + words - 1``,
    or with ``banks`` > 1 the same words of each of banks 0 .. ``banks - 1`` -- and its user word's index in a
    storage of ``banks * words // 2`` user words (the banks' windows one after another)."""
    if banks == 1:
        inside = addr < base + words
        if base:                                        # (no constant comparison: a Verilator warning)
            inside &= addr >= base
        return inside, (addr - base)[1:]
    bank_bits = (MIG.BANK_WORDS - 1).bit_length()
    offset, bank = addr[:bank_bits], addr[bank_bits:]
    inside = (bank < banks) & (offset < base + words)
    if base:
        inside &= offset >= base
    return inside, bank * (words // 2) + (offset - base)[1:]


def check_init(base, words, storage, init, banks=1):
    """Initial contents (memory word address -> value) as a dict; ``ValueError`` for a word outside the window
    or contents with a storage other than ``"memory"``."""
    init = dict(init or {})
    if init and storage != "memory":
        raise ValueError("initial contents need the \"memory\" storage")
    if any(not in_window(a, base, words, banks) for a in init):
        raise ValueError(f"initial contents outside the window {base}+{words} ({banks} banks)")
    return init


def storage_index(address, base, words, banks=1):
    """The storage index of memory word ``address`` in the window (Python integers): its user word's index
    times 2, plus 1 for the falling-edge half."""
    if banks == 1:
        return address - base
    bank, offset = divmod(address, MIG.BANK_WORDS)
    return bank * words + offset - base


class MemoryPortsSignature(wiring.Signature):
    """The memory window's ports as its user (the controller) drives them: ``raddr`` (its word on ``rdata`` the
    next clock), ``waddr``, ``wdata``, ``wmask`` (a 1 leaves its byte unwritten), ``we``."""

    def __init__(self, addr_width=MIG.ADDR_WIDTH, data_width=MIG.DATA_WIDTH):
        super().__init__({
            "raddr": Out(addr_width), "rdata": In(data_width),
            "waddr": Out(addr_width), "wdata": Out(data_width), "wmask": Out(data_width // 8), "we": Out(1)})


class MemoryWindow(wiring.Component):
    """The memory words ``base`` .. ``base + words - 1`` (64-bit words, ``app_af_addr``'s unit) -- with
    ``banks`` > 1 those words of each of banks 0 .. ``banks - 1`` (bank ``k`` is the ``MIG.BANK_WORDS`` words from
    ``k * MIG.BANK_WORDS``), for a design that spreads its buffers over the banks -- as 128-bit user words, each
    stored as it is written and read: {the falling-edge 64 bits, the rising-edge 64 bits}. User word ``i`` of the
    burst at ``addr`` covers memory words ``addr + 2 i`` (rise) and ``addr + 2 i + 1`` (fall). Contents start at 0
    (the board's DRAM holds garbage after a reset), or with ``"memory"`` storage at ``init``.

    Parameters
    ----------
    base, words : int
        The window, in 64-bit memory words; both multiples of the burst (4).
    banks : int
        1: the window is ``base`` .. ``base + words - 1`` of the part; 2 .. 4: the same words within each of the
        first ``banks`` banks (then within a bank).
    addr_width, data_width : int
        ``app_af_addr``'s and a user word's widths.
    storage : str
        ``"memory"``: an Amaranth Memory (Amaranth's simulator; a small window anywhere); ``"verilog"``: an
        instance of :data:`STORAGE_MODULE`, whose text :data:`STORAGE_VERILOG` the compiled backends append
        (the full window).
    init : dict
        With ``"memory"`` storage: initial contents, 64-bit memory word address (inside the window) -> its value
        (byte ``k`` of the word in bits ``8 k .. 8 k + 7``); other words 0.

    Members
    -------
    port : In(MemoryPortsSignature)
        ``raddr``: the 64-bit-word address of a user word (even); its data is on ``rdata`` the next clock (0
        outside the window). ``waddr``, ``wdata``, ``wmask``, ``we``: a user word written; ``wmask`` bit ``i``
        set leaves byte ``i`` unwritten. Outside the window nothing is written.

    Clock domain ``sync`` (clk0).

    Raises
    ------
    ValueError
        ``base`` or ``words`` not burst-aligned, ``words`` 0, the window beyond the part, an unknown
        ``storage``; ``init`` outside the window or with ``"verilog"`` storage.
    """

    def __init__(self, *, base, words, banks=1, addr_width=MIG.ADDR_WIDTH, data_width=MIG.DATA_WIDTH,
                 storage="memory", init=None):
        check_window(base, words, banks)
        check_storage(storage)
        self._init = check_init(base, words, storage, init, banks)
        self._base, self._words, self._banks, self._storage = base, words, banks, storage
        self._data_width = data_width
        super().__init__({"port": In(MemoryPortsSignature(addr_width, data_width))})

    def _index(self, addr):
        """Whether ``addr`` is in the window, and its user word's index in the storage."""
        return window_index(addr, self._base, self._words, self._banks)

    def elaborate(self, platform):
        m = Module()
        depth, width = self._banks * self._words // 2, self._data_width
        port = self.port
        w_inside, w_index = self._index(port.waddr)
        r_inside, r_index = self._index(port.raddr)
        raddr, waddr = Signal(range(depth)), Signal(range(depth))
        wen, rdata = Signal(width // 8), Signal(width)
        r_valid = Signal()
        m.d.sync += r_valid.eq(r_inside)
        m.d.comb += [
            raddr.eq(r_index), waddr.eq(w_index),
            wen.eq(~port.wmask & (w_inside & port.we).replicate(width // 8)),
            port.rdata.eq(rdata & r_valid.replicate(width)),
        ]
        if self._storage == "memory":
            half = width // 2                           # a user word: {fall (odd word), rise (even word)}
            init = [0] * depth
            for addr, value in self._init.items():
                i = storage_index(addr, self._base, self._words, self._banks)
                init[i >> 1] |= value << (half * (i & 1))
            m.submodules.storage = storage = Memory(shape=width, depth=depth, init=init)
            write, read = storage.write_port(granularity=8), storage.read_port()
            m.d.comb += [write.addr.eq(waddr), write.data.eq(port.wdata), write.en.eq(wen),
                         read.addr.eq(raddr), rdata.eq(read.data)]
        else:
            m.submodules.storage = Instance(
                STORAGE_MODULE, p_DEPTH=depth, p_ABITS=len(raddr), p_WIDTH=width, i_clk=ClockSignal("sync"),
                i_raddr=raddr, o_rdata=rdata, i_waddr=waddr, i_wdata=port.wdata, i_wen=wen)
        return m
