# amaranth: UnusedElaboratable=no
"""SegmentBand: every pixel of the segmentation view is the grey, the dimmed grey or the tinted dimmed grey that the
rule of docs/display.md ("Segmentation") gives for its code, two clocks after the code and the grey.

Every input is free on every clock (the disparity register too: the colour at t uses the register at t - 2, like the
code). A reference written from the docs (|code - 2**F d| <= 2**F half width, computed signed and wide; the grey
bit-replicated to 8 bits) gives the colour.
"""

from amaranth import Cat

from hdl.segment_band import SegmentBand
from hdl.switches import SWITCH_VALUE_BITS
from hdl.text_layer import CHAR_BITS, char_codes
from sim.formal.runner import FormalHarness
from spec.depth import DEPTH
from spec.display import SEGMENT_DIM_SHIFT, SEGMENT_HALF_WIDTH, SEGMENT_INVALID_RGB, SEGMENT_TEXT
from spec.sensor import SENSOR


class SegmentBandHarness(FormalHarness):
    name = "segment_band"
    block = "SegmentBand"

    def __init__(self, geometry=SENSOR, config=DEPTH):
        super().__init__()
        self.geometry, self.config = geometry, config

    def dut(self):
        return SegmentBand(self.geometry, self.config)

    def connect(self, m, dut, disparity, enable, code, grey):
        """The block's ports (the one place to adapt when the signature changes)."""
        m.d.comb += [dut.disparity.eq(disparity), dut.enable.eq(enable), dut.code.eq(code), dut.grey.eq(grey)]
        return dut.rgb, dut.chars.as_value()

    def build(self, m):
        cfg, g = self.config, self.geometry
        disparity = self.free("disparity", SWITCH_VALUE_BITS)
        enable, code, grey = self.free("enable"), self.free("code", cfg.code_bits), self.free("grey", g.grey_bits)
        m.submodules.dut = dut = self.dut()
        rgb, chars = self.connect(m, dut, disparity, enable, code, grey)

        pv = self.past_valid(m, 2)
        code_2, grey_2 = self.past(m, code, 2, name="code_2"), self.past(m, grey, 2, name="grey_2")
        d_2 = self.past(m, disparity, 2, name="disparity_2")
        distance = code_2 - (d_2 << cfg.fraction_bits)            # signed, wide enough for both operands
        half = cfg.fraction * SEGMENT_HALF_WIDTH
        inside = (distance >= -half) & (distance <= half)
        invalid = code_2 == cfg.invalid
        grey8 = Cat(grey_2[g.grey_bits - (8 - g.grey_bits):], grey_2) if g.grey_bits < 8 else grey_2
        dim = grey8 >> SEGMENT_DIM_SHIFT
        self.prove(m, "inside_band_shows_the_grey", ~(pv & inside & ~invalid) | (rgb == Cat(grey8, grey8, grey8)))
        self.prove(m, "outside_band_dimmed", ~(pv & ~inside & ~invalid) | (rgb == Cat(dim, dim, dim)))
        self.prove(m, "invalid_dimmed_and_tinted",
                   ~(pv & invalid) | (rgb == (Cat(dim, dim, dim) | SEGMENT_INVALID_RGB)))
        blank = sum(c << (CHAR_BITS * i) for i, c in enumerate(char_codes(" " * len(SEGMENT_TEXT))))
        # The text: three clocks after ``enable``.
        was_off = ~self.past(m, enable, 3, name="enable_3")
        self.prove(m, "text_blank_while_off", ~(self.past_valid(m, 3) & was_off) | (chars == blank))
        self.cover(m, "inside_at_the_near_edge", pv & ~invalid & (distance == half))
        self.cover(m, "outside_past_the_far_edge",
                   pv & (distance == -half - 1) & (grey_2 != 0))
        self.cover(m, "invalid_pixel", pv & invalid & (grey_2 != 0))
