"""Dual-clock frame buffer: one grey image, written by a camera, read by the display side (thesis 4.2.1).

A simple dual-port RAM of ``geometry.buf_depth`` words of ``geometry.grey_bits`` bits, addressed
``A = y * buf_width + x`` (thesis eq. 4.1). 400 x 300 x 5 bits by default: 120,000 words.

Mapping: the word is stored as ``grey_bits`` one-bit-wide memories (``amaranth.lib.memory.Memory``, one per bit,
same addresses, same ports). A 120,000 x 1 memory fits only one way into Virtex-5 block RAM: RAMB36 in its
32K x 1 aspect ratio, 4 blocks (or the same 4 blocks' worth as 8 RAMB18 16K x 1), so a synthesis tool cannot
take more than 4 x 5 = 20 RAMB36 for a frame buffer whatever it does -- a single 120,000 x 5 memory could be
built from 4K x 9 (30 blocks) or 8K x 4 (30 blocks) as well as 32K x 1 (20). It stays one Amaranth design that
Amaranth's simulator runs (tests/test_capture.py, tests/test_compositor.py).

Clock domains: the write port is in ``write_domain`` (a camera's PCLK domain), the read port in
``read_domain`` (the pixel clock). The two ports share no logic, so no synchroniser is needed; a read of a word
being written in the same instant returns either value (as the BRAM does).

Latency: read data appears on ``read.data`` one ``read_domain`` clock after ``read.addr`` (synchronous read,
always enabled). A write is committed on the ``write_domain`` clock edge where ``write.en`` is high.

Safety: a write whose ``write.addr`` is not below the depth is dropped, so no address from a malformed camera
stream can land outside the buffer, whatever the capture logic upstream does.
"""

from amaranth import Cat, Module
from amaranth.lib import wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from spec.sensor import SENSOR
from hdl.signature import ParametricSignature

__all__ = ["FrameBufferReadSignature", "FrameBufferWriteSignature", "FrameBuffer"]


class FrameBufferReadSignature(ParametricSignature):
    """A frame buffer's read port as the reader sees it: ``addr`` out (``geometry.addr_bits``), ``data`` in
    (``geometry.grey_bits``), valid one read-domain clock after ``addr``. A reader has ``Out(sig)``, the
    buffer ``In(sig)``. Two signatures are equal when their widths are."""

    def __init__(self, geometry):
        super().__init__({"addr": Out(geometry.addr_bits), "data": In(geometry.grey_bits)}, geometry=geometry)


class FrameBufferWriteSignature(ParametricSignature):
    """A frame buffer's write port as the writer sees it: ``addr``, ``data`` and ``en`` out; the word is written
    on the write-domain clock edge where ``en`` is high. A writer has ``Out(sig)``, the buffer ``In(sig)``."""

    def __init__(self, geometry):
        super().__init__({"addr": Out(geometry.addr_bits), "data": Out(geometry.grey_bits), "en": Out(1)},
                         geometry=geometry)


class FrameBuffer(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
        ``buf_depth`` words of ``grey_bits`` bits.
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
        w_en = self.write.en & (self.write.addr < depth)
        bits = []
        for i in range(self.geometry.grey_bits):
            init = [(word >> i) & 1 for word in self._init]
            m.submodules[f"bit{i}"] = memory = Memory(shape=1, depth=depth, init=init)
            write = memory.write_port(domain=self.write_domain)
            read = memory.read_port(domain=self.read_domain)
            m.d.comb += [
                write.addr.eq(self.write.addr), write.data.eq(self.write.data[i]), write.en.eq(w_en),
                read.addr.eq(self.read.addr),
            ]
            bits.append(read.data)
        m.d.comb += self.read.data.eq(Cat(*bits))
        return m
