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
    "DepthConfig", "DEPTH", "SMALL_DEPTH",
    "VMODCAM_RIG", "disparity_of_distance", "DEPTH_COLOURS", "DEPTH_INVALID_RGB", "DEPTH_NOT_READY_RGB",
    "CROSSHAIR_RGB", "TEXT_RGB", "DEPTH_LABELS_M", "CROSSHAIR_ARM", "READOUT_TEXT", "FONT_CELL", "FONT",
    "Box", "Region", "TextBox", "ColourBar", "DisplayLayout",
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

#: A small mode with the same structure, for fast tests of the same RTL (124 x 59 = 7316 clocks a frame;
#: its active area holds the default four-panel layout of SMALL_SENSOR's 16 x 12 buffers with SMALL_DEPTH).
SMALL_TIMING = VideoTiming(
    h_active=112, h_front=4, h_sync=3, h_back=5,
    v_active=52, v_front=2, v_sync=2, v_back=3,
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
#: Colour of the screen outside the images (and of a text box's unlit pixels).
BACKGROUND_RGB = 0x303030


def gray_to_rgb24(gray, gray_bits=5):
    """The 24-bit RGB (R in bits 23:16) shown for a ``gray_bits`` grey value: bit replication to 8 bits."""
    g8 = (gray << (8 - gray_bits)) | (gray >> (2 * gray_bits - 8)) if gray_bits < 8 else gray
    return (g8 << 16) | (g8 << 8) | g8



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


# --- The depth display (issue 15; docs/display.md "Four panels") ------------------------------------------

class VMODCAM_RIG:
    """The stereo rig's optics, the numbers the test bed uses (sim/scene.py): baseline 6.3 cm (VmodCAM reference
    manual: 63 mm camera spacing), focal length 3.81 mm (thesis 4.6.7), 2.2 um sensor pixels (MT9D112)."""
    BASELINE_M = 0.063
    FOCAL_M = 3.81e-3
    PIXEL_M = 2.2e-6


def disparity_of_distance(distance_m, geometry=SENSOR):
    """The buffer-pixel disparity of a point at ``distance_m``: d = B f / (Z p s), ``s`` = the buffer's scale
    (p s = 4 x 2.2 um for the 400 x 300 buffers). Its inverse gives the distance of a disparity."""
    return VMODCAM_RIG.BASELINE_M * VMODCAM_RIG.FOCAL_M / (distance_m * VMODCAM_RIG.PIXEL_M * geometry.scale)


#: The depth colour map: nine sRGB anchors of matplotlib's perceptual "viridis" (sampled at 0, 1/8, .., 1),
#: dark blue-violet (far, small disparity) to yellow (near, large disparity). Disparity d of D gets the
#: piecewise-linear colour at u = 8 d / (D - 1), each channel rounded to nearest (docs/display.md).
DEPTH_COLOURS = (
    (68, 1, 84), (71, 45, 123), (59, 82, 139), (44, 114, 142), (33, 145, 140),
    (40, 174, 128), (94, 201, 98), (173, 220, 48), (253, 231, 37),
)
#: Colour of an invalid depth pixel (code D).
DEPTH_INVALID_RGB = 0x000000
#: Colour of a depth row the engine has not finished when the display reaches it (never in a working system).
DEPTH_NOT_READY_RGB = NO_DATA_RGB
#: Crosshair, tick marks and text.
CROSSHAIR_RGB = 0xFFFFFF
TEXT_RGB = 0xFFFFFF
#: Distances (metres) marked on the colour bar (each where its disparity lies inside 0 < d < D).
DEPTH_LABELS_M = (0.5, 1, 2, 3, 5)
#: Buffer pixels of each crosshair arm; the arms leave the 3 x 3 window the distance is measured in free.
CROSSHAIR_ARM = 8
#: The centre distance readout: four digits (centimetres, leading zeros blank; "----" when invalid) and "cm".
READOUT_TEXT = "0000cm"

#: A 5 x 7 font in a 6 x 8 cell (one blank column right, one blank row below). Rows top to bottom, "#" = lit.
FONT_CELL = (6, 8)
FONT = {
    " ": (".....",) * 7,
    "0": (".###.", "#...#", "#..##", "#.#.#", "##..#", "#...#", ".###."),
    "1": ("..#..", ".##..", "..#..", "..#..", "..#..", "..#..", ".###."),
    "2": (".###.", "#...#", "....#", "...#.", "..#..", ".#...", "#####"),
    "3": ("#####", "...#.", "..#..", "...#.", "....#", "#...#", ".###."),
    "4": ("...#.", "..##.", ".#.#.", "#..#.", "#####", "...#.", "...#."),
    "5": ("#####", "#....", "####.", "....#", "....#", "#...#", ".###."),
    "6": ("..##.", ".#...", "#....", "####.", "#...#", "#...#", ".###."),
    "7": ("#####", "....#", "...#.", "..#..", ".#...", ".#...", ".#..."),
    "8": (".###.", "#...#", "#...#", ".###.", "#...#", "#...#", ".###."),
    "9": (".###.", "#...#", "#...#", ".####", "....#", "...#.", ".##.."),
    ".": (".....", ".....", ".....", ".....", ".....", ".##..", ".##.."),
    "-": (".....", ".....", ".....", "#####", ".....", ".....", "....."),
    "c": (".....", ".....", ".###.", "#....", "#....", "#...#", ".###."),
    "m": (".....", ".....", "##.#.", "#.#.#", "#.#.#", "#...#", "#...#"),
}


# --- Screen layout of the compositor (spec "HDMI driver": defined in one place) ---------------------------

@dataclass(frozen=True)
class Box:
    """A rectangle of the active area: columns [x0, x1), rows [y0, y1)."""
    x0: int
    y0: int
    width: int
    height: int

    @property
    def x1(self):
        return self.x0 + self.width

    @property
    def y1(self):
        return self.y0 + self.height

    def overlaps(self, other):
        return self.x0 < other.x1 and other.x0 < self.x1 and self.y0 < other.y1 and other.y0 < self.y1

    def inside(self, other):
        return other.x0 <= self.x0 and self.x1 <= other.x1 and other.y0 <= self.y0 and self.y1 <= other.y1


@dataclass(frozen=True)
class Region:
    """One image on the screen: ``source`` ("left", "right", "disparity" or "depth") drawn with its top-left
    corner at (``x0``, ``y0``) of the active area, each buffer pixel repeated ``scale`` x ``scale`` times."""
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

    @property
    def box(self):
        return Box(self.x0, self.y0, self.x1 - self.x0, self.y1 - self.y0)


@dataclass(frozen=True)
class TextBox:
    """``text`` in :data:`FONT` with its top-left corner at (``x0``, ``y0``), every font pixel ``scale`` x
    ``scale``: glyph pixels in ``TEXT_RGB``, the rest of the box in ``BACKGROUND_RGB`` (opaque)."""
    text: str
    x0: int
    y0: int
    scale: int

    @property
    def box(self):
        return Box(self.x0, self.y0, len(self.text) * FONT_CELL[0] * self.scale, FONT_CELL[1] * self.scale)


@dataclass(frozen=True)
class ColourBar:
    """The depth colour map as a vertical bar: code c (0..codes-1) fills rows
    ``y0 + (codes - 1 - c) * step`` .. ``+ step`` (near = large disparity on top) of columns [x0, x0 + width)."""
    x0: int
    y0: int
    width: int
    step: int
    codes: int

    @property
    def box(self):
        return Box(self.x0, self.y0, self.width, self.codes * self.step)


@dataclass(frozen=True)
class DisplayLayout:
    """Where everything goes on the screen: the four panels (``regions``), the colour bar with its tick marks
    (``ticks``, boxes in ``TEXT_RGB``) and distance labels (``labels``), the centre-distance ``readout`` and the
    crosshair's ``crosshair_arm`` (buffer pixels).

    Default (:meth:`centred`): the two camera images at 1x side by side on top, separated by ``gap``; the
    difference map and the depth map at 2x below them, side by side, another ``gap`` lower; the colour bar right
    of the depth map with its labels; the readout beside the crosshair (right of and below the centre) inside
    the depth map if it fits there, else just below the depth map. For 1080p and 400 x 300 buffers: left
    [540, 940) x [70, 370), right [980, 1380) x [70, 370), difference map [100, 900) x [410, 1010), depth map
    [940, 1740) x [410, 1010), bar [1748, 1764) x [422, 998). :func:`hdl.compositor.check_layout` checks that
    nothing overlaps (except the readout inside the depth map) and everything fits.
    """
    regions: tuple
    bar: ColourBar = None
    ticks: tuple = ()
    labels: tuple = ()
    readout: TextBox = None
    crosshair_arm: int = CROSSHAIR_ARM

    def region(self, source):
        return next(r for r in self.regions if r.source == source)

    @classmethod
    def centred(cls, timing, geometry, depth=DEPTH, gap=None):
        w, h, codes = geometry.buf_width, geometry.buf_height, depth.disparities
        large = timing.h_active >= 640
        if gap is None:
            gap = 40 if large else 4
        fs = 2 if large else 1                      # font scale
        cell_w, cell_h = FONT_CELL[0] * fs, FONT_CELL[1] * fs
        step = max(1, 2 * h // codes)
        bar_gap, bar_w, tick_w = 4 * fs, 8 * fs, 3 * fs
        marks = [(f"{z:g}m", disparity_of_distance(z, geometry)) for z in DEPTH_LABELS_M]
        marks = [(text, d) for text, d in marks if 0 < d < codes]
        label_w = max((len(text) for text, _ in marks), default=0) * cell_w
        top_w = 2 * w + gap
        bottom_w = 4 * w + gap + bar_gap + bar_w + tick_w + fs + label_w
        readout_w = len(READOUT_TEXT) * cell_w
        xc, yc = w // 2, h // 2
        inside = (xc + 3) * 2 + readout_w <= 2 * w and (yc + 3) * 2 + cell_h <= 2 * h
        total_h = 3 * h + gap + (0 if inside else fs + cell_h)
        if max(top_w, bottom_w) > timing.h_active or total_h > timing.v_active:
            raise ValueError(f"{w}x{h} buffers and the depth display do not fit the "
                             f"{timing.h_active}x{timing.v_active} active area")
        x_left, y_top = (timing.h_active - top_w) // 2, (timing.v_active - total_h) // 2
        x_bottom, y_bottom = (timing.h_active - bottom_w) // 2, y_top + h + gap
        depth_region = Region("depth", x_bottom + 2 * w + gap, y_bottom, 2, w, h)
        bar = ColourBar(depth_region.x1 + bar_gap, y_bottom + (2 * h - codes * step) // 2, bar_w, step, codes)
        ticks, labels = [], []
        for text, d in marks:
            t = bar.y0 + int((codes - 1 - d + 0.5) * step)
            ticks.append(Box(bar.box.x1, t - fs // 2, tick_w, fs))
            labels.append(TextBox(text, bar.box.x1 + tick_w + fs, t - cell_h // 2, fs))
        if inside:
            readout = TextBox(READOUT_TEXT, depth_region.x0 + (xc + 3) * 2, depth_region.y0 + (yc + 3) * 2, fs)
        else:
            readout = TextBox(READOUT_TEXT, depth_region.x0, depth_region.y1 + fs, fs)
        return cls(regions=(
            Region("left", x_left, y_top, 1, w, h),
            Region("right", x_left + w + gap, y_top, 1, w, h),
            Region("disparity", x_bottom, y_bottom, 2, w, h),
            depth_region,
        ), bar=bar, ticks=tuple(ticks), labels=tuple(labels), readout=readout,
            crosshair_arm=min(CROSSHAIR_ARM, xc - 1, yc - 1, w - 1 - xc, h - 1 - yc))
