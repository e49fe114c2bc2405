"""RowTagTracker: which camera frame last started writing each frame-buffer row, and which row is being written
now (consistency at the tear; docs/capture.md "Frame after frame").

A camera's capture (:class:`hdl.capture.CameraCapture`, in the camera's domain) strobes ``frame_start`` at a frame's
start and ``row_start`` / ``row_end`` before the first and after the last write of every kept buffer row. Each strobe
is carried into ``pix`` by its own :class:`amaranth.lib.cdc.PulseSynchronizer` (as :mod:`hdl.frame_skew` does).
There:

* a frame start is reported on ``pair.started`` and the frame takes ``pair.tag`` (from
  :class:`hdl.frame_pairing.FramePairing`, which gives the two cameras' frames that belong together one tag; a
  tracker alone behind a pairing whose other camera never starts counts its frame starts): the tag of the frame in
  progress;
* the row index counts the row starts since the frame start, saturating at ``height`` (= no row: a row start
  beyond the buffer writes nothing and changes nothing);
* at a row start the frame's tag is written into a memory of ``height`` tags at the row index, and that row
  becomes the row in progress (``busy``) until the row's end or the next frame start.

Strobes that reach ``pix`` in the same clock take effect in the order of a well-formed stream: ``row_end`` (of the
row before), ``frame_start``, ``row_start`` (of the new frame's first row).
"""

from amaranth import Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.cdc import PulseSynchronizer
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from hdl.depth.ports import RowTagReadSignature
from hdl.frame_pairing import FramePairSignature
from spec.sensor import ROW_TAG_BITS, SENSOR

__all__ = ["RowTagTracker", "ROW_TAG_LATENCY"]

#: Pix clocks from a strobe's toggle (the camera clock edge ending the strobe's clock) to the edge of the answer
#: that reflects it, at most: up to 1 clock to the first synchroniser stage's sampling edge (+1 if it is
#: metastable), the second stage, the tracker's state registers, the answer register.
ROW_TAG_LATENCY = 5


class RowTagTracker(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
        The buffer: ``buf_height`` rows of tags.
    bits : int
        Tag width (the frame count mod ``2**bits``).
    cam_domain : str
        The domain of the capture's strobes.
    pix_domain : str
        The domain of the tags and the read port.

    Attributes
    ----------
    frame_start, row_start, row_end : ``In(1)``, ``cam_domain``
        The capture's strobes (:data:`hdl.capture.CaptureStatusSignature`).
    read : ``In(RowTagReadSignature(buf_height, bits))``, ``pix_domain``
        ``row`` in; one clock later ``tag`` (the tag written at that row's last start, 0 before any) and ``busy``
        (that row is the row in progress), both as the tracker's state was in the request's clock (before that
        clock's update). The tags are a distributed RAM (asynchronous read, registered answer).
    pair : ``Out(FramePairSignature(bits))``, ``pix_domain``
        ``started``: the frame start, synchronised (a one-clock pulse); ``tag``: the tag that frame takes, read in
        the same clock (combinational in the pairing).
    frame_tag : ``Out(bits)``, ``pix_domain``
        The tag of the frame in progress (``pair.tag`` at the last frame start; 0 after reset).

    Clock domains: ``cam_domain`` (the three synchronisers' toggles) and ``pix_domain`` (everything else).
    Latency: every answer registered on a pix edge at least :data:`ROW_TAG_LATENCY` pix clocks after the camera
    edge that ends a strobe's clock reflects that strobe (4 when the first synchroniser stage is not
    metastable), and none registered less than 3 pix clocks after it. With the capture's latencies (row_start
    2 camera clocks before the row's first write, row_end 1 after its last), at 148.5 MHz pix and 80 MHz PCLK
    ``busy`` and the new tag are answered at most 2 pix clocks after the row's first write, and ``busy`` until at
    least 4 pix clocks after its last.

    Raises
    ------
    ValueError
        ``bits`` below 1.
    """

    def __init__(self, geometry=SENSOR, bits=ROW_TAG_BITS, cam_domain="cam_a", pix_domain="pix"):
        if bits < 1:
            raise ValueError(f"bits must be at least 1, got {bits}")
        self.geometry, self.bits = geometry, bits
        self.cam_domain, self.pix_domain = cam_domain, pix_domain
        height = geometry.buf_height
        super().__init__({
            "frame_start": In(1), "row_start": In(1), "row_end": In(1),
            "read": In(RowTagReadSignature(height, bits)),
            "pair": Out(FramePairSignature(bits)),
            "frame_tag": Out(bits),
        })

    def elaborate(self, platform):
        m = Module()
        height = self.geometry.buf_height
        pix = m.d[self.pix_domain]
        strobes = {}
        for name in ("frame_start", "row_start", "row_end"):
            m.submodules[f"sync_{name}"] = ps = PulseSynchronizer(i_domain=self.cam_domain, o_domain=self.pix_domain)
            m.d.comb += ps.i.eq(getattr(self, name))
            strobes[name] = ps.o
        frame_start, row_start, row_end = strobes["frame_start"], strobes["row_start"], strobes["row_end"]

        m.submodules.tags = tags = Memory(shape=self.bits, depth=height, init=[])
        write = tags.write_port(domain=self.pix_domain)
        read = tags.read_port(domain="comb")      # asynchronous read + output register: distributed RAM, no BRAM

        frame = self.frame_tag
        index = Signal(range(height + 1))       # row starts since the frame start, saturating at height
        busy, busy_row = Signal(), Signal(range(height))
        tag_now = Signal(self.bits)             # the frame tag after this clock's frame start
        index_now = Signal(range(height + 1))   # the row index after this clock's frame start
        m.d.comb += [
            self.pair.started.eq(frame_start),
            tag_now.eq(Mux(frame_start, self.pair.tag, frame)),
            index_now.eq(Mux(frame_start, 0, index)),
        ]
        with m.If(frame_start):
            pix += [frame.eq(tag_now), index.eq(0)]
        with m.If(row_start & (index_now != height)):
            pix += [index.eq(index_now + 1), busy.eq(1), busy_row.eq(index_now)]
        with m.Elif(frame_start | row_end):
            pix += busy.eq(0)
        m.d.comb += [
            write.addr.eq(index_now),
            write.data.eq(tag_now),
            write.en.eq(row_start & (index_now != height)),
            read.addr.eq(self.read.row),
        ]
        pix += [self.read.tag.eq(read.data), self.read.busy.eq(busy & (busy_row == self.read.row))]
        return m
