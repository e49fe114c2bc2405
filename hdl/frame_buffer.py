"""Dual-clock frame buffer: one grey image, written by a camera, read by the display side (thesis 4.2.1).

A simple dual-port block RAM (``amaranth.lib.memory.Memory``) of ``geometry.buf_depth`` words of
``geometry.gray_bits`` bits, addressed ``A = y * buf_width + x`` (thesis eq. 4.1). 400 x 300 x 5 bits by
default: 120,000 words, which synthesis maps onto block RAM.

Clock domains: the write port is in ``write_domain`` (a camera's PCLK domain), the read port in
``read_domain`` (the pixel clock). The two ports share no logic, so no synchroniser is needed; a read of a word
being written in the same instant returns either value (as the BRAM does).

Latency: read data appears on ``read.data`` one ``read_domain`` clock after ``read.addr`` (synchronous read,
always enabled). A write is committed on the ``write_domain`` clock edge where ``write.en`` is high.

Safety: a write whose ``write.addr`` is not below the depth is dropped, so no address from a malformed camera
stream can land outside the buffer, whatever the capture logic upstream does.
"""

from amaranth import Module, unsigned
from amaranth.lib import wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from .params import SENSOR
from .signature import ParametricSignature

__all__ = ["FrameBufferReadSignature", "FrameBufferWriteSignature", "FrameBuffer"]


class FrameBufferReadSignature(ParametricSignature):
    """A frame buffer's read port as the reader sees it: ``addr`` out (``geometry.addr_bits``), ``data`` in
    (``geometry.gray_bits``), valid one read-domain clock after ``addr``. A reader has ``Out(sig)``, the
    buffer ``In(sig)``. Two signatures are equal when their widths are."""

    def __init__(self, geometry):
        super().__init__({"addr": Out(geometry.addr_bits), "data": In(geometry.gray_bits)}, geometry=geometry)


class FrameBufferWriteSignature(ParametricSignature):
    """A frame buffer's write port as the writer sees it: ``addr``, ``data`` and ``en`` out; the word is written
    on the write-domain clock edge where ``en`` is high. A writer has ``Out(sig)``, the buffer ``In(sig)``."""

    def __init__(self, geometry):
        super().__init__({"addr": Out(geometry.addr_bits), "data": Out(geometry.gray_bits), "en": Out(1)},
                         geometry=geometry)


class FrameBuffer(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    geometry : :class:`hdl.params.SensorGeometry`
        ``buf_depth`` words of ``gray_bits`` bits.
    write_domain, read_domain : str
        Clock domains of the write and the read port.
    init : sequence of int
        Initial contents (the rest is 0).

    Attributes
    ----------
    write : ``In(FrameBufferWriteSignature(geometry))``
    read : ``In(FrameBufferReadSignature(geometry))``
    """

    def __init__(self, geometry=SENSOR, *, write_domain="sync", read_domain="sync", init=()):
        self.geometry = geometry
        self.write_domain = write_domain
        self.read_domain = read_domain
        self._init = list(init)
        super().__init__({
            "write": In(FrameBufferWriteSignature(geometry)),
            "read": In(FrameBufferReadSignature(geometry)),
        })

    def elaborate(self, platform):
        m = Module()
        depth = self.geometry.buf_depth
        m.submodules.memory = memory = Memory(
            shape=unsigned(self.geometry.gray_bits), depth=depth, init=self._init)
        write = memory.write_port(domain=self.write_domain)
        read = memory.read_port(domain=self.read_domain)
        m.d.comb += [
            write.addr.eq(self.write.addr),
            write.data.eq(self.write.data),
            write.en.eq(self.write.en & (self.write.addr < depth)),
            read.addr.eq(self.read.addr),
            self.read.data.eq(read.data),
        ]
        return m
