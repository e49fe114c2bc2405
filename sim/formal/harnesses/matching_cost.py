# amaranth: UnusedElaboratable=no
"""MatchingCost with Birchfield and Tomasi's symmetric AD term: every lane's cost is the census Hamming distance
plus min(dis, 2 ad_clip) >> (ad_shift + 1), dis = min(max(0, 2 I_R - high_L, low_L - 2 I_R), max(0, 2 I_L -
high_R, low_R - 2 I_L)) in 2x units, or ``cost_max`` outside the image, three clocks after its inputs.

Every input is free on every clock; the one assumption is what a pixel's range always is (``low`` <= ``high``),
weaker than the census window's (low <= 2 I <= high): the block's logic ORs the clipped values of the two
differences of a direction, which needs no more. The harness computes the term with its own arithmetic (signed
differences, max and min as comparisons) from the inputs three clocks earlier. Two lanes of 8-bit pixels, a 3 x 3
census (8 bits), ad_clip 16 >> 1 (``DEPTH_800``'s term).
"""

from amaranth import Mux, Signal, Value, signed

from hdl.depth.matching_cost import MatchingCost
from spec.depth import DepthConfig
from sim.formal.runner import FormalHarness

CONFIG = DepthConfig(disparities=2, lanes=2, census_width=3, census_height=3, pixel_bits=8, ad_clip=16, ad_shift=1,
                     ad_sampling="bt")


class MatchingCostBTHarness(FormalHarness):
    name = "matching_cost_bt"
    block = "MatchingCost"
    engine = "induction"            # a 3-clock pipeline: closes at k = 4
    max_steps = 6

    def __init__(self, config=CONFIG):
        super().__init__()
        self.config = config

    def dut(self):
        return MatchingCost(self.config)

    def build(self, m):
        cfg = self.config
        dut = self.dut()
        self.open(m, "dut", dut)
        ports = ("right", "left", "inside", "right_grey", "left_grey", "right_range", "left_range")
        inputs = {name: self.free(name, len(Value.cast(getattr(dut, name)))) for name in ports}
        m.d.comb += [getattr(dut, name).eq(inputs[name]) for name in ports]
        ranges = [dut.right_range] + [dut.left_range[k] for k in range(cfg.lanes)]
        for i, grey_range in enumerate(ranges):
            self.assume(m, f"range_{i}_ordered", grey_range.low <= grey_range.high)

        done = self.past_valid(m, MatchingCost.LATENCY)
        for k in range(cfg.lanes):
            expected, reverse_smaller, clipped = self._reference(m, dut, k)
            late = self.past(m, expected, MatchingCost.LATENCY, name=f"ref_cost_{k}")
            self.prove(m, f"lane_{k}_cost_is_census_plus_bt_term", ~done | (dut.cost[k] == late))
            if k == 0:
                late_reverse = self.past(m, reverse_smaller, MatchingCost.LATENCY, name="ref_reverse_smaller")
                late_clipped = self.past(m, clipped, MatchingCost.LATENCY, name="ref_clipped")
                inside = self.past(m, dut.inside[0], MatchingCost.LATENCY, name="ref_inside")
                self.cover(m, "reverse_direction_is_the_smaller", done & inside & late_reverse)
                self.cover(m, "term_at_the_clip", done & inside & late_clipped)

    def _reference(self, m, dut, k):
        """Lane k's cost from this clock's inputs, and whether the reverse direction's dis is the smaller and the
        term is at the clip (for the covers)."""
        cfg = self.config
        n = cfg.pixel_bits

        def dis(grey, grey_range, name):
            above = Signal(signed(n + 3), name=f"ref_above_{name}_{k}")
            below = Signal(signed(n + 3), name=f"ref_below_{name}_{k}")
            value = Signal(signed(n + 3), name=f"ref_dis_{name}_{k}")
            m.d.comb += [above.eq(2 * grey - grey_range.high), below.eq(grey_range.low - 2 * grey),
                         value.eq(Mux(above > below, Mux(above > 0, above, 0), Mux(below > 0, below, 0)))]
            return value

        forward = dis(dut.right_grey, dut.left_range[k], "forward")
        reverse = dis(dut.left_grey[k], dut.right_range, "reverse")
        smaller = Mux(reverse < forward, reverse, forward)
        clip = 2 * cfg.ad_clip
        term = Mux(smaller > clip, clip, smaller) >> (cfg.ad_shift + 1)
        hamming = sum((dut.right ^ dut.left[k])[i] for i in range(cfg.census_bits))
        cost = Signal(cfg.cost_bits, name=f"ref_cost_{k}")
        m.d.comb += cost.eq(Mux(dut.inside[k], hamming + term, cfg.cost_max))
        return cost, reverse < forward, smaller >= clip
