"""The automatic depth engine's constants (docs/depth.md)."""

from dataclasses import dataclass

__all__ = ["DepthConfig", "DEPTH", "SMALL_DEPTH"]


@dataclass(frozen=True)
class DepthConfig:
    """The dense matcher's constants: census transform, semi-global aggregation on two paths, winner-take-all,
    sub-pixel fit, validity rule and 3 x 3 median (docs/depth.md). The widths follow from them: no stage can
    overflow. Codes count 1 / 2**fraction_bits pixel; ``invalid`` is D in those steps.

    ``lanes`` disparities are computed per clock (the RTL's parallelism); it does not change the result.
    """
    disparities: int = 64       # D: candidates 0..D-1 (right image = reference, match left(x + d, y))
    census_width: int = 7       # census window, odd x odd, centred
    census_height: int = 7
    p1: int = 16                # penalty for a disparity change of 1 between path neighbours
    p2: int = 96                # penalty for a larger change
    max_cost: int = 120         # a winner whose summed cost is above this is invalid
    fraction_bits: int = 4      # sub-pixel: codes in 1 / 2**fraction_bits pixel (equiangular fit); 0 = whole pixels
    uniqueness: int = 64        # confidence: invalid when 64 S* > uniqueness x S2 (S2: best at |d - d*| >= 2); 64 = off
    lanes: int = 16             # disparities per clock in the RTL (divides D)

    @property
    def census_bits(self):
        """Bits of a census signature: one per window pixel except the centre; also the largest cost."""
        return self.census_width * self.census_height - 1

    @property
    def cost_bits(self):
        return self.census_bits.bit_length()

    @property
    def path_max(self):
        """Largest path cost: L = C + min(...) - M <= C + P2."""
        return self.census_bits + self.p2

    @property
    def path_bits(self):
        return self.path_max.bit_length()

    @property
    def sum_bits(self):
        return (2 * self.path_max).bit_length()

    @property
    def fraction(self):
        """Code steps per pixel: code = 2**fraction_bits x disparity."""
        return 1 << self.fraction_bits

    @property
    def invalid(self):
        """Output code of an invalid pixel: D in code steps (above every disparity code)."""
        return self.disparities * self.fraction

    @property
    def code_bits(self):
        return self.invalid.bit_length()


#: The board's engine: D = 64, 7 x 7 census, P1 = 16, P2 = 96, 16 disparities per clock.
DEPTH = DepthConfig()
#: A reduced engine for fast tests of the same RTL on SMALL_SENSOR's 16 x 12 buffers.
SMALL_DEPTH = DepthConfig(disparities=8, lanes=4, uniqueness=60)
