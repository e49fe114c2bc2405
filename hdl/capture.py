"""CameraCapture: one camera's capture path, from the sensor pins to the frame-buffer write port (thesis 4.2).

Pipeline (all in one clock domain, the camera's PCLK)::

    data/lv/fv pins -> input registers -> frame tracker (FV edges, row counter)
                    -> RGB565Assembler (byte pairs, column) -> Grey -> Downscaler -> write        ("keep")
                                                            -> AveragingDownscaler -> write         ("average")

``geometry.downscale`` chooses the block: ``"keep"`` (the thesis's capture, 5-bit grey: the pixel at (scale i,
scale j) of each block, :class:`~hdl.downscaler.Downscaler`) or ``"average"`` (8-bit grey: the rounded mean of the
whole block, :class:`~hdl.averaging_downscaler.AveragingDownscaler`, docs/capture.md "The averaging capture").

Counting rules (spec "Camera driver"; docs/capture.md): a frame starts at a FV rising edge and ends when FV
falls; inside it, column = byte count / 2 within LV, row = count of LV falling edges. Outside a frame
everything is ignored (LV without FV), and after reset the block waits for a FV rising edge (a frame already
in progress at reset is ignored). Keeping, pixel (column, row) is written, when both are multiples of ``scale`` and
fall inside the configured size, at ``A = (row/scale) * buf_width + column/scale``; averaging, the block (x, y) is
written at ``A = y * buf_width + x`` with its last pixel (column ``scale x + scale - 1``, row ``scale y + scale - 1``)
when it lies inside the configured size. Counters saturate, so a
long line, extra lines or a stream without LV gaps can never wrap onto a valid address: no write ever lands
outside the buffer or outside the pixel the counting rules give it. A malformed frame only affects itself:
every FV rising edge restarts the counters.

Ports: ``pins`` (:data:`CameraSignature`: ``data[8]``, ``lv``, ``fv``, sampled on the rising PCLK edge); the
frame-buffer write port ``write``; ``status`` (:data:`CaptureStatusSignature`): ``frame_start`` (one-cycle strobe,
a frame begins), ``frame_done`` (one-cycle strobe, FV fell on a frame that had started) with ``frame_ok`` (that
frame had exactly ``height`` lines of exactly ``2 * width`` bytes), ``frame_count`` (frames completed, wrapping),
``in_frame``, ``row_start`` / ``row_end`` (one-cycle strobes around each kept buffer row's writes: the LV-high run
of a sensor row ``r`` with ``r < scale * buf_height`` and ``r % scale == 0`` (keeping) or ``r % scale == scale - 1``
(averaging: the block's last row, the one that writes) starts / ends; a run cut by the end of the frame ends there).

Clock domain: ``sync`` (the parent uses ``DomainRenamer`` to place it in ``cam_a`` / ``cam_b``).
Latency (keeping): ``write.en`` is high in the 3rd clock cycle after the rising edge that sampled a kept pixel's
second byte (input register, assembler, downscaler register); the memory commits it on the rising edge that ends
that cycle. ``frame_start``/``frame_done`` come 1 cycle after the edge that sampled the FV change, ``row_start``
1 cycle after the edge that sampled the run's first byte (at least 2 cycles before the row's first ``write.en``),
``row_end`` 2 cycles after the edge that sampled the run's end (LV or FV low: 1 cycle after the row's last
``write.en``). Averaging: every one of these :data:`EXTRA_LATENCY` (2) cycles later (the averaging downscaler's
``LATENCY`` of 3 clocks against the Downscaler's 1; the whole status goes through as many registers), so the
writes and the status keep the same order and spacing.
A stream should therefore give at least 3 (averaging: 5) PCLK edges after a frame's last byte before PCLK stops
(the MT9D112's blanking does).
"""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.averaging_downscaler import AveragingDownscaler, LATENCY as AVERAGING_LATENCY, check_geometry as check_average
from hdl.delay import delayed
from hdl.downscaler import Downscaler, check_geometry as check_downscale
from hdl.frame_buffer import FrameBufferWriteSignature
from hdl.grey import Grey
from spec.sensor import SENSOR
from hdl.rgb565_assembler import RGB565Assembler, check_width

__all__ = ["CameraSignature", "CaptureStatusSignature", "CameraCapture", "check_geometry", "EXTRA_LATENCY"]

#: Clocks the averaging capture's writes and status come later than the thesis's capture's (its downscaler's
#: latency over the Downscaler's one clock).
EXTRA_LATENCY = AVERAGING_LATENCY - 1

#: A camera's parallel video bus as the sensor drives it (MT9D112 DOUT[7:0], LINE_VALID, FRAME_VALID). The pins
#: change on PCLK's falling edge and are sampled on its rising edge: PCLK is the clock of the receiving domain
#: (``cam_a``, ``cam_b``), not a member.
CameraSignature = wiring.Signature({"data": Out(8), "lv": Out(1), "fv": Out(1)})

#: What a capture reports, in its camera's domain: strobes at a frame's start and end, whether the frame that
#: ended was whole, frames completed (wrapping), and whether a frame is in progress.
CaptureStatusSignature = wiring.Signature({
    "frame_start": Out(1), "frame_done": Out(1), "frame_ok": Out(1), "frame_count": Out(16), "in_frame": Out(1),
    "row_start": Out(1), "row_end": Out(1),
})


def check_geometry(geometry):
    """``ValueError`` unless a capture can be built for ``geometry``: keeping (``downscale = "keep"``), 5 bits of
    grey and a geometry the downscaler (:func:`hdl.downscaler.check_geometry`) takes; averaging, one the averaging
    downscaler (:func:`hdl.averaging_downscaler.check_geometry`: 8 bits of grey) takes; either way a width the
    assembler (:func:`hdl.rgb565_assembler.check_width`) takes."""
    if geometry.downscale == "average":
        check_average(geometry)
    else:
        if geometry.grey_bits != 5:
            raise ValueError("the spec's grey conversion gives 5 bits; geometry.grey_bits must be 5")
        check_downscale(geometry)
    check_width(geometry.width)


class CameraCapture(wiring.Component):
    """One camera's capture, pins to frame-buffer write port; see the module docstring for the counting rules,
    the status and the latency.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
        Sensor and buffer size and the downscale (``grey_bits`` must be 5 keeping, what the spec's grey conversion
        gives, and 8 averaging).
    r_byte_first : bool
        The byte order the sensor is configured for.

    Attributes
    ----------
    pins : ``In(CameraSignature)``
        Sampled on the rising PCLK edge (this block's domain).
    write : ``Out(FrameBufferWriteSignature(geometry))``
    status : ``Out(CaptureStatusSignature)``

    Raises
    ------
    ValueError
        A geometry :func:`check_geometry` rejects.
    """

    def __init__(self, geometry=SENSOR, r_byte_first=True):
        check_geometry(geometry)
        self.geometry = geometry
        self.r_byte_first = r_byte_first
        super().__init__({
            "pins": In(CameraSignature),
            "write": Out(FrameBufferWriteSignature(geometry)),
            "status": Out(CaptureStatusSignature),
        })

    def elaborate(self, platform):
        m = Module()
        g = self.geometry
        averaging = g.downscale == "average"
        m.submodules.assembler = assembler = RGB565Assembler(g.width, r_byte_first=self.r_byte_first)
        # The assembler's column counts 0 .. width (saturating at width).
        if averaging:
            m.submodules.averager = downscaler = AveragingDownscaler(g, column_bits=g.width.bit_length(),
                                                                     row_bits=g.height.bit_length())
        else:
            m.submodules.grey = grey = Grey()
            m.submodules.downscaler = downscaler = Downscaler(g, column_bits=g.width.bit_length(),
                                                             row_bits=g.height.bit_length())
        wiring.connect(m, wiring.flipped(self.write), downscaler.write)

        # Input registers (IOB flip-flops on the board). FV's registers start high so that a frame in
        # progress when reset ends does not look like a FV rising edge.
        data_r = Signal(8)
        lv_r = Signal()
        fv_r = Signal(init=1)
        fv_prev = Signal(init=1)
        pins = self.pins
        m.d.sync += [data_r.eq(pins.data), lv_r.eq(pins.lv), fv_r.eq(pins.fv), fv_prev.eq(fv_r)]

        # Frame tracker.
        in_frame = Signal()
        fv_rise = fv_r & ~fv_prev
        frame_active = Signal()
        m.d.comb += frame_active.eq(fv_r & (in_frame | fv_rise))
        m.d.sync += in_frame.eq(frame_active)
        frame_end = in_frame & ~fv_r

        row = Signal(range(g.height + 1))      # LV falling edges in this frame, saturating at height
        bad = Signal()                          # a line of this frame had the wrong length, or too many lines
        m.d.comb += [
            assembler.data.eq(data_r),
            assembler.lv.eq(lv_r & frame_active),
        ]
        line_end = assembler.line_end
        line_bad = line_end & (~assembler.line_ok | (row == g.height))

        with m.If(fv_rise):
            m.d.sync += [row.eq(0), bad.eq(0)]
        with m.Elif(line_end):
            with m.If(row != g.height):
                m.d.sync += row.eq(row + 1)
            with m.If(line_bad):
                m.d.sync += bad.eq(1)

        rows_done = Signal(range(g.height + 2))
        m.d.comb += rows_done.eq(row + line_end)
        # Averaging, the status is computed here and reaches the ports EXTRA_LATENCY clocks later, with the writes.
        status = CaptureStatusSignature.create(path=("early",)) if averaging else self.status
        m.d.sync += [
            status.frame_start.eq(fv_rise),
            status.frame_done.eq(frame_end),
            status.in_frame.eq(frame_active),
        ]
        with m.If(frame_end):
            m.d.sync += [
                status.frame_ok.eq(~bad & ~line_bad & (rows_done == g.height)),
                status.frame_count.eq(status.frame_count + 1),
            ]

        self._row_strobes(m, status, lv_r & frame_active, fv_rise, line_end, row)
        if averaging:
            for name in CaptureStatusSignature.members:
                m.d.comb += getattr(self.status, name).eq(
                    delayed(m, getattr(status, name), EXTRA_LATENCY, f"status_{name}"))

        self._pixel_path(m, assembler, None if averaging else grey, downscaler, row)
        return m

    def _pixel_path(self, m, assembler, grey, downscaler, row):
        """The assembler's pixels into the downscaler, through ``grey`` when there is one (keeping)."""
        if grey is None:
            m.d.comb += [
                downscaler.pixel.eq(assembler.pixel),
                downscaler.valid.eq(assembler.valid),
            ]
        else:
            m.d.comb += [
                grey.pixel.eq(assembler.pixel),
                downscaler.valid.eq(assembler.valid),
                downscaler.grey.eq(grey.grey),
            ]
        m.d.comb += [
            downscaler.column.eq(assembler.column),
            downscaler.row.eq(row),
        ]

    def _row_strobes(self, m, status, lv_gated, fv_rise, line_end, row):
        """``status.row_start`` / ``row_end`` (counting rule 7, kept buffer rows only: keeping, the rows ``r %
        scale == 0``; averaging, ``r % scale == scale - 1``). The row of a run that starts with the frame is 0,
        whatever the counter still holds in that cycle; ``row_end`` is delayed a cycle more, to follow the row's last
        write."""
        g = self.geometry
        lv_gated_prev = Signal()
        m.d.sync += lv_gated_prev.eq(lv_gated)
        shift = g.scale.bit_length() - 1
        phase = g.scale - 1 if g.downscale == "average" else 0

        def kept(r):
            return ((r[:shift] == phase) if shift else 1) & (r < g.scale * g.buf_height)

        # The frame's first run is row 0: kept iff phase is 0.
        starts_kept = (fv_rise | kept(row)) if phase == 0 else (~fv_rise & kept(row))
        row_end_1 = Signal()
        m.d.sync += [
            status.row_start.eq(lv_gated & ~lv_gated_prev & starts_kept),
            row_end_1.eq(line_end & kept(row)),
            status.row_end.eq(row_end_1),
        ]
