"""One source of truth for the constants shared by the RTL, the simulation models and the golden model.

Every block takes its sizes as constructor arguments whose defaults come from here, so a test can build the
same RTL small. Sources: ../shared/spec.md (which pins the thesis down), CEA-861 for the video timing, and
docs/hardware-facts.md for the parts' clocks and addresses.
"""

from dataclasses import dataclass

__all__ = [
    "VideoTiming", "CEA_1080P60", "SMALL_TIMING",
    "SensorGeometry", "SENSOR", "SMALL_SENSOR",
    "CLOCKS", "I2C_ADDR",
    "DIFF_THRESHOLDS", "DIFF_LEVEL_GREY", "NO_DATA_RGB", "BACKGROUND_RGB", "gray_to_rgb24",
    "Region", "DisplayLayout",
    "DepthConfig", "DEPTH", "SMALL_DEPTH",
]


# --- Clocks (thesis table 4.1, spec "Clocks") -------------------------------------------------------------

class CLOCKS:
    """Clock frequencies in Hz. The thesis writes 148.25 MHz; CEA-861 1080p60 is 148.5 MHz (spec)."""
    SYS_HZ = 100_000_000        # Genesys oscillator, "sync" domain (I2C masters, switch synchronisers' source)
    CAM_MCLK_HZ = 24_000_000    # MCLK to both MT9D112 sensors (PLL_ADV: 100 MHz x 6 / 25; hdl/clocking.py)
    CAM_PCLK_HZ = 80_000_000    # each sensor's PCLK as the MT9D112 init table programs it (24 MHz x 80 / 3 / 8;
                                # Digilent's CamCtl: "1600x1200 @ 80 MHz pixel clock"): the cam_a/cam_b domains
    PIXEL_HZ = 148_500_000      # "pix" domain: sync generator, frame-buffer read ports, disparity, compositor
    I2C_HZ = 100_000            # I2C standard mode


# --- Video timing -----------------------------------------------------------------------------------------

@dataclass(frozen=True)
class VideoTiming:
    """Horizontal and vertical timing of one video mode, in pixel clocks and lines.

    A line is ``h_active`` pixels of data, then ``h_front`` porch, ``h_sync`` sync pulse, ``h_back`` porch.
    A frame is ``v_active`` lines, then ``v_front``, ``v_sync``, ``v_back`` lines. ``*_sync_positive`` is the
    pulse polarity (True: high during the pulse).
    """
    h_active: int
    h_front: int
    h_sync: int
    h_back: int
    v_active: int
    v_front: int
    v_sync: int
    v_back: int
    hsync_positive: bool = True
    vsync_positive: bool = True
    pixel_hz: int = CLOCKS.PIXEL_HZ

    @property
    def h_total(self):
        return self.h_active + self.h_front + self.h_sync + self.h_back

    @property
    def v_total(self):
        return self.v_active + self.v_front + self.v_sync + self.v_back

    @property
    def h_sync_start(self):
        return self.h_active + self.h_front

    @property
    def v_sync_start(self):
        return self.v_active + self.v_front

    @property
    def clocks_per_frame(self):
        return self.h_total * self.v_total

    @property
    def frame_hz(self):
        return self.pixel_hz / self.clocks_per_frame


#: CEA-861 1920x1080p @ 60 Hz (VIC 16): 2200 x 1125 at 148.5 MHz, exactly 60.00 Hz, positive syncs.
CEA_1080P60 = VideoTiming(
    h_active=1920, h_front=88, h_sync=44, h_back=148,
    v_active=1080, v_front=4, v_sync=5, v_back=36,
    hsync_positive=True, vsync_positive=True, pixel_hz=CLOCKS.PIXEL_HZ,
)

#: A small mode with the same structure, for fast tests of the same RTL (92 x 55 = 5060 clocks a frame;
#: its active area holds the default layout of SMALL_SENSOR's 16 x 12 buffers).
SMALL_TIMING = VideoTiming(
    h_active=80, h_front=4, h_sync=3, h_back=5,
    v_active=48, v_front=2, v_sync=2, v_back=3,
    hsync_positive=True, vsync_positive=True, pixel_hz=CLOCKS.PIXEL_HZ,
)


# --- Camera and frame buffer geometry (thesis 4.2, 4.2.1; spec "Camera driver") ---------------------------

@dataclass(frozen=True)
class SensorGeometry:
    """Sensor output size and the downscale into the frame buffer.

    The capture keeps the pixel at (``scale``*i, ``scale``*j) of each ``scale`` x ``scale`` block (thesis
    figure 4.4), converts it to ``gray_bits`` of grey and writes it at ``A = y * buf_width + x`` (eq. 4.1).
    """
    width: int = 1600
    height: int = 1200
    scale: int = 4
    gray_bits: int = 5

    @property
    def buf_width(self):
        return self.width // self.scale

    @property
    def buf_height(self):
        return self.height // self.scale

    @property
    def buf_depth(self):
        return self.buf_width * self.buf_height

    @property
    def addr_bits(self):
        return max(1, (self.buf_depth - 1).bit_length())


#: The VmodCAM's MT9D112 at full resolution -> 400 x 300 x 5-bit buffers (2 x 120,000 words).
SENSOR = SensorGeometry()
#: A small sensor for fast tests: 64 x 48 -> 16 x 12 buffers.
SMALL_SENSOR = SensorGeometry(width=64, height=48)


# --- I2C device addresses (7-bit) -------------------------------------------------------------------------

class I2C_ADDR:
    """7-bit I2C addresses (docs/hardware-facts.md gives the sources)."""
    MT9D112 = 0x3C   # 0x78 as an 8-bit write address; each camera has its own bus on the VmodCAM
    CH7301C = 0x76   # AS strap dependent (0x75 or 0x76): see docs/hardware-facts.md


# --- Disparity display (thesis 4.3; spec "Disparity map generator") ---------------------------------------

#: |L - R| (0..31 for 5-bit grey) is quantised to a display level: level = number of thresholds t with
#: |L - R| >= t. Differences below the first threshold are sensor noise and show black, so a matched
#: object "disappears" (thesis 4.6). Default: 5 levels.
DIFF_THRESHOLDS = (2, 4, 8, 16)
#: The 8-bit grey shown for each level (len(DIFF_THRESHOLDS) + 1 entries).
DIFF_LEVEL_GREY = (0, 64, 128, 192, 255)
#: Colour of disparity pixels whose shifted left read falls outside the 400 x 300 image ("no data").
NO_DATA_RGB = 0x2040C0
#: Colour of the screen outside the three images.
BACKGROUND_RGB = 0x303030


def gray_to_rgb24(gray, gray_bits=5):
    """The 24-bit RGB (R in bits 23:16) shown for a ``gray_bits`` grey value: bit replication to 8 bits."""
    g8 = (gray << (8 - gray_bits)) | (gray >> (2 * gray_bits - 8)) if gray_bits < 8 else gray
    return (g8 << 16) | (g8 << 8) | g8


# --- Screen layout of the compositor (spec "HDMI driver": defined in one place) ---------------------------

@dataclass(frozen=True)
class Region:
    """One image on the screen: ``source`` ("left", "right" or "disparity") drawn with its top-left corner at
    (``x0``, ``y0``) of the active area, each buffer pixel repeated ``scale`` x ``scale`` times."""
    source: str
    x0: int
    y0: int
    scale: int
    width: int       # buffer width (pixels before scaling)
    height: int      # buffer height

    @property
    def x1(self):
        return self.x0 + self.width * self.scale

    @property
    def y1(self):
        return self.y0 + self.height * self.scale


@dataclass(frozen=True)
class DisplayLayout:
    """Where the left image, the right image and the disparity map go on the screen.

    Default (:meth:`centred`): the two camera images at 1x side by side on top, separated by ``gap``; the
    disparity map at 2x below them, another ``gap`` lower; the whole group centred in the active area.
    For 1080p and 400 x 300 buffers: left [540, 940) x [70, 370), right [980, 1380) x [70, 370),
    disparity [560, 1360) x [410, 1010). Regions never overlap.
    """
    regions: tuple

    def region(self, source):
        return next(r for r in self.regions if r.source == source)

    @classmethod
    def centred(cls, timing, geometry, gap=None):
        w, h = geometry.buf_width, geometry.buf_height
        if gap is None:
            gap = 40 if timing.h_active >= 640 else 4
        top_w, total_h = 2 * w + gap, 3 * h + gap
        if max(top_w, 2 * w) > timing.h_active or total_h > timing.v_active:
            raise ValueError(f"{w}x{h} buffers do not fit the {timing.h_active}x{timing.v_active} active area")
        x_left = (timing.h_active - top_w) // 2
        y_top = (timing.v_active - total_h) // 2
        return cls(regions=(
            Region("left", x_left, y_top, 1, w, h),
            Region("right", x_left + w + gap, y_top, 1, w, h),
            Region("disparity", (timing.h_active - 2 * w) // 2, y_top + h + gap, 2, w, h),
        ))


# --- Automatic depth engine (docs/depth.md) ---------------------------------------------------------------

@dataclass(frozen=True)
class DepthConfig:
    """The dense matcher's constants: census transform, semi-global aggregation on two paths, winner-take-all,
    validity rule and 3 x 3 median (docs/depth.md). The widths follow from them: no stage can overflow.

    ``lanes`` disparities are computed per clock (the RTL's parallelism); it does not change the result.
    """
    disparities: int = 64       # D: candidates 0..D-1 (right image = reference, match left(x + d, y))
    census_width: int = 7       # census window, odd x odd, centred
    census_height: int = 7
    p1: int = 16                # penalty for a disparity change of 1 between path neighbours
    p2: int = 96                # penalty for a larger change
    max_cost: int = 120         # a winner whose summed cost is above this is invalid
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
    def invalid(self):
        """Output code of an invalid pixel (one above the largest disparity)."""
        return self.disparities

    @property
    def code_bits(self):
        return self.disparities.bit_length()


#: The board's engine: D = 64, 7 x 7 census, P1 = 16, P2 = 96, 16 disparities per clock.
DEPTH = DepthConfig()
#: A reduced engine for fast tests of the same RTL on SMALL_SENSOR's 16 x 12 buffers.
SMALL_DEPTH = DepthConfig(disparities=8, lanes=4)
