"""The frame store's clients of the memory, as the arbiter (:class:`hdl.frame_store.arbiter.MemoryArbiter`) serves
them, all in the ``mem`` domain: a writer asks for one BL4 burst write at a time, a reader for one BL4 burst read."""

from amaranth.lib.wiring import In, Out

from hdl.signature import ParametricSignature
from spec.memory import MIG

from .layout import BURST_BYTES

__all__ = ["BurstWriteSignature", "BurstReadSignature"]


class BurstWriteSignature(ParametricSignature):
    """A burst writer's request, as the writer sees it: ``request`` (a burst is ready), ``addr`` (its memory word
    address, burst-aligned), ``data`` (its 32 bytes: the first user word in the low 128 bits), ``mask`` (a 1 masks
    a byte) out; ``grant`` in (the arbiter takes the burst in this clock: the writer offers the next one after it)."""

    def __init__(self, addr_width=MIG.ADDR_WIDTH):
        super().__init__({"request": Out(1), "addr": Out(addr_width), "data": Out(8 * BURST_BYTES),
                          "mask": Out(BURST_BYTES), "grant": In(1)}, addr_width=addr_width)


class BurstReadSignature(ParametricSignature):
    """A burst reader's request and its data, as the reader sees it: ``request``, ``addr`` out; ``grant`` in (the
    read command is issued in this clock); ``data`` and ``valid`` in: the reader's words, two a burst, in the
    order of its commands, each valid for one clock (no backpressure, as MIG's read data)."""

    def __init__(self, addr_width=MIG.ADDR_WIDTH, data_width=MIG.DATA_WIDTH):
        super().__init__({"request": Out(1), "addr": Out(addr_width), "grant": In(1),
                          "data": In(data_width), "valid": In(1)}, addr_width=addr_width, data_width=data_width)
