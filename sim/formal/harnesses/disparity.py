# amaranth: UnusedElaboratable=no
"""DisparitySubtractor: both reads stay in the buffer, ``no_data`` exactly when the shifted read leaves the image.

Inputs are free within the subtractor's interface contract (its docstring), which the compositor meets:

* a valid pixel lies inside the buffer and comes with its own address ``addr = y * buf_width + x``
  (the compositor's running counters);
* ``disparity`` and ``rectification`` have been stable for ``SETTLE_CLOCKS`` clocks before a valid pixel
  (the switch registers change only at a frame start, lines before the disparity region).

The read data are free too (any buffer contents). The harness computes, from the same inputs and with its own
arithmetic, the shifted position, the no-data flag and the quantised difference, and compares them with the
block's outputs through the 4-clock pipeline.
"""

from amaranth import Mux, Signal

from hdl.disparity import LATENCY, SETTLE_CLOCKS, DisparitySubtractor
from spec.display import DIFF_THRESHOLDS
from spec.sensor import SMALL_SENSOR
from hdl.switches import SWITCH_VALUE_BITS
from sim.formal.runner import FormalHarness


class DisparityHarness(FormalHarness):
    name = "disparity"
    block = "DisparitySubtractor"
    engine = "induction"            # the 4-clock pipeline closes at k = 5; PDR takes over ten times longer
    max_steps = 8

    def __init__(self, geometry=SMALL_SENSOR, thresholds=DIFF_THRESHOLDS):
        super().__init__()
        self.geometry = geometry
        self.thresholds = thresholds

    def dut(self):
        return DisparitySubtractor(self.geometry, self.thresholds)

    def build(self, m):
        g = self.geometry
        w, h = g.buf_width, g.buf_height
        i = {name: self.free(name, width) for name, width in (
            ("valid", 1), ("x", range(w)), ("y", (h - 1).bit_length() or 1), ("addr", g.addr_bits),
            ("disparity", SWITCH_VALUE_BITS), ("rectification", SWITCH_VALUE_BITS),
            ("left_data", g.grey_bits), ("right_data", g.grey_bits))}
        m.submodules.dut = dut = self.dut()
        # The block's ports (the one place to adapt when the signature changes).
        m.d.comb += [getattr(dut, name).eq(i[name]) for name in ("valid", "x", "y", "addr")]
        m.d.comb += [dut.settings.disparity.eq(i["disparity"]), dut.settings.rectification.eq(i["rectification"]),
                     dut.left.data.eq(i["left_data"]), dut.right.data.eq(i["right_data"])]
        left_addr, right_addr, level, no_data, out_valid = (
            dut.left.addr, dut.right.addr, dut.level, dut.no_data, dut.out_valid)

        self._contract(m, i)
        pv = self.past_valid(m)

        # Clock n + 1: the reads of the pixel that was valid at clock n.
        was_valid = pv & self.past(m, i["valid"], name="past_valid_in")
        px, py = self.past(m, i["x"], name="past_x"), self.past(m, i["y"], name="past_y")
        pd, pr = self.past(m, i["disparity"], name="past_disparity"), self.past(m, i["rectification"],
                                                                               name="past_rectification")
        shifted_x, shifted_y = px + pd, py + pr.as_signed()       # the rectification is signed
        outside = (shifted_x >= w) | (shifted_y >= h) | (shifted_y < 0)
        self.prove(m, "reads_idle_at_zero_between_pixels", ~pv | was_valid | ((left_addr == 0) & (right_addr == 0)))
        self.prove(m, "left_read_in_buffer", ~was_valid | (left_addr < g.buf_depth))
        self.prove(m, "right_read_in_buffer", ~was_valid | (right_addr < g.buf_depth))
        self.prove(m, "right_read_at_pixel", ~was_valid | (right_addr == self.past(m, i["addr"], name="past_addr")))
        self.prove(m, "left_read_at_shifted_pixel", ~(was_valid & ~outside) | (left_addr == shifted_y * w + shifted_x))

        # Clock n + 4: the result; the data read for the pixel arrived at clock n + 2.
        self._result(m, i, pv, outside, level, no_data, out_valid)
        self.cover(m, "read_at_last_address", was_valid & (left_addr == g.buf_depth - 1) & ~outside)
        self.cover(m, "no_data_from_horizontal_shift", was_valid & (px + pd >= w) & (py + pr < h))
        self.cover(m, "no_data_from_vertical_shift", was_valid & (px + pd < w) & (shifted_y >= h))
        self.cover(m, "no_data_from_negative_vertical_shift", was_valid & (px + pd < w) & (shifted_y < 0))

    def _contract(self, m, i):
        g = self.geometry
        self.assume(m, "valid_pixel_inside_buffer", ~i["valid"] | (i["y"] < g.buf_height))
        self.assume(m, "valid_pixel_address_matches_position",
                    ~i["valid"] | (i["addr"] == i["y"] * g.buf_width + i["x"]))
        settled = self.past_valid(m, SETTLE_CLOCKS)
        for name in ("disparity", "rectification"):
            for k in range(1, SETTLE_CLOCKS + 1):
                settled &= i[name] == self.past(m, i[name], k, name=f"settle_{name}")
        self.assume(m, "switches_settled_before_valid_pixel", ~i["valid"] | settled)

    def _result(self, m, i, pv, outside, level, no_data, out_valid):
        ld = self.past(m, i["left_data"], LATENCY - 2, name="past_left_data")
        rd = self.past(m, i["right_data"], LATENCY - 2, name="past_right_data")
        difference = (ld - rd).as_signed()
        magnitude = Signal(self.geometry.grey_bits + 1, name="ref_magnitude")
        m.d.comb += magnitude.eq(Mux(difference < 0, -difference, difference))
        expected = sum((magnitude >= t).as_unsigned() for t in self.thresholds)
        result_valid = self.past_valid(m, LATENCY) & self.past(m, i["valid"], LATENCY, name="delayed_valid")
        result_outside = self.past(m, outside, LATENCY - 1, name="delayed_outside")
        self.prove(m, "out_valid_four_clocks_after_valid", ~self.past_valid(m, LATENCY) | (out_valid == result_valid))
        self.prove(m, "no_data_exactly_when_shift_leaves_image", ~result_valid | (no_data == result_outside))
        self.prove(m, "level_is_quantised_difference",
                   ~result_valid | (level == Mux(result_outside, 0, expected)))
        self.cover(m, "top_level", result_valid & (level == len(self.thresholds)))
