"""ReadArbiter: one frame-buffer read port shared by the compositor (priority) and the depth engine."""

from amaranth import Module, Mux
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.depth.ports import SharedReadSignature
from hdl.frame_buffer import FrameBufferReadSignature
from spec.sensor import SENSOR

__all__ = ["ReadArbiter"]


class ReadArbiter(wiring.Component):
    """Fixed-priority sharing of a frame buffer's one read port, without a second copy of the buffer.

    The display reads in every clock it raises ``display.request`` and is always granted: it never misses a
    pixel. The engine's ``engine.request`` is granted in the clocks the display leaves free (``engine.grant``
    = not ``display.request``, combinationally, as :class:`hdl.depth.SharedReadSignature` specifies). The
    buffer's address is the granted reader's; its data (one clock later) goes to both readers, each of which
    keeps it only for a read it was granted.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`

    Attributes
    ----------
    display, engine : ``In(SharedReadSignature(geometry))``
    buffer : ``Out(FrameBufferReadSignature(geometry))``

    Clock domain: none (combinational).
    """

    def __init__(self, geometry=SENSOR):
        self.geometry = geometry
        super().__init__({
            "display": In(SharedReadSignature(geometry)),
            "engine": In(SharedReadSignature(geometry)),
            "buffer": Out(FrameBufferReadSignature(geometry)),
        })

    def elaborate(self, platform):
        m = Module()
        display, engine = self.display, self.engine
        m.d.comb += [
            display.grant.eq(1),
            engine.grant.eq(~display.request),
            self.buffer.addr.eq(Mux(display.request, display.port.addr, engine.port.addr)),
            display.port.data.eq(self.buffer.data),
            engine.port.data.eq(self.buffer.data),
        ]
        return m
