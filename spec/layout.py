"""The screen layout of the compositor (spec "HDMI driver": defined in one place): panels, colour bar, ticks,
labels and readout, and the two arrangements: :meth:`DisplayLayout.centred` (the 400 x 300 build's: camera images
1:1, maps 2x) and :meth:`DisplayLayout.full_maps` (the 800 x 600 build's: camera images at half size, maps 1:1)."""

from dataclasses import dataclass

from .depth import DEPTH
from .display import CROSSHAIR_ARM, DEPTH_LABELS_M, READOUT_TEXT, RECTIFICATION_TEXT, SEGMENT_TEXT
from .font import FONT_CELL
from .sensor import disparity_of_distance

__all__ = ["Box", "Region", "TextBox", "ColourBar", "DisplayLayout"]


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
    corner at (``x0``, ``y0``) of the active area, each buffer pixel repeated ``scale`` x ``scale`` times; with
    ``shrink`` > 1 (and ``scale`` 1) the image at 1 / ``shrink`` size instead: display pixel (i, j) of the region
    shows buffer pixel (``shrink`` i, ``shrink`` j), the top-left pixel of each ``shrink`` x ``shrink`` block."""
    source: str
    x0: int
    y0: int
    scale: int
    width: int       # buffer width (pixels before scaling)
    height: int      # buffer height
    shrink: int = 1

    @property
    def x1(self):
        return self.x0 + self.width * self.scale // self.shrink

    @property
    def y1(self):
        return self.y0 + self.height * self.scale // self.shrink

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
    """The depth colour map as a vertical bar: whole disparity d (0..codes-1, shown in the colour of its code
    2**F d) fills rows ``y0 + (codes - 1 - d) * step`` .. ``+ step`` (near = large disparity on top) of columns
    [x0, x0 + width)."""
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
    (``ticks``, boxes in ``TEXT_RGB``) and distance labels (``labels``), the centre-distance ``readout``, the
    crosshair's ``crosshair_arm`` (buffer pixels), the segmentation band's text (``band``, or None) and the
    rectification in use (``rectification``, or None).

    Both arrangements put the two camera images side by side on top, separated by ``gap``; the difference map and
    the depth map side by side below them, another ``gap`` lower, each map on screen twice the size of a camera
    image; the colour bar right of the depth map (one band per whole disparity, as many rows each as fit the map's
    height) with its labels; the readout beside the crosshair (right of and below the centre) inside the depth map
    if it fits there, else just below the depth map; the band text left-aligned with the difference map in the gap
    above it and the rectification text with the depth map, when the gap is as high as a text line (and, for the
    rectification text, the line is long enough; else None). :func:`hdl.compositor.check_layout` checks that
    nothing overlaps (except the readout inside the depth map) and everything fits.

    * :meth:`centred` (the 400 x 300 build): camera images 1:1, maps 2x. For 1080p and 400 x 300 buffers: left
      [540, 940) x [70, 370), right [980, 1380) x [70, 370), difference map [100, 900) x [410, 1010), depth map
      [940, 1740) x [410, 1010), bar [1748, 1764) x [422, 998), band text [100, 244) x [382, 398), rectification
      text [940, 1096) x [382, 398).
    * :meth:`full_maps` (the 800 x 600 build): camera images at half size (``shrink`` 2), maps 1:1, the crosshair
      arm twice :data:`~spec.display.CROSSHAIR_ARM` (the same length on screen). For 1080p and 800 x 600 buffers
      the panels, band and rectification text are where :meth:`centred` puts them for 400 x 300; the bar, 4 rows
      per code for D = 128, is [1748, 1764) x [454, 966).
    """
    regions: tuple
    bar: ColourBar = None
    ticks: tuple = ()
    labels: tuple = ()
    readout: TextBox = None
    crosshair_arm: int = CROSSHAIR_ARM
    band: TextBox = None
    rectification: TextBox = None

    def region(self, source):
        return next(r for r in self.regions if r.source == source)

    @classmethod
    def centred(cls, timing, geometry, depth=DEPTH, gap=None):
        """Camera images 1:1, maps 2x (the 400 x 300 build's screen); ``ValueError`` if it does not fit."""
        return cls._arranged(timing, geometry, depth, gap, image_shrink=1, map_scale=2, arm=CROSSHAIR_ARM)

    @classmethod
    def full_maps(cls, timing, geometry, depth=DEPTH, gap=None):
        """Camera images at half size, maps 1:1 (the 800 x 600 build's screen); ``ValueError`` if it does not fit
        or the buffers have an odd size."""
        if geometry.buf_width % 2 or geometry.buf_height % 2:
            raise ValueError(f"{geometry.buf_width}x{geometry.buf_height} buffers: half-size images need an even "
                             "width and height")
        return cls._arranged(timing, geometry, depth, gap, image_shrink=2, map_scale=1, arm=2 * CROSSHAIR_ARM)

    @classmethod
    def default(cls, timing, geometry, depth=DEPTH, gap=None):
        """:meth:`centred` where it fits the active area, else :meth:`full_maps` (so 400 x 300 buffers get the one,
        800 x 600 buffers the other on 1080p)."""
        try:
            return cls.centred(timing, geometry, depth, gap)
        except ValueError:
            return cls.full_maps(timing, geometry, depth, gap)

    @classmethod
    def _arranged(cls, timing, geometry, depth, gap, image_shrink, map_scale, arm):
        w, h, codes = geometry.buf_width, geometry.buf_height, depth.disparities
        iw, ih = w // image_shrink, h // image_shrink                 # a camera image on screen
        mw, mh = w * map_scale, h * map_scale                         # a map on screen
        large = timing.h_active >= 640
        if gap is None:
            gap = 40 if large else 4
        fs = 2 if large else 1                      # font scale
        cell_w, cell_h = FONT_CELL[0] * fs, FONT_CELL[1] * fs
        step = max(1, mh // codes)
        bar_gap, bar_w, tick_w = 4 * fs, 8 * fs, 3 * fs
        marks = [(f"{z:g}m", disparity_of_distance(z, geometry)) for z in DEPTH_LABELS_M]
        marks = [(text, d) for text, d in marks if 0 < d < codes]
        label_w = max((len(text) for text, _ in marks), default=0) * cell_w
        top_w = 2 * iw + gap
        bottom_w = 2 * mw + gap + bar_gap + bar_w + tick_w + fs + label_w
        readout_w = len(READOUT_TEXT) * cell_w
        xc, yc = w // 2, h // 2
        inside = (xc + 3) * map_scale + readout_w <= mw and (yc + 3) * map_scale + cell_h <= mh
        total_h = ih + gap + mh + (0 if inside else fs + cell_h)
        if max(top_w, bottom_w) > timing.h_active or total_h > timing.v_active:
            raise ValueError(f"{w}x{h} buffers and the depth display do not fit the "
                             f"{timing.h_active}x{timing.v_active} active area")
        x_left, y_top = (timing.h_active - top_w) // 2, (timing.v_active - total_h) // 2
        x_bottom, y_bottom = (timing.h_active - bottom_w) // 2, y_top + ih + gap
        depth_region = Region("depth", x_bottom + mw + gap, y_bottom, map_scale, w, h)
        bar = ColourBar(depth_region.x1 + bar_gap, y_bottom + (mh - codes * step) // 2, bar_w, step, codes)
        ticks, labels = [], []
        for text, d in marks:
            t = bar.y0 + int((codes - 1 - d + 0.5) * step)
            ticks.append(Box(bar.box.x1, t - fs // 2, tick_w, fs))
            labels.append(TextBox(text, bar.box.x1 + tick_w + fs, t - cell_h // 2, fs))
        if inside:
            readout = TextBox(READOUT_TEXT, depth_region.x0 + (xc + 3) * map_scale,
                              depth_region.y0 + (yc + 3) * map_scale, fs)
        else:
            readout = TextBox(READOUT_TEXT, depth_region.x0, depth_region.y1 + fs, fs)
        band = rectification = None
        if gap >= cell_h:
            band = TextBox(SEGMENT_TEXT, x_bottom, y_top + ih + (gap - cell_h) // 2, fs)
            if depth_region.x0 + len(RECTIFICATION_TEXT) * cell_w <= timing.h_active:
                rectification = TextBox(RECTIFICATION_TEXT, depth_region.x0, band.y0, fs)
        return cls(regions=(
            Region("left", x_left, y_top, 1, w, h, image_shrink),
            Region("right", x_left + iw + gap, y_top, 1, w, h, image_shrink),
            Region("disparity", x_bottom, y_bottom, map_scale, w, h),
            depth_region,
        ), bar=bar, ticks=tuple(ticks), labels=tuple(labels), readout=readout, band=band,
            rectification=rectification,
            crosshair_arm=min(arm, xc - 1, yc - 1, w - 1 - xc, h - 1 - yc))
