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
"""

from amaranth import Signal

from hdl.depth.median import Median3x3
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
