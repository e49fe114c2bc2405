"""``MemoryWindow``: the DDR2 contents the MIG model keeps, a window of the part's address space."""

from amaranth.hdl import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from spec.memory import MIG

__all__ = ["MemoryWindow", "MemoryPortsSignature", "check_window"]


def check_window(base, words):
    """Raise ``ValueError`` unless the window ``base`` .. ``base + words - 1`` (64-bit memory words) is
    burst-aligned, non-empty and within the part."""
    if base % MIG.BURST_LENGTH or words % MIG.BURST_LENGTH or words <= 0 \
            or base < 0 or base + words > MIG.MEMORY_WORDS:
        raise ValueError(f"memory window {base}+{words} words: must be burst-aligned, non-empty and within "
                         f"the part's {MIG.MEMORY_WORDS} words")


class MemoryPortsSignature(wiring.Signature):
    """The memory window's ports as its user (the controller) drives them: ``raddr`` (its word on ``rdata`` the
    next clock), ``waddr``, ``wdata``, ``wmask`` (a 1 leaves its byte unwritten), ``we``."""

    def __init__(self, addr_width=MIG.ADDR_WIDTH, data_width=MIG.DATA_WIDTH):
        super().__init__({
            "raddr": Out(addr_width), "rdata": In(data_width),
            "waddr": Out(addr_width), "wdata": Out(data_width), "wmask": Out(data_width // 8), "we": Out(1)})


class MemoryWindow(wiring.Component):
    """The memory words ``base`` .. ``base + words - 1`` (64-bit words, ``app_af_addr``'s unit) as 128-bit user
    words, each stored as it is written and read: {the falling-edge 64 bits, the rising-edge 64 bits}. User word
    ``i`` of the burst at ``addr`` covers memory words ``addr + 2 i`` (rise) and ``addr + 2 i + 1`` (fall).
    Contents start at 0 (the board's DRAM holds garbage after a reset).

    Parameters
    ----------
    base, words : int
        The window, in 64-bit memory words; both multiples of the burst (4).
    addr_width, data_width : int
        ``app_af_addr``'s and a user word's widths.

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
        ``base`` or ``words`` not burst-aligned, ``words`` 0, or the window beyond the part.
    """

    def __init__(self, *, base, words, addr_width=MIG.ADDR_WIDTH, data_width=MIG.DATA_WIDTH):
        check_window(base, words)
        self._base, self._words = base, words
        self._data_width = data_width
        super().__init__({"port": In(MemoryPortsSignature(addr_width, data_width))})

    def _index(self, addr):
        """Whether ``addr`` is in the window, and its user word's index in the storage."""
        inside = (addr >= self._base) & (addr < self._base + self._words)
        return inside, (addr - self._base)[1:]

    def elaborate(self, platform):
        m = Module()
        m.submodules.storage = storage = Memory(shape=self._data_width, depth=self._words // 2, init=[])
        write = storage.write_port(granularity=8)
        read = storage.read_port(transparent_for=(write,))
        port = self.port
        w_inside, w_index = self._index(port.waddr)
        r_inside, r_index = self._index(port.raddr)
        r_valid = Signal()
        m.d.sync += r_valid.eq(r_inside)
        m.d.comb += [
            write.addr.eq(w_index), write.data.eq(port.wdata),
            write.en.eq(~port.wmask & (w_inside & port.we).replicate(self._data_width // 8)),
            read.addr.eq(r_index),
            port.rdata.eq(read.data & r_valid.replicate(self._data_width)),
        ]
        return m
