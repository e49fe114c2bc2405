# amaranth: UnusedElaboratable=no
"""The depth engine's code-producing blocks: every code is a sub-pixel disparity below D - 1 (at most
2**F (D - 2) + 2**(F - 1)) or the invalid code D 2**F.

The whole engine's datapath in one proof did not finish (docs/formal.md, "Not covered"), so the two blocks that
produce codes are proven on their own, with free inputs inside their interface contracts:

* :class:`hdl.depth.winner.Winner`: tokens and path costs free; the token's ``group`` < D / lanes (the
  ``token_layout`` contract: groups 0..groups-1). D = 6 with 2 lanes: 3 groups behind a 2-bit field, so the
  contract matters, and D - 1 is not a power of two.
* :class:`hdl.depth.median.Median3x3`: the pass, the column, ``valid`` and the code free; a valid pixel's code is
  <= D (the winner's output, proven above). A 4 x 3 image.
* :class:`hdl.depth.subpixel.Subpixel`: the winner and its neighbours' sums free within the winner's contract
  (S(d* - 1) > S(d*) <= S(d* + 1)); every code is the validity rule's, and a valid fraction q is exactly the
  rounded equiangular fit: 2 e (q + 2**(F - 1)) <= 2**F (n + e) + e < 2 e (q + 2**(F - 1) + 1) with
  -2**(F - 1) <= q <= 2**(F - 1) (the floor division's defining inequalities). A 3 x 3 census and P2 = 7 keep
  the sums at 5 bits.
"""

from amaranth import C, Cat, Mux

from hdl.depth.median import Median3x3
from hdl.depth.subpixel import Subpixel
from hdl.depth.winner import Winner
from spec.depth import DepthConfig
from spec.sensor import SensorGeometry
from sim.formal.runner import FormalHarness

#: D = 6 (not a power of two), 2 lanes: 3 groups.
CONFIG = DepthConfig(disparities=6, lanes=2, max_cost=20)
#: 16 x 12 sensor pixels at scale 4: a 4 x 3 image.
GEOMETRY = SensorGeometry(width=16, height=12, scale=4)


class WinnerCodesHarness(FormalHarness):
    name = "winner_codes"
    block = "Winner"

    def __init__(self, config=CONFIG, width=GEOMETRY.buf_width):
        super().__init__()
        self.config, self.width = config, width

    def dut(self):
        return Winner(self.config, self.width)

    def build(self, m):
        cfg = self.config
        m.submodules.dut = dut = self.dut()
        token = self.free("token", len(dut.token.as_value()))
        horizontal = self.free("horizontal", len(dut.horizontal.as_value()))
        vertical = self.free("vertical", len(dut.vertical.as_value()))
        # The block's ports (the one place to adapt when the signature changes).
        m.d.comb += [dut.token.eq(token), dut.horizontal.eq(horizontal), dut.vertical.eq(vertical)]
        # token_layout: group counts 0 .. groups - 1.
        self.assume(m, "token_group_in_range", ~dut.token.go | (dut.token.group < cfg.disparities // cfg.lanes))
        top = cfg.fraction * (cfg.disparities - 2) + cfg.fraction // 2      # d* = D - 2, fraction + 1/2
        self.prove(m, "code_is_disparity_or_invalid", dut.code <= cfg.invalid)
        self.prove(m, "code_below_last_disparity_or_invalid", (dut.code <= top) | (dut.code == cfg.invalid))
        self.cover(m, "largest_valid_code", dut.valid & (dut.code == top))
        self.cover(m, "invalid_code", dut.valid & (dut.code == cfg.invalid))


class MedianCodesHarness(FormalHarness):
    name = "median_codes"
    block = "Median3x3"

    def __init__(self, config=CONFIG, geometry=GEOMETRY):
        super().__init__()
        self.config, self.geometry = config, geometry

    def dut(self):
        return Median3x3(self.config, self.geometry)

    def build(self, m):
        cfg = self.config
        m.submodules.dut = dut = self.dut()
        y = self.free("y", len(dut.y))
        valid = self.free("valid")
        x = self.free("x", len(dut.x))
        code = self.free("code", len(dut.code))
        # The block's ports (the one place to adapt when the signature changes).
        m.d.comb += [dut.y.eq(y), dut.valid.eq(valid), dut.x.eq(x), dut.code.eq(code)]
        # The codes come from the Winner: <= D (proven in winner_codes).
        self.assume(m, "valid_code_is_disparity_or_invalid", ~valid | (code <= cfg.invalid))
        self.prove(m, "median_is_disparity_or_invalid", ~dut.out_valid | (dut.out_code <= cfg.invalid))
        self.cover(m, "median_invalid", dut.out_valid & (dut.out_code == cfg.invalid))
        self.cover(m, "median_largest_code", dut.out_valid & (dut.out_code == cfg.invalid - 1))


#: Sums of 5 bits (N = 8, P2 = 7: L <= 15, S <= 30), D = 6, F = 4, max_cost 20.
SUBPIXEL_CONFIG = DepthConfig(disparities=6, lanes=2, census_width=3, census_height=3, p1=3, p2=7, max_cost=20)


class SubpixelCodesHarness(FormalHarness):
    name = "subpixel_codes"
    block = "Subpixel"
    engine = "induction"            # closes once k exceeds the latency: the pipeline's state is its last inputs

    def __init__(self, config=SUBPIXEL_CONFIG, width=GEOMETRY.buf_width):
        super().__init__()
        self.config, self.width = config, width

    def dut(self):
        return Subpixel(self.config, self.width)

    def build(self, m):
        cfg, F = self.config, self.config.fraction_bits
        m.submodules.dut = dut = self.dut()
        ports = {name: self.free(name, len(getattr(dut, name))) for name in
                 ("valid", "x", "d", "below", "best", "above", "ambiguous")}
        # The block's ports (the one place to adapt when the signature changes).
        m.d.comb += [getattr(dut, name).eq(value) for name, value in ports.items()]
        # The winner's contract: d* < D; S(d* - 1) > S(d*) (ties go to the smaller d) unless d* = 0; S(d* + 1) >= S(d*).
        self.assume(m, "d_in_range", ports["d"] < cfg.disparities)
        self.assume(m, "winner_below_is_larger", ~ports["valid"] | (ports["d"] == 0) |
                    (ports["below"] > ports["best"]))
        self.assume(m, "winner_above_not_smaller", ~ports["valid"] | (ports["above"] >= ports["best"]))
        lat = Subpixel.latency(cfg)
        # A pipeline without feedback: the output at clock t is a function of the inputs at t - lat only, so
        # k-induction closes (PDR on the divider's arithmetic did not finish in 600 s).
        seen = {name: self.past(m, value, lat, name=f"in_{name}") for name, value in ports.items()}
        ready = self.past_valid(m, lat)
        self.prove(m, "valid_after_latency", ~ready | (dut.out_valid == seen["valid"]))
        invalid = (seen["best"] > cfg.max_cost) | (seen["d"] == cfg.disparities - 1) | seen["ambiguous"]
        checked = ready & seen["valid"]
        self.prove(m, "invalid_by_the_rule", ~checked | ((dut.code == cfg.invalid) == invalid))
        self.prove(m, "no_fraction_at_d0", ~checked | invalid | (seen["d"] != 0) | (dut.code == 0))
        def value(v):                           # unsigned -> signed, zero-extended
            return Cat(v, C(0, 1)).as_signed()

        a, b, c = value(seen["below"]), value(seen["best"]), value(seen["above"])
        e = Mux(a > c, a, c) - b
        n = a - c
        q = value(dut.code) - value(seen["d"] * cfg.fraction)
        num = ((n + e) << F) + e
        shifted = q + cfg.fraction // 2
        fit = (2 * e * shifted <= num) & (num < 2 * e * (shifted + 1))
        inner = ~invalid & (seen["d"] != 0)
        self.prove(m, "fraction_is_the_rounded_fit", ~checked | ~inner | fit)
        self.prove(m, "fraction_in_range", ~checked | ~inner | ((q >= -(cfg.fraction // 2)) &
                                                             (q <= cfg.fraction // 2)))
        self.cover(m, "largest_fraction", checked & inner & (q == cfg.fraction // 2))
        self.cover(m, "smallest_fraction", checked & inner & (q == -(cfg.fraction // 2)))
