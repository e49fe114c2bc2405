"""The automatic depth engine's constants (docs/depth.md)."""

from dataclasses import dataclass, replace

from spec.sensor import SENSOR, SENSOR_800

__all__ = ["PATH_STEPS", "AD_SAMPLINGS", "TWO_PATHS", "DIAGONAL_PATHS", "THREE_PATHS", "DepthConfig", "DEPTH",
           "DEPTH_800", "DEPTH_800_BASE", "DEPTH_800_THREE", "SMALL_DEPTH", "SMALL_DEPTH_800"]

#: The aggregation paths (docs/depth.md, "Paths"): for each, the step (dx, dy) from a pixel p to the previous
#: pixel p' on the path. Every path runs along rows or down the image, so a row-by-row engine can compute it.
PATH_STEPS = {
    "left_to_right": (-1, 0),
    "top_to_bottom": (0, -1),
    "right_to_left": (1, 0),
    "top_left_to_bottom_right": (-1, -1),
    "top_right_to_bottom_left": (1, -1),
}
#: The board's engine today.
TWO_PATHS = ("left_to_right", "top_to_bottom")
#: Two paths with the diagonal from the top right as the second (docs/depth.md, "Cheap levers at 800 x 600"): the
#: RTL's vertical line buffer read at the column to the right (p' = (x + 1, y - 1)).
DIAGONAL_PATHS = ("left_to_right", "top_right_to_bottom_left")
#: The 800 x 600 build's paths: + right to left along the row.
THREE_PATHS = TWO_PATHS + ("right_to_left",)


#: The AD term's grey differences (``DepthConfig.ad_sampling``): the pixels' own, Birchfield-Tomasi's with the left
#: image interpolated, Birchfield-Tomasi's symmetric form.
AD_SAMPLINGS = ("pixel", "bt_left", "bt")


@dataclass(frozen=True)
class DepthConfig:
    """The dense matcher's constants: census transform, matching cost (census Hamming distance, plus the clipped
    grey difference min(|dI|, ``ad_clip``) >> ``ad_shift`` when ``ad_clip`` > 0: AD-census), semi-global
    aggregation on ``paths``, winner-take-all, sub-pixel fit, validity rule, with ``left_right`` the left-right
    check and the background fill, and median (``median`` 3: 3 x 3; 5, 7: the separable 5 x 5, 7 x 7; with
    ``median_valid`` each of the separable form's medians is taken over its valid codes) (docs/depth.md).
    The widths follow from them (``cost_max`` on): no stage can overflow. ``ValueError`` for paths, AD or median
    parameters outside their ranges. Codes count 1 / 2**fraction_bits pixel; ``invalid`` is D in those steps.
    ``pixel_bits`` is the width of the grey values the engine reads (the capture's ``grey_bits``).

    ``ad_sampling`` selects the AD term's grey difference (``AD_SAMPLINGS``): ``"pixel"``, |I_R(x) - I_L(x + d)|;
    ``"bt_left"``, Birchfield and Tomasi's sampling-insensitive dissimilarity with the left image interpolated,
    max(0, I_R(x) - Imax, Imin - I_R(x)), Imin and Imax the smallest and largest of I_L(x'), (I_L(x') + I_L(x' - 1)) / 2
    and (I_L(x') + I_L(x' + 1)) / 2 at x' = x + d (neighbours clamped at the image border); ``"bt"``, the smaller of
    that and the same with the images' roles swapped (the symmetric form).

    ``lanes`` disparities are computed per clock (the RTL's parallelism); it does not change the result. The RTL
    (hdl/depth/) computes ``TWO_PATHS``, ``DIAGONAL_PATHS`` and ``THREE_PATHS``; the golden model any set of
    ``PATH_STEPS``.
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
    pixel_bits: int = SENSOR.grey_bits      # grey values 0 .. 2**pixel_bits - 1
    paths: tuple = TWO_PATHS    # aggregation paths (names of PATH_STEPS), summed
    median: int = 3             # 3: the 3 x 3 median; 5, 7: the separable 5 x 5, 7 x 7 (docs/depth.md, "median")
    median_valid: bool = False  # separable medians over the valid codes only (median 5 or 7)
    ad_clip: int = 0            # AD-census: + min(|I_R - I_L|, ad_clip) >> ad_shift on the cost; 0 = off
    ad_shift: int = 0
    left_right: bool = False    # the left-right check from the same sums and the background fill (docs/depth.md)
    ad_sampling: str = "pixel"  # the AD term's grey difference: "pixel" |I_R - I_L|; "bt_left", "bt": Birchfield-Tomasi

    def __post_init__(self):
        if self.median not in (3, 5, 7):
            raise ValueError(f"median must be 3 (3 x 3), 5 or 7 (separable 5 x 5, 7 x 7), not {self.median!r}")
        if not isinstance(self.median_valid, bool) or (self.median_valid and self.median == 3):
            raise ValueError(f"median_valid must be False or True, True with median 5 or 7 only (median "
                             f"{self.median!r}, median_valid {self.median_valid!r})")
        if not isinstance(self.left_right, bool):
            raise ValueError(f"left_right must be True or False, not {self.left_right!r}")
        unknown = [p for p in self.paths if p not in PATH_STEPS]
        if unknown or not self.paths or len(set(self.paths)) != len(self.paths):
            raise ValueError(f"paths must be distinct names of {', '.join(PATH_STEPS)}, not {self.paths!r}")
        self._check_ad()
        if self.ad_sampling not in AD_SAMPLINGS:
            raise ValueError(f"ad_sampling must be one of {', '.join(AD_SAMPLINGS)}, not {self.ad_sampling!r}")
        if self.ad_sampling != "pixel" and not self.ad_clip:
            raise ValueError(f"ad_sampling = {self.ad_sampling!r} without ad_clip: the AD term is off")

    def _check_ad(self):
        """The AD term's parameters: ad_clip 0 (off) or 1 .. 2**pixel_bits - 1 (any integer: the largest grey
        difference that counts), ad_shift >= 0 with at least 1 left of ad_clip (the term is not always 0)."""
        top = (1 << self.pixel_bits) - 1
        for name in ("ad_clip", "ad_shift"):
            if not isinstance(getattr(self, name), int) or isinstance(getattr(self, name), bool):
                raise ValueError(f"{name} must be an int, not {getattr(self, name)!r}")
        if not 0 <= self.ad_clip <= top:
            raise ValueError(f"ad_clip must be 0 (off) or 1..{top} (the largest grey difference), "
                             f"not {self.ad_clip}")
        if self.ad_shift < 0:
            raise ValueError(f"ad_shift must not be negative, not {self.ad_shift}")
        if self.ad_clip and not self.ad_clip >> self.ad_shift:
            raise ValueError(f"ad_clip >> ad_shift = {self.ad_clip} >> {self.ad_shift} is 0: the AD term would "
                             f"be 0 everywhere")
        if not self.ad_clip and self.ad_shift:
            raise ValueError(f"ad_shift = {self.ad_shift} without ad_clip: the AD term is off")

    @property
    def census_bits(self):
        """Bits of a census signature: one per window pixel except the centre; the largest Hamming distance."""
        return self.census_width * self.census_height - 1

    @property
    def ad_max(self):
        """Largest AD term, ad_clip >> ad_shift (0 when off): also its value where x + d leaves the image."""
        return self.ad_clip >> self.ad_shift

    @property
    def cost_max(self):
        """Largest matching cost, census_bits + ad_max: also the cost where x + d leaves the image."""
        return self.census_bits + self.ad_max

    @property
    def cost_bits(self):
        return self.cost_max.bit_length()

    @property
    def path_max(self):
        """Largest path cost: L = C + min(...) - M <= C + P2."""
        return self.cost_max + self.p2

    @property
    def path_bits(self):
        return self.path_max.bit_length()

    @property
    def sum_max(self):
        """Largest summed cost: one path_max per path."""
        return len(self.paths) * self.path_max

    @property
    def sum_bits(self):
        return self.sum_max.bit_length()

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
#: The 800 x 600 engine without its quality options: 8-bit averaged buffers (SENSOR_800), D = 128 (the same 0.43 m
#: near limit at twice the resolution), the two paths left to right and top to bottom, the 3 x 3 median; everything
#: else as DEPTH. The base the quality levers are measured against (docs/depth.md, "Cheap levers at 800 x 600").
DEPTH_800_BASE = DepthConfig(disparities=128, pixel_bits=SENSOR_800.grey_bits)
#: The 800 x 600 build: DEPTH_800_BASE with AD-census 16 >> 1 (Birchfield and Tomasi's symmetric dissimilarity as
#: the grey difference), the top-right diagonal as the second path, SGM's left-right check with the background fill
#: and the separable 7 x 7 median, max_cost 68 a path (the board's 60 + the AD term's 8) (docs/depth.md, "Cheap
#: levers at 800 x 600", "On top of the package" and "The test bed": the choice). A third path at D = 128 fits no
#: scheme within the board's block RAM and frame time (docs/depth.md, "The third path in the RTL").
DEPTH_800 = replace(DEPTH_800_BASE, paths=DIAGONAL_PATHS, ad_clip=16, ad_shift=1, ad_sampling="bt", left_right=True,
                    median=7, max_cost=(DepthConfig.max_cost // len(TWO_PATHS) + (16 >> 1)) * len(DIAGONAL_PATHS))
#: DEPTH_800_BASE with the third path (right to left), max_cost the board's 60 per path: what a third path would buy
#: (golden model and bench figures; the RTL builds it at small sizes, ``DepthEngine`` with ``THREE_PATHS``).
DEPTH_800_THREE = replace(DEPTH_800_BASE, paths=THREE_PATHS,
                          max_cost=DepthConfig.max_cost * len(THREE_PATHS) // len(TWO_PATHS))
#: A reduced engine for fast tests of the same RTL on SMALL_SENSOR's 16 x 12 buffers.
SMALL_DEPTH = DepthConfig(disparities=8, lanes=4, uniqueness=60)
#: DEPTH_800 reduced for fast tests of the 800 x 600 build's RTL on SMALL_SENSOR_800's 32 x 24 buffers: twice
#: SMALL_DEPTH's disparities (as DEPTH_800 has twice DEPTH's) at SMALL_DEPTH's lanes; the paths, the 8-bit pixels
#: and everything else DEPTH_800's.
SMALL_DEPTH_800 = replace(DEPTH_800, disparities=2 * SMALL_DEPTH.disparities, lanes=SMALL_DEPTH.lanes)
