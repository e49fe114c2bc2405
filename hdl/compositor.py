"""Display compositor: the camera images, the difference map and the depth map on one video frame (thesis 4.3-4.5).

Inputs: the sync generator's raster (``timing``: :data:`hdl.video_bus.TimingSignature`), the switch registers
(``settings``: :data:`hdl.switches.SettingsSignature`), one read port per frame buffer (``left``, ``right``:
:class:`hdl.depth.SharedReadSignature`; the compositor raises ``request`` in every clock it reads and needs no
grant: its arbiter gives it priority) and the depth engine's result ring (``depth``:
:class:`hdl.depth.ResultReadSignature`). Output: a :data:`hdl.video_bus.VideoSignature` stream (``video``).

Layout (``layout``, default :meth:`spec.layout.DisplayLayout.centred`): each region shows its buffer with every
pixel repeated ``scale`` x ``scale`` times, or a camera image at 1 / ``shrink`` size (every ``shrink``-th pixel of
every ``shrink``-th row: :meth:`spec.layout.DisplayLayout.full_maps`) (docs/display.md, "Four panels").

* ``left`` / ``right``: the camera image, grey by bit replication (:func:`spec.display.grey_to_rgb24`).
* ``disparity``: the :class:`hdl.disparity.DisparitySubtractor` output, ``level_grey[level]`` or ``NO_DATA_RGB``.
* ``depth``: the engine's sub-pixel code through the colour map ROM (:func:`hdl.colour_map.colour_table`, the
  2**F D codes below the invalid one in block RAM, the invalid colour chosen after it); the crosshair
  (``CROSSHAIR_RGB``) on the centre row and column, 2 .. ``crosshair_arm`` buffer pixels from the centre; a row
  the engine has not finished (``rows_ready``) shows ``DEPTH_NOT_READY_RGB``. A finished depth row is released
  to the engine after its last display line.
* ``segment`` (when the layout allows it, :attr:`Compositor.segmentation`): the difference map's place shows the
  segmentation view instead (:class:`hdl.segment_band.SegmentBand`: the right image, dimmed outside the depth band
  around the disparity register, the engine's codes read from the result ring on the depth map's rows) and the
  layout's ``band`` text box the band in metres (spaces, so background, while ``segment`` is low).
* the colour bar (every whole disparity d in the colour of code 2**F d, near on top), the tick marks (``TEXT_RGB``), the distance labels and the
  centre-distance readout (:class:`hdl.text_layer.TextLayer`: glyph pixels ``TEXT_RGB``, the rest of a text box
  ``BACKGROUND_RGB``); the readout shows :class:`hdl.centre_distance.CentreDistance` of this frame's map, the
  layout's ``rectification`` box the rectification in use (:class:`hdl.rectification_text.RectificationText`).
* ``BACKGROUND_RGB`` elsewhere in the active area, ``rgb = 0`` outside it (``de`` low).

The image regions and the disparity computation share each buffer's port; they never overlap (checked), so the
compositor makes at most one read per port per clock. Addresses come from running counters
(:class:`hdl.region_scanner.RegionScanner`), so there is no per-pixel multiplier; they clear in vertical
blanking (``y >= v_active``).

Clock domain: ``sync`` (single domain; the parent places it in ``pix`` with ``DomainRenamer``).

Latency: **6 clocks**. ``video.rgb``/``de``/``hsync``/``vsync`` at clock ``n + 6`` describe the raster position
that ``timing`` gave at clock ``n``; ``de``/``hsync``/``vsync`` are the input ones delayed by 6 registers.

=======  ================================================================================================
clock    what happens
=======  ================================================================================================
n        ``timing`` in; compare ``x``/``y`` with the region bounds
n + 1    region flags registered; running counters give the buffer/ring address and coordinates
n + 2    read addresses and requests registered; crosshair, window and row-ready flags
n + 3    frame-buffer and result-ring read data (into the segmentation block too); the colour-map ROM's
         address: the code (depth map) or 2**F x the band's disparity (bar)
n + 4    read data registered (BRAM output register); the colour-map word and the invalid flag; the text
         layer's font pixel; the segmentation block's code and grey registered; the subtractor's valid and
         no-data flags (``next_valid``, ``next_no_data``)
n + 5    disparity level, the code's colour, the segmentation colour registered; the region's choice
         registered: which of four candidates to show and the colour of the first (a constant colour --
         background, text, no-data, not-ready, crosshair -- or the image grey)
n + 6    ``video`` registered: the chosen candidate (that colour, the level's grey, the code's colour or the
         segmentation colour): a 4:1 multiplexer a bit of registers
=======  ================================================================================================

Switch timing: ``settings`` are used only for pixels in the disparity region. They change
on the clock edge ending the ``frame_start`` clock (raster position 0, with :class:`hdl.switches.SwitchControl`)
and the subtractor needs them settled ``SETTLE_CLOCKS`` (2) clocks before it samples a pixel, one clock after the
raster gives it; the constructor checks that the region starts at least 2 pixels into the raster (the default
layouts start lines down). So every disparity pixel of a frame uses the values loaded at that frame's start.
"""

from amaranth import Cat, Const, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.centre_distance import SETTLE_CLOCKS as READOUT_SETTLE, CentreDistance
from hdl.colour_map import LATENCY as COLOUR_LATENCY, ColourMap
from hdl.delay import delayed
from hdl.depth.ports import ResultReadSignature, SharedReadSignature
from hdl.disparity import LATENCY as SUBTRACTOR_LATENCY, SETTLE_CLOCKS, DisparitySubtractor, check_thresholds
from spec.depth import DEPTH
from spec.display import (
    BACKGROUND_RGB,
    CROSSHAIR_RGB,
    DEPTH_NOT_READY_RGB,
    DIFF_LEVEL_GREY,
    NO_DATA_RGB,
    TEXT_RGB,
    diff_thresholds,
)
from spec.layout import DisplayLayout
from spec.sensor import SENSOR
from spec.video import CEA_1080P60
from hdl.rectification_text import LATENCY as RECTIFICATION_LATENCY, RectificationModeSignature, RectificationText
from hdl.region_scanner import RegionScanner
from hdl.segment_band import LATENCY as SEGMENT_LATENCY, SegmentBand
from hdl.switches import SettingsSignature
from hdl.text_layer import LATENCY as TEXT_LATENCY, TextLayer, char_codes
from hdl.video_bus import TimingSignature, VideoSignature
from hdl.reset_tree import add_reset_subtree

__all__ = ["Compositor", "LATENCY", "check_layout", "check_parameters", "segmentation_fits"]

#: Clocks from ``timing`` in to ``video`` out.
LATENCY = 6
#: The candidates of the last stage's colour choice (``pick_5``): the colour registered at n + 5 by region (a
#: constant or the image grey), the difference map's level grey, the code's colour, the segmentation colour.
_EARLY, _LEVEL, _COLOUR, _SEGMENT = range(4)
SOURCES = ("left", "right", "disparity", "depth")
#: The raster position from which the rectification text holds this frame's characters: the text block samples
#: one clock after ``frame_start`` (raster position 0) and has them :data:`hdl.rectification_text.LATENCY` clocks
#: later; the text layer reads a cell's character one clock after its raster position.
RECTIFICATION_SETTLE = 1 + RECTIFICATION_LATENCY


def _check_regions(layout, timing, geometry):
    regions = {}
    for r in layout.regions:
        if r.source not in SOURCES or r.source in regions:
            raise ValueError(f"layout needs exactly one region each for {SOURCES}, got {r.source!r} again "
                             "or unknown")
        regions[r.source] = r
    if set(regions) != set(SOURCES):
        raise ValueError(f"layout needs exactly one region each for {SOURCES}, got {sorted(regions)}")
    for r in regions.values():
        if (r.width, r.height) != (geometry.buf_width, geometry.buf_height):
            raise ValueError(f"region {r.source} is {r.width}x{r.height} but the buffers are "
                             f"{geometry.buf_width}x{geometry.buf_height}")
        if not isinstance(r.scale, int) or r.scale < 1:
            raise ValueError(f"region {r.source} needs a positive integer scale, not {r.scale!r}")
        if not isinstance(r.shrink, int) or r.shrink < 1:
            raise ValueError(f"region {r.source} needs a positive integer shrink, not {r.shrink!r}")
        if r.shrink > 1 and (r.source not in ("left", "right") or r.scale != 1
                             or r.width % r.shrink or r.height % r.shrink):
            raise ValueError(f"region {r.source}: only a camera image at scale 1 with a size divisible by "
                             f"{r.shrink} can be shown at 1/{r.shrink} size")
    return regions


def check_layout(layout, timing, geometry, config=DEPTH):
    """The regions by source; ``ValueError`` unless ``layout`` has one region per source, each a whole buffer at
    a positive integer scale (a camera image may instead be at 1 / ``shrink`` size), everything inside the active area and nothing overlapping (but the readout, which
    may lie inside the depth map), the colour bar has one band per code, the readout starts after the centre
    window's last line, the crosshair fits the map, the disparity map starts at least ``SETTLE_CLOCKS``
    pixels into the raster (so it never sees the switch registers change) and the rectification text at least
    :data:`RECTIFICATION_SETTLE` (so it shows only this frame's text)."""
    regions = _check_regions(layout, timing, geometry)
    if layout.bar is None or layout.readout is None:
        raise ValueError("layout needs a colour bar and a readout")
    if layout.bar.codes != config.disparities or layout.bar.step < 1 or layout.bar.width < 1:
        raise ValueError(f"the colour bar needs {config.disparities} bands of at least one row")
    named = [(f"region {r.source}", r.box) for r in regions.values()] + [("colour bar", layout.bar.box)]
    named += [(f"tick {i}", t) for i, t in enumerate(layout.ticks)]
    named += [(f"label {t.text!r}", t.box) for t in layout.labels]
    if layout.band is not None:
        named.append(("band text", layout.band.box))
    if layout.rectification is not None:
        named.append(("rectification text", layout.rectification.box))
    readout, depth = layout.readout.box, regions["depth"]
    for name, b in named + [("readout", readout)]:
        if b.x0 < 0 or b.y0 < 0 or b.x1 > timing.h_active or b.y1 > timing.v_active:
            raise ValueError(f"{name} [{b.x0}, {b.x1}) x [{b.y0}, {b.y1}) is outside the "
                             f"{timing.h_active}x{timing.v_active} active area")
    if not readout.inside(depth.box):                # over the depth map, or a place of its own
        named.append(("readout", readout))
    for i, (name_a, a) in enumerate(named):
        for name_b, b in named[i + 1:]:
            if a.overlaps(b):
                raise ValueError(f"{name_a} and {name_b} overlap")
    xc, yc = geometry.buf_width // 2, geometry.buf_height // 2
    if readout.y0 < depth.y0 + (yc + 2) * depth.scale:
        raise ValueError("the readout must start below the line after the centre window (buffer row "
                         f"{yc + 1}) so that it shows this frame's distance")
    arm = layout.crosshair_arm
    if not 0 <= arm <= min(xc, yc, geometry.buf_width - 1 - xc, geometry.buf_height - 1 - yc):
        raise ValueError(f"crosshair arm {arm} does not fit the {geometry.buf_width}x{geometry.buf_height} map")
    # The switch registers change on the edge ending frame_start's clock (raster position 0); the subtractor
    # samples raster position p one clock later and needs them SETTLE_CLOCKS clocks before that.
    first = regions["disparity"].y0 * timing.h_total + regions["disparity"].x0
    if first < SETTLE_CLOCKS:
        raise ValueError(f"the disparity region must start at least {SETTLE_CLOCKS} pixels after the raster "
                         "origin, where the switch registers change")
    if layout.rectification is not None:
        text = layout.rectification
        if text.y0 * timing.h_total + text.x0 < RECTIFICATION_SETTLE:
            raise ValueError(f"the rectification text must start at least {RECTIFICATION_SETTLE} pixels after the "
                             "raster origin, where its characters are still being computed")
    if timing.h_total < READOUT_SETTLE + LATENCY:
        raise ValueError("a line is too short for the centre distance to settle before the readout")
    return regions


def segmentation_fits(layout):
    """The segmentation view can take the difference map's place: the difference map is on the depth map's rows
    at its scale and left of it (so it reads each result-ring row before the depth map releases it)."""
    diff, depth = layout.region("disparity"), layout.region("depth")
    return (diff.y0, diff.scale) == (depth.y0, depth.scale) and diff.x1 <= depth.x0


def check_parameters(timing, geometry, layout, config, thresholds, level_grey):
    """``(layout, regions, thresholds, level_grey)`` of a :class:`Compositor`: the layout (``None``: centred), its
    regions by source (:func:`check_layout`), the threshold and grey tables as tuples; ``ValueError`` for what
    :class:`Compositor` rejects."""
    if layout is None:
        layout = DisplayLayout.centred(timing, geometry, config)
    regions = check_layout(layout, timing, geometry, config)
    if thresholds is None:
        thresholds = diff_thresholds(geometry.grey_bits)
    thresholds = check_thresholds(thresholds, geometry.grey_bits)
    grey = tuple(int(v) for v in level_grey)
    if len(grey) != len(thresholds) + 1 or any(not 0 <= v <= 255 for v in grey):
        raise ValueError(f"level_grey needs {len(thresholds) + 1} entries in 0..255 (one per level), "
                         f"got {level_grey!r}")
    if geometry.grey_bits > 8:
        raise ValueError(f"grey_bits = {geometry.grey_bits}: the display shows at most 8 bits of grey")
    for box in layout.labels:
        char_codes(box.text)
    return layout, regions, thresholds, grey


class Compositor(wiring.Component):
    """Lays out the camera images, the difference map and the depth map on the video frame; latency 6 clocks.

    See the module docstring for the layout, the pipeline and the switch timing.

    Parameters
    ----------
    timing : :class:`spec.video.VideoTiming`
    geometry : :class:`spec.sensor.SensorGeometry`
    layout : :class:`spec.layout.DisplayLayout` or None
        Default: :meth:`~spec.layout.DisplayLayout.centred`.
    config : :class:`spec.depth.DepthConfig`
        The depth engine's D (codes 0..D, D = invalid).
    out_rows : int
        Rows in the engine's result ring.
    thresholds : sequence of int or None
        The subtractor's threshold table; None: :func:`spec.display.diff_thresholds` of the grey bits.
    level_grey : sequence of int
        The 8-bit grey shown for each level (one more entry than ``thresholds``).

    Attributes
    ----------
    timing : ``In(TimingSignature)``
        The raster (the video mode is ``video_timing``).
    settings : ``In(SettingsSignature)``
    segment : ``In(1)``
        Show the segmentation view (static through a frame; no effect unless :attr:`segmentation`).
    rectification_mode : ``In(RectificationModeSignature)``
        Automatic mode and held verdict for the rectification text (sampled one clock after ``frame_start``; no
        effect when the layout has no ``rectification`` box).
    segmentation : bool
        The layout allows the segmentation view (:func:`segmentation_fits`).
    dynamic : dict
        The text layer's boxes of changing text by name (``readout``; ``band``, ``rectification`` where the
        layout has them).
    left, right : ``Out(SharedReadSignature(geometry))``
        ``grant`` is not used (the arbiter gives the compositor priority).
    depth : ``Out(ResultReadSignature(...))``
        The engine's result ring.
    video : ``Out(VideoSignature)``

    Raises
    ------
    ValueError
        A layout that does not fit, overlaps or starts too early (:func:`check_layout`), a bad threshold or grey
        table, more than 8 bits of grey, a label character the font lacks.
    """

    def __init__(self, timing=CEA_1080P60, geometry=SENSOR, layout=None, *, config=DEPTH, out_rows=4,
                 thresholds=None, level_grey=DIFF_LEVEL_GREY):
        layout, self.regions, self.thresholds, self.level_grey = check_parameters(
            timing, geometry, layout, config, thresholds, level_grey)
        self.video_timing = timing          # (the ``timing`` attribute is the TimingSignature port)
        self.geometry, self.config, self.out_rows = geometry, config, out_rows
        self.layout = layout
        g = geometry
        ring_addr_bits = (out_rows * g.buf_width - 1).bit_length()
        super().__init__({
            "timing": In(TimingSignature),
            "settings": In(SettingsSignature),
            "segment": In(1),
            "rectification_mode": In(RectificationModeSignature),
            "left": Out(SharedReadSignature(g)),
            "right": Out(SharedReadSignature(g)),
            "depth": Out(ResultReadSignature(ring_addr_bits, config.code_bits, g.buf_height)),
            "video": Out(VideoSignature),
        })
        self.segmentation = segmentation_fits(layout)
        self.dynamic = {"readout": layout.readout}          # the text layer's boxes of changing text
        if self.segmentation and layout.band is not None:
            self.dynamic["band"] = layout.band
        if layout.rectification is not None:
            self.dynamic["rectification"] = layout.rectification

    def elaborate(self, platform):
        m = Module()
        g = self.geometry
        inside, eol, vblank_1 = self._region_flags(m)
        de_d, hsync_d, vsync_d = self._delay_line(m)
        scanners = self._scanners(m, inside, eol, vblank_1)
        sub = add_reset_subtree(m, "subtractor", DisparitySubtractor(g, self.thresholds))
        wiring.connect(m, wiring.flipped(self.settings), sub.settings)     # the switch registers: the subtractor's
        m.d.comb += [            # the disparity region's pixels (latency SUBTRACTOR_LATENCY = 4)
            sub.valid.eq(inside["disparity"]),
            sub.x.eq(scanners["disparity"].xb),
            sub.y.eq(scanners["disparity"].yb),
            sub.addr.eq(scanners["disparity"].addr),
        ]
        distance = add_reset_subtree(m, "distance", CentreDistance(g, self.config))
        text = add_reset_subtree(m, "text", TextLayer(self.layout.labels, self.dynamic,
                                                      v_active=self.video_timing.v_active,
                                                      x_bits=len(self.timing.x), y_bits=len(self.timing.y)))
        m.d.comb += [text.x.eq(self.timing.x), text.y.eq(self.timing.y), text.chars.readout.eq(distance.chars)]
        if "rectification" in self.dynamic:
            self._rectification_text(m, text)
        image_4 = self._image_reads(m, inside, scanners, sub)
        view_4 = self._depth_reads(m, inside, scanners, vblank_1, distance, text)
        segment = self._segment_view(m, scanners, text)
        self._colour(m, image_4, view_4, segment, de_d[4], sub)
        m.d.comb += [
            self.video.de.eq(de_d[LATENCY]),
            self.video.hsync.eq(hsync_d[LATENCY]),
            self.video.vsync.eq(vsync_d[LATENCY]),
        ]
        return m

    def _region_flags(self, m):
        """Clock n -> n + 1: region flags, end-of-region-line flags, vertical blanking."""
        raster, layout = self.timing, self.layout

        def within(b, name):
            # A box that starts right of column 0 takes its row range from the previous clock's y, registered:
            # the raster is in scan order, so y changes only where x returns to 0, outside such a box. The
            # comparisons of x and of y are then in different clocks (no deep shared compare tree).
            across = (raster.x >= b.x0) & (raster.x < b.x1)
            if b.x0 == 0:
                return across & (raster.y >= b.y0) & (raster.y < b.y1)
            down = Signal(name=f"{name}_rows_0")
            m.d.sync += down.eq((raster.y >= b.y0) & (raster.y < b.y1))
            return across & down

        inside, eol = {}, {}
        areas = {source: r.box for source, r in self.regions.items()}
        areas["bar"] = layout.bar.box
        for source, b in areas.items():
            inside[source] = Signal(name=f"in_{source}_1")
            eol[source] = Signal(name=f"eol_{source}_1")
            m.d.sync += [inside[source].eq(within(b, source)), eol[source].eq(raster.x == b.x1 - 1)]
        # The ticks in two registered stages (each tick's x and y ranges, then their OR): in_tick_2 is one clock
        # later than the other region flags; its delay line is one register shorter.
        spans = []
        for k, t in enumerate(layout.ticks):
            across, down = Signal(name=f"tick{k}_x_1"), Signal(name=f"tick{k}_y_1")
            m.d.sync += [across.eq((raster.x >= t.x0) & (raster.x < t.x1)),
                         down.eq((raster.y >= t.y0) & (raster.y < t.y1))]
            spans.append(across & down)
        inside["tick"] = Signal(name="in_tick_2")
        m.d.sync += inside["tick"].eq(_or(spans))
        vblank_1 = Signal(name="vblank_1")
        m.d.sync += vblank_1.eq(raster.y >= self.video_timing.v_active)
        return inside, eol, vblank_1

    def _delay_line(self, m):
        """The raster's de and syncs through LATENCY registers (starting with the pulses inactive)."""
        t, raster = self.video_timing, self.timing
        de_d, hsync_d, vsync_d = [raster.de], [raster.hsync], [raster.vsync]
        hsync_idle = 0 if t.hsync_positive else 1
        vsync_idle = 0 if t.vsync_positive else 1
        for i in range(1, LATENCY + 1):
            de_i = Signal(name=f"de_{i}")
            hs_i = Signal(name=f"hsync_{i}", init=hsync_idle)
            vs_i = Signal(name=f"vsync_{i}", init=vsync_idle)
            m.d.sync += [de_i.eq(de_d[-1]), hs_i.eq(hsync_d[-1]), vs_i.eq(vsync_d[-1])]
            de_d.append(de_i)
            hsync_d.append(hs_i)
            vsync_d.append(vs_i)
        return de_d, hsync_d, vsync_d

    def _scanners(self, m, inside, eol, vblank_1):
        """Clock n + 1: the running counters of the regions (the depth map's address wraps around the ring)
        and the colour bar's band."""
        g, bar = self.geometry, self.layout.bar
        scanners = {}
        for source, r in self.regions.items():
            wrap = self.out_rows * g.buf_width if source == "depth" else None
            scanners[source] = RegionScanner(g.buf_width, g.buf_height, r.scale, wrap=wrap, stride=r.shrink)
        scanners["bar"] = RegionScanner(1, bar.codes, bar.width, bar.step)
        flags = {source: source for source in scanners}
        if self.segmentation:       # the segmentation view's ring addresses over the difference map's region
            r = self.regions["disparity"]
            scanners["segment"] = RegionScanner(g.buf_width, g.buf_height, r.scale, wrap=self.out_rows * g.buf_width)
            flags["segment"] = "disparity"
        for source, sc in scanners.items():
            m.submodules[f"scan_{source}"] = sc
            flag = flags[source]
            m.d.comb += [sc.active.eq(inside[flag]), sc.eol.eq(eol[flag] & inside[flag]), sc.clear.eq(vblank_1)]
        return scanners

    def _image_reads(self, m, inside, scanners, sub):
        """Clocks n + 2 .. n + 4: each read port serves its image region or the subtractor ``sub``; the image grey
        and its flag at n + 4 (``grey``, ``show``)."""
        g = self.geometry
        # n + 2: read addresses; the subtractor registers its own addresses from the disparity flag at n + 1.
        show_left_2, show_right_2 = Signal(name="show_left_2"), Signal(name="show_right_2")
        subtracting_2 = Signal(name="subtracting_2")
        left_img_addr_2 = Signal(g.addr_bits, name="left_img_addr_2")
        right_img_addr_2 = Signal(g.addr_bits, name="right_img_addr_2")
        m.d.sync += [
            show_left_2.eq(inside["left"]),
            show_right_2.eq(inside["right"]),
            subtracting_2.eq(inside["disparity"]),
            left_img_addr_2.eq(scanners["left"].addr),
            right_img_addr_2.eq(scanners["right"].addr),
        ]
        m.d.comb += [
            self.left.port.addr.eq(Mux(show_left_2, left_img_addr_2, sub.left.addr)),
            self.right.port.addr.eq(Mux(show_right_2, right_img_addr_2, sub.right.addr)),
            self.left.request.eq(show_left_2 | subtracting_2),
            self.right.request.eq(show_right_2 | subtracting_2),
            sub.left.data.eq(self.left.port.data),
            sub.right.data.eq(self.right.port.data),
        ]
        # n + 3 -> n + 4: register the image read data
        show_left_4 = delayed(m, show_left_2, 2, "show_left")
        show_right_4 = delayed(m, show_right_2, 2, "show_right")
        left_q_4, right_q_4 = Signal(g.grey_bits, name="left_q_4"), Signal(g.grey_bits, name="right_q_4")
        m.d.sync += [left_q_4.eq(self.left.port.data), right_q_4.eq(self.right.port.data)]
        # n + 4: the image grey and whether it is shown (into the colour choice); the subtractor's level arrives at
        # n + 5
        assert SUBTRACTOR_LATENCY == 4, "the stage numbering above assumes the subtractor's 4-clock latency"
        return dict(grey=Mux(show_left_4, left_q_4, right_q_4), show=show_left_4 | show_right_4)

    def _depth_reads(self, m, inside, scanners, vblank_1, distance, text):
        """Clocks n + 1 .. n + 5: the depth map from the result ring (rows released as they are shown), the
        crosshair, the centre window (into ``distance``), the bar's band and the colour of the code (``colour``, at
        n + 5); the region flags, the crosshair and row-ready flags and ``text``'s flags at n + 4."""
        g, cfg, arm = self.geometry, self.config, self.layout.crosshair_arm
        scan, result = scanners["depth"], self.depth
        with m.If(vblank_1):
            m.d.sync += result.rows_released.eq(0)
        with m.Elif(scan.row_done):
            m.d.sync += result.rows_released.eq(result.rows_released + 1)
        xb, yb, xc, yc = scan.xb, scan.yb, g.buf_width // 2, g.buf_height // 2
        in_depth_2, ready_2, cross_2 = Signal(name="in_depth_2"), Signal(name="ready_2"), Signal(name="cross_2")
        window_2, bar_code_2 = Signal(9, name="window_2"), Signal(cfg.code_bits, name="bar_code_2")
        ring_addr_2 = Signal.like(result.addr, name="ring_addr_2")
        ring_scan_addr = scan.addr          # the segmentation view reads the ring in the difference map's region
        if self.segmentation:
            ring_scan_addr = Mux(inside["disparity"], scanners["segment"].addr, scan.addr)
        arm_x = ((xb + 2 <= xc) & (xb + arm >= xc)) | ((xb >= xc + 2) & (xb <= xc + arm))
        arm_y = ((yb + 2 <= yc) & (yb + arm >= yc)) | ((yb >= yc + 2) & (yb <= yc + arm))
        m.d.sync += [
            in_depth_2.eq(inside["depth"]), ready_2.eq(yb < result.rows_ready), ring_addr_2.eq(ring_scan_addr),
            cross_2.eq(((yb == yc) & arm_x) | ((xb == xc) & arm_y)),
            window_2.eq(Cat(((xb == xc + dx) & (yb == yc + dy)) for dy in (-1, 0, 1) for dx in (-1, 0, 1))),
            bar_code_2.eq(cfg.disparities - 1 - scanners["bar"].yb),
        ]
        m.d.comb += result.addr.eq(ring_addr_2)
        # n + 3: the ring's data; the centre window.
        in_depth_3, window_3 = delayed(m, in_depth_2, 1, "in_depth"), delayed(m, window_2, 1, "window")
        m.d.comb += [distance.capture.eq(Mux(in_depth_3, window_3, 0)), distance.code.eq(result.data)]
        # n + 3: the code to colour (the ring's data, or the bar's whole disparity d as code 2**F d) into the
        # colour map (its ROM read at n + 3, the word at n + 4); the colour registered at n + 5.
        m.submodules.colour_map = colour_map = ColourMap(cfg)
        m.d.comb += colour_map.code.eq(Mux(in_depth_3, result.data,
                                           delayed(m, bar_code_2, 1, "bar_code") << cfg.fraction_bits))
        colour_5 = colour_map.rgb                                       # n + 3 + COLOUR_LATENCY
        return dict(colour=colour_5, depth=delayed(m, in_depth_3, COLOUR_LATENCY - 1, "in_depth_3"),
                    ready=delayed(m, ready_2, 2, "ready"), cross=delayed(m, cross_2, 2, "cross"),
                    bar=delayed(m, inside["bar"], 3, "in_bar"), tick=delayed(m, inside["tick"], 2, "in_tick"),
                    in_text=delayed(m, text.in_text, 4 - TEXT_LATENCY, "in_text"),
                    lit=delayed(m, text.lit, 4 - TEXT_LATENCY, "lit"))

    def _rectification_text(self, m, text):
        """The rectification in use as text: sampled one clock after ``frame_start``, when the settings of this
        frame have loaded (they change on the edge that ends the ``frame_start`` clock)."""
        m.submodules.rectification_text = rt = RectificationText()
        frame_start_1 = Signal()
        m.d.sync += frame_start_1.eq(self.timing.frame_start)
        m.d.comb += [rt.frame_start.eq(frame_start_1), rt.offset.eq(self.settings.rectification),
                     rt.mode.auto.eq(self.rectification_mode.auto), rt.mode.held.eq(self.rectification_mode.held),
                     text.chars.rectification.eq(rt.chars)]

    def _segment_view(self, m, scanners, text):
        """Clocks n + 2 .. n + 5: the segmentation view's colour (``rgb``, at n + 5, from the ring's code and the right
        port's grey at n + 3) and whether it is shown at n + 4 (``on``: ``segment`` registered once; ``ready``: the
        ring row is ready), its band into ``text``; None without segmentation."""
        if not self.segmentation:
            return None
        m.submodules.segment_band = seg = SegmentBand(self.geometry, self.config)
        ready_2 = Signal(name="segment_ready_2")
        m.d.sync += ready_2.eq(scanners["segment"].yb < self.depth.rows_ready)
        m.d.comb += [seg.disparity.eq(self.settings.disparity), seg.enable.eq(self.segment),
                     seg.code.eq(self.depth.data), seg.grey.eq(self.right.port.data)]
        if "band" in self.dynamic:
            m.d.comb += text.chars.band.eq(seg.chars)
        assert SEGMENT_LATENCY == 2, "the stage numbering assumes the segmentation block's 2-clock latency"
        # ``segment`` may come from a comparison of the switch registers: registered before it joins the colour
        # choice. It changes at frame_start; the difference map starts at least SETTLE_CLOCKS pixels later.
        on_1 = Signal(name="segment_on_1")
        m.d.sync += on_1.eq(self.segment)
        return dict(rgb=seg.rgb, ready=delayed(m, ready_2, 2, "segment_ready"), on=on_1)

    def _colour(self, m, image_4, view_4, segment, de_4, sub):
        """Clocks n + 4 -> n + 6: the colour chosen by region, in two registered steps.

        n + 4 -> n + 5: from the region flags, the choice of one of four candidates (``pick_5``) and the colour of
        the :data:`_EARLY` candidate (``early_5``: a constant colour or the image grey); n + 5 -> n + 6: ``video.rgb``
        = the picked one of ``early_5``, the difference map's level grey (``sub.level``, a register at n + 5), the
        segmentation colour and the code's colour (registers at n + 5): a 4:1 multiplexer a bit after one level of
        logic on the level. The subtractor's ``next_valid`` / ``next_no_data`` are its ``out_valid`` / ``no_data``
        at n + 4."""
        early_4, pick_4 = Signal(24, name="early_4"), Signal(2, name="pick_4")
        # Reset-less: in reset de_4 is low, so they load the reset choice (colour 0) every clock anyway, and the
        # synthesis has no reset logic to fold into their set/reset pins.
        early_5 = Signal(24, name="early_5", reset_less=True)
        pick_5 = Signal(2, name="pick_5", reset_less=True)
        grey8 = self._replicate_to_8_bits(image_4["grey"])
        m.d.comb += pick_4.eq(_EARLY)
        with m.If(~de_4):
            m.d.comb += early_4.eq(0)
        with m.Elif(view_4["in_text"]):
            m.d.comb += early_4.eq(Mux(view_4["lit"], TEXT_RGB, BACKGROUND_RGB))
        with m.Elif(sub.next_valid):
            if segment is not None:
                with m.If(segment["on"]):
                    with m.If(segment["ready"]):
                        m.d.comb += pick_4.eq(_SEGMENT)
                    with m.Else():
                        m.d.comb += early_4.eq(DEPTH_NOT_READY_RGB)
                with m.Elif(sub.next_no_data):
                    m.d.comb += early_4.eq(NO_DATA_RGB)
                with m.Else():
                    m.d.comb += pick_4.eq(_LEVEL)
            else:
                with m.If(sub.next_no_data):
                    m.d.comb += early_4.eq(NO_DATA_RGB)
                with m.Else():
                    m.d.comb += pick_4.eq(_LEVEL)
        with m.Elif(image_4["show"]):
            m.d.comb += early_4.eq(Cat(grey8, grey8, grey8))
        with m.Elif(view_4["depth"]):
            with m.If(~view_4["ready"]):
                m.d.comb += early_4.eq(DEPTH_NOT_READY_RGB)
            with m.Elif(view_4["cross"]):
                m.d.comb += early_4.eq(CROSSHAIR_RGB)
            with m.Else():
                m.d.comb += pick_4.eq(_COLOUR)
        with m.Elif(view_4["bar"]):
            m.d.comb += pick_4.eq(_COLOUR)
        with m.Elif(view_4["tick"]):
            m.d.comb += early_4.eq(TEXT_RGB)
        with m.Else():
            m.d.comb += early_4.eq(BACKGROUND_RGB)
        m.d.sync += [early_5.eq(early_4), pick_5.eq(pick_4)]
        level_rgb = Signal(24, name="level_rgb")
        with m.Switch(sub.level):
            for level, v in enumerate(self.level_grey[:-1]):
                with m.Case(level):
                    m.d.comb += level_rgb.eq((v << 16) | (v << 8) | v)
            with m.Default():                       # the top level (the subtractor never exceeds it)
                v = self.level_grey[-1]
                m.d.comb += level_rgb.eq((v << 16) | (v << 8) | v)
        with m.Switch(pick_5):
            with m.Case(_EARLY):
                m.d.sync += self.video.rgb.eq(early_5)
            with m.Case(_LEVEL):
                m.d.sync += self.video.rgb.eq(level_rgb)
            with m.Case(_COLOUR):
                m.d.sync += self.video.rgb.eq(view_4["colour"])
            if segment is not None:
                with m.Case(_SEGMENT):
                    m.d.sync += self.video.rgb.eq(segment["rgb"])

    @staticmethod
    def _replicate_to_8_bits(grey):
        """The 8-bit value whose bits are ``grey``'s bits repeated from the MSB down (5 bits: g4..g0 g4 g3 g2)."""
        bits = []
        while len(bits) < 8:
            bits.extend(grey[i] for i in reversed(range(len(grey))))   # MSB first
        return Cat(*reversed(bits[:8]))


def _or(values):
    out = Const(0)
    for v in values:
        out = out | v
    return out
