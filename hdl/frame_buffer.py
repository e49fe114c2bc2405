"""Dual-clock frame buffer: one grey image, written by a camera, read by the display side (thesis 4.2.1).

A simple dual-port block RAM (``amaranth.lib.memory.Memory``) of ``geometry.buf_depth`` words of
``geometry.gray_bits`` bits, addressed ``A = y * buf_width + x`` (thesis eq. 4.1). 400 x 300 x 5 bits by
default: 120,000 words, which synthesis maps onto block RAM.

Clock domains: the write port is in ``write_domain`` (a camera's PCLK domain), the read port in
``read_domain`` (the pixel clock). The two ports share no logic, so no synchroniser is needed; a read of a word
being written in the same instant returns either value (as the BRAM does).

Latency: read data appears on ``r_data`` one ``read_domain`` clock after ``r_addr`` (synchronous read,
``r_en`` always on). A write is committed on the ``write_domain`` clock edge where ``w_en`` is high.

Safety: a write whose ``w_addr`` is not below the depth is dropped, so no address from a malformed camera
stream can land outside the buffer, whatever the capture logic upstream does.
"""

from amaranth import Module, unsigned
from amaranth.lib import wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from .params import SENSOR

__all__ = ["FrameBuffer"]


class FrameBuffer(wiring.Component):
    def __init__(self, geometry=SENSOR, *, write_domain="sync", read_domain="sync", init=()):
        self.geometry = geometry
        self.write_domain = write_domain
        self.read_domain = read_domain
        self._init = list(init)
        addr_bits = geometry.addr_bits
        super().__init__({
            "w_addr": In(addr_bits),
            "w_data": In(geometry.gray_bits),
            "w_en": In(1),
            "r_addr": In(addr_bits),
            "r_data": Out(geometry.gray_bits),
        })

    def elaborate(self, platform):
        m = Module()
        depth = self.geometry.buf_depth
        m.submodules.memory = memory = Memory(
            shape=unsigned(self.geometry.gray_bits), depth=depth, init=self._init)
        write = memory.write_port(domain=self.write_domain)
        read = memory.read_port(domain=self.read_domain)
        m.d.comb += [
            write.addr.eq(self.w_addr),
            write.data.eq(self.w_data),
            write.en.eq(self.w_en & (self.w_addr < depth)),
            read.addr.eq(self.r_addr),
            self.r_data.eq(read.data),
        ]
        return m
