# amaranth: UnusedElaboratable=no
"""CameraCapture: for any stream of FV/LV/data bytes, only kept pixels are written, at their address, in the buffer.

The sensor pins are free on every clock: no assumption, so malformed streams (lines too long or too short, LV
without FV, FV falling mid-line, frames in progress at reset) are all included. The harness follows the
counting rules of the capture docstring with its own reference counters on the pins (frame = FV rising edge to
FV falling edge, column = byte pair in the LV run, row = LV falling edges in the frame, both saturating), and
compares the write port, 3 clocks later (the capture's latency), with the pixel the rules give. The row strobes:
``row_start`` exactly 2 clocks after a kept row's run starts on the pins, ``row_end`` 3 clocks after it ends; and
every write lies strictly inside its row's strobes (between the row start counted since the frame start and the
next row end).

The averaging capture (``CaptureAverageHarness``, ``geometry.downscale == "average"``): a block is written with its
last pixel (column and row ``= scale - 1`` mod ``scale``, its block inside the buffer), at the block's address, 5
clocks after (``EXTRA_LATENCY`` = 2 more), the status as much later, the kept rows the blocks' last. The grey values
are not part of the proofs (tests/test_averaging_capture.py compares them with the golden model for every block sum).
"""

from amaranth import Cat, Mux, Signal

from hdl.capture import EXTRA_LATENCY, CameraCapture
from spec.sensor import SMALL_SENSOR, SensorGeometry
from sim.formal.runner import FormalHarness

#: Clocks from the pins to the write port (the thesis's capture; averaging, ``EXTRA_LATENCY`` more).
LATENCY = 3

#: The averaging capture's proofs: a 17 x 9 sensor, 8 x 4 buffer pixels of 2 x 2 blocks (the last column and row
#: belong to no whole block; the counters, saturating at 17 and 9, would complete blocks past the buffer's edge).
SMALL_AVERAGE = SensorGeometry(width=17, height=9, scale=2, grey_bits=8, downscale="average")


class CaptureHarness(FormalHarness):
    name = "capture"
    block = "CameraCapture"

    def __init__(self, geometry=SMALL_SENSOR):
        super().__init__()
        self.geometry = geometry
        self.averaging = geometry.downscale == "average"
        self.extra = EXTRA_LATENCY if self.averaging else 0

    def dut(self):
        return CameraCapture(self.geometry)

    def build(self, m):
        g = self.geometry
        latency, extra = LATENCY + self.extra, self.extra
        data, lv, fv = self.free("data", 8), self.free("lv"), self.free("fv")
        dut = self.dut()
        module = self.open(m, "dut", dut)
        # The block's ports and the counters of its submodules (the one place to adapt to a new signature).
        m.d.comb += [dut.pins.data.eq(data), dut.pins.lv.eq(lv), dut.pins.fv.eq(fv)]
        w_addr, w_en = dut.write.addr, dut.write.en
        frame_start, frame_done, in_frame = dut.status.frame_start, dut.status.frame_done, dut.status.in_frame
        assembler = module.submodules.assembler
        column = assembler.column
        row = module.submodules.averager.row if self.averaging else module.submodules.downscaler.row
        pixel, pixel_valid = assembler.pixel, assembler.valid

        ref = self._reference(m, data, lv, fv)
        pv = self.past_valid(m, latency)
        expect = {k: self.past(m, v, latency, name=f"expected_{k}") for k, v in ref.items()
                  if k in ("keep", "address")}
        expect_pixel = self.past(m, ref["pixel"], LATENCY - 1, name="expected_pixel")
        self.prove(m, "write_address_in_buffer", ~w_en | (w_addr < g.buf_depth))
        self.prove(m, "writes_only_kept_pixels", ~w_en | (pv & expect["keep"]))
        self.prove(m, "every_kept_pixel_written", ~(pv & expect["keep"]) | w_en)
        self.prove(m, "write_address_is_pixel_position", ~w_en | (w_addr == expect["address"]))
        # The bytes of each pixel are paired in order (the grey conversion itself is checked exhaustively, for all
        # 2^16 pixels, by tests/test_downscaler.py; its arithmetic would only slow the proof down here).
        self.prove(m, "pixel_bytes_paired_in_order",
                   ~pixel_valid | (self.past_valid(m, LATENCY) & (pixel == expect_pixel)))
        self.prove(m, "column_counter_bounded", column <= g.width)
        self.prove(m, "row_counter_bounded", row <= g.height)
        self.prove(m, "in_frame_follows_fv",
                   ~pv | (in_frame == self.past(m, ref["in_frame"], 1 + extra, name="past_ref_in_frame")))
        pv2 = self.past_valid(m, 2 + extra)
        self.prove(m, "frame_start_exactly_at_fv_rise",
                   ~pv2 | (frame_start == self.past(m, ref["rise"], 2 + extra, name="past_rise")))
        self.prove(m, "frame_done_exactly_when_frame_fv_falls",
                   ~pv2 | (frame_done == self.past(m, ref["fall"], 2 + extra, name="past_fall")))

        row_start, row_end = self.row_strobes(dut)
        self.prove(m, "row_start_exactly_at_kept_run_start",
                   ~pv2 | (row_start == self.past(m, ref["run_start"], 2 + extra, name="past_run_start")))
        self.prove(m, "row_end_exactly_after_kept_run_end",
                   ~pv | (row_end == self.past(m, ref["run_end"], latency, name="past_run_end")))
        self._writes_inside_rows(m, dut, row_start, row_end)

        self.cover(m, "write_in_second_kept_row", w_en & (w_addr == g.buf_width))
        self.cover(m, "write_at_last_address", w_en & (w_addr == g.buf_depth - 1))
        self.cover(m, "long_line_saturates_column", column == g.width)
        fell_mid_line = Signal(name="fv_fell_mid_line")
        with m.If(ref["fall"] & lv):
            m.d.sync += fell_mid_line.eq(1)
        self.cover(m, "first_pixel_written_after_fv_fell_mid_line", w_en & (w_addr == 0) & fell_mid_line)

    def row_strobes(self, dut):
        """The capture's ``row_start`` and ``row_end`` (a mutant may connect others)."""
        return dut.status.row_start, dut.status.row_end

    def _writes_inside_rows(self, m, dut, row_start, row_end):
        """From the strobes alone: the row in progress (row starts since the frame start, 1-based, saturating) and
        whether one is open; a write must be to that row, in a clock after its start and before its end."""
        g = self.geometry
        status = dut.status
        starts = Signal(range(g.buf_height + 2), name="strobe_rows_started")
        open_row = Signal(name="strobe_row_open")
        base = Mux(status.frame_start, 0, starts)
        with m.If(row_start):
            m.d.sync += [starts.eq(Mux(base == g.buf_height + 1, base, base + 1)), open_row.eq(1)]
        with m.Elif(status.frame_start):
            m.d.sync += starts.eq(0)
        with m.If(row_end & ~row_start):
            m.d.sync += open_row.eq(0)
        y = Signal(range(g.buf_height + 1), name="write_row")
        m.d.comb += y.eq(dut.write.addr // g.buf_width)
        self.prove(m, "write_inside_its_row_strobes",
                   ~dut.write.en | (open_row & ~row_end & ~row_start & (starts == y + 1)))
        self.cover(m, "row_end_after_a_kept_last_pixel", row_end & self.past(m, dut.write.en, name="past_w_en"))

    def _reference(self, m, data, lv, fv):
        """The counting rules on the pins: whether the pixel completed now is kept, its address and grey."""
        g = self.geometry
        fv_prev = Signal(init=1, name="ref_fv_prev")       # a frame in progress at reset is not a new frame
        in_frame = Signal(name="ref_in_frame")
        lv_prev = Signal(name="ref_lv_prev")
        odd = Signal(name="ref_odd")                       # the first byte of a pixel has arrived
        first = Signal(8, name="ref_first_byte")
        column = Signal(range(g.width + 1), name="ref_column")   # pixels completed in this LV run
        row = Signal(range(g.height + 1), name="ref_row")        # LV falling edges in this frame

        rise = fv & ~fv_prev
        active = fv & (in_frame | rise)
        lv_on = lv & active
        line_end = lv_prev & ~lv_on
        m.d.sync += [fv_prev.eq(fv), in_frame.eq(active), lv_prev.eq(lv_on)]
        with m.If(lv_on):
            m.d.sync += [odd.eq(~odd), first.eq(data)]
            with m.If(odd & (column != g.width)):
                m.d.sync += column.eq(column + 1)
        with m.Else():
            m.d.sync += [odd.eq(0), column.eq(0)]
        with m.If(rise):
            m.d.sync += row.eq(0)
        with m.Elif(line_end & (row != g.height)):
            m.d.sync += row.eq(row + 1)

        s = g.scale
        completes = lv_on & odd
        if self.averaging:          # a block's last pixel, its block inside the buffer
            phase = s - 1
            keep = completes & (column % s == phase) & (row % s == phase) & (column < s * g.buf_width) & \
                (row < s * g.buf_height)
        else:
            phase = 0
            keep = completes & (column % s == 0) & (row % s == 0) & (column < g.width) & (row < g.height)

        def kept(r):
            return (r % s == phase) & (r < s * g.buf_height)
        return {"keep": keep, "address": (row // s) * g.buf_width + column // s, "pixel": Cat(data, first),
                "rise": rise, "fall": in_frame & ~fv, "in_frame": in_frame,
                "run_start": lv_on & ~lv_prev & kept(Mux(rise, 0, row)), "run_end": line_end & kept(row)}


class CaptureAverageHarness(CaptureHarness):
    """The averaging capture (``downscale="average"``): the same properties at its latency and with its kept pixels
    and rows (module docstring)."""
    name = "capture_average"

    def __init__(self, geometry=SMALL_AVERAGE):
        super().__init__(geometry)
