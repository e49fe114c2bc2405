"""Display compositor: the left image, the right image and the disparity map on one video frame (thesis 4.3-4.5).

Inputs: the sync generator's raster (``timing``: :data:`hdl.video_bus.TimingSignature`), the switch registers
(``settings``: :data:`hdl.switches.SettingsSignature`) and one read port per frame buffer (``left``, ``right``:
:class:`hdl.frame_buffer.FrameBufferReadSignature`, data one clock after the address). Output: a
:data:`hdl.video_bus.VideoSignature` stream (``video``).

Layout (``layout``, default :meth:`hdl.params.DisplayLayout.centred`): each region shows its buffer with every
pixel repeated ``scale`` x ``scale`` times.

* ``left`` / ``right``: the camera image, grey by bit replication of the ``gray_bits`` value to 8 bits per
  channel (what :func:`hdl.params.gray_to_rgb24` specifies).
* ``disparity``: the :class:`hdl.disparity.DisparitySubtractor` output for the buffer pixel, shown as
  ``level_grey[level]`` on all three channels, or ``NO_DATA_RGB`` where the shifted left read falls outside
  the image.
* ``BACKGROUND_RGB`` elsewhere in the active area, ``rgb = 0`` outside it (``de`` low).

Each buffer has a single read port shared by the image region and the disparity computation; the regions never
overlap (checked), so each port serves at most one read per clock. Addresses come from running counters (one
per region: increment per buffer pixel, rewind to the row start to repeat a row ``scale`` times), so there is
no per-pixel multiplier; the counters clear in vertical blanking (``y >= v_active``).

Clock domain: ``sync`` (single domain; the parent places it in ``pix`` with ``DomainRenamer``).

Latency: **6 clocks**. ``video.rgb``/``de``/``hsync``/``vsync`` at clock ``n + 6`` describe the raster position
that ``timing`` gave at clock ``n``; ``de``/``hsync``/``vsync`` are the input ones delayed by 6 registers.

=======  ================================================================================================
clock    what happens
=======  ================================================================================================
n        ``timing`` in; compare ``x``/``y`` with the region bounds
n + 1    region flags registered; running counters give the buffer address/coordinates of the pixel
n + 2    read addresses registered (image counter or subtractor address, per port)
n + 3    frame-buffer read data
n + 4    read data registered (BRAM output register)
n + 5    disparity level / no-data and the image grey registered
n + 6    ``video`` registered: the colour chosen by region
=======  ================================================================================================

Switch timing: ``settings`` are used only for pixels in the disparity region. They change
on the clock edge ending the ``frame_start`` clock (raster position 0, with :class:`hdl.switches.SwitchControl`)
and the subtractor needs them settled ``SETTLE_CLOCKS`` (2) clocks before it samples a pixel, one clock after the
raster gives it; the constructor checks that the region starts at least 2 pixels into the raster (the default
layouts start tens of lines down). So every disparity pixel of a frame uses the values loaded at that frame's
start.
"""

from amaranth import Cat, Const, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from .disparity import LATENCY as SUBTRACTOR_LATENCY, SETTLE_CLOCKS, DisparitySubtractor, check_thresholds
from .forward import forward
from .frame_buffer import FrameBufferReadSignature
from .params import (BACKGROUND_RGB, CEA_1080P60, DIFF_LEVEL_GREY, DIFF_THRESHOLDS, NO_DATA_RGB, SENSOR,
                     DisplayLayout)
from .switches import SettingsSignature
from .video_bus import TimingSignature, VideoSignature
from .rejecting import rejecting

__all__ = ["Compositor", "LATENCY"]

#: Clocks from ``timing`` in to ``video`` out.
LATENCY = 6
SOURCES = ("left", "right", "disparity")


def check_layout(layout, timing, geometry):
    """``ValueError`` unless ``layout`` has one region per source, each a whole buffer at a positive integer
    scale inside the active area, the regions do not overlap and the disparity map starts at least
    ``SETTLE_CLOCKS`` pixels into the raster (so it never sees the switch registers change)."""
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
        if r.x0 < 0 or r.y0 < 0 or r.x1 > timing.h_active or r.y1 > timing.v_active:
            raise ValueError(f"region {r.source} [{r.x0}, {r.x1}) x [{r.y0}, {r.y1}) is outside the "
                             f"{timing.h_active}x{timing.v_active} active area")
    rs = list(regions.values())
    for i, a in enumerate(rs):
        for b in rs[i + 1:]:
            if a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1:
                raise ValueError(f"regions {a.source} and {b.source} overlap")
    # The switch registers change on the edge ending frame_start's clock (raster position 0); the subtractor
    # samples raster position p one clock later and needs them SETTLE_CLOCKS clocks before that.
    first = regions["disparity"].y0 * timing.h_total + regions["disparity"].x0
    if first < SETTLE_CLOCKS:
        raise ValueError(f"the disparity region must start at least {SETTLE_CLOCKS} pixels after the raster "
                         "origin, where the switch registers change")
    return regions


class _RegionScanner(wiring.Component):
    """Running address of one region: the buffer address and coordinates of the current display pixel.

    Inputs (registered flags of the pixel at this clock): ``active`` (pixel inside the region), ``eol`` (last
    pixel of a region line), ``clear`` (vertical blanking). Outputs, valid while ``active``: ``addr`` =
    ``yb * buf_width + xb`` and ``xb``, ``yb``, all registers (no logic between them and the outputs).
    """

    def __init__(self, geometry, scale):
        self.geometry = geometry
        self.scale = scale
        super().__init__({
            "active": In(1),
            "eol": In(1),
            "clear": In(1),
            "addr": Out(geometry.addr_bits),
            "xb": Out(range(geometry.buf_width)),
            "yb": Out(range(geometry.buf_height)),
        })

    def elaborate(self, platform):
        m = Module()
        s = self.scale
        row_start = Signal.like(self.addr)          # address of (0, yb): where a repeated row rewinds to
        if s > 1:
            x_phase = Signal(range(s))             # which of the s copies of a pixel this is
            y_phase = Signal(range(s))             # which of the s copies of a row this is
            last_x_copy, last_y_copy = x_phase == s - 1, y_phase == s - 1
        else:                                      # every pixel and row is the last (only) copy
            last_x_copy = last_y_copy = Const(1)
        with m.If(self.clear):
            m.d.sync += [self.addr.eq(0), row_start.eq(0), self.xb.eq(0), self.yb.eq(0)]
            if s > 1:
                m.d.sync += [x_phase.eq(0), y_phase.eq(0)]
        with m.Elif(self.active & self.eol):
            m.d.sync += self.xb.eq(0)
            if s > 1:
                m.d.sync += x_phase.eq(0)
            with m.If(last_y_copy):                 # next buffer row
                m.d.sync += [self.addr.eq(self.addr + 1), row_start.eq(self.addr + 1), self.yb.eq(self.yb + 1)]
                if s > 1:
                    m.d.sync += y_phase.eq(0)
            if s > 1:
                with m.Else():                      # repeat this buffer row
                    m.d.sync += [self.addr.eq(row_start), y_phase.eq(y_phase + 1)]
        with m.Elif(self.active):
            with m.If(last_x_copy):                 # next buffer pixel
                m.d.sync += [self.addr.eq(self.addr + 1), self.xb.eq(self.xb + 1)]
                if s > 1:
                    m.d.sync += x_phase.eq(0)
            if s > 1:
                with m.Else():                      # another copy of the same buffer pixel
                    m.d.sync += x_phase.eq(x_phase + 1)
        return m


class Compositor(wiring.Component):
    """Lays the left image, the right image and the disparity map out on the video frame; latency 6 clocks.

    See the module docstring for the layout, the pipeline and the switch timing.

    Parameters
    ----------
    timing : :class:`hdl.params.VideoTiming`
    geometry : :class:`hdl.params.SensorGeometry`
    layout : :class:`hdl.params.DisplayLayout` or None
        Default: :meth:`~hdl.params.DisplayLayout.centred`.
    thresholds : sequence of int
        The subtractor's threshold table.
    level_grey : sequence of int
        The 8-bit grey shown for each level (one more entry than ``thresholds``).

    Attributes
    ----------
    timing : ``In(TimingSignature)``
        The raster (the video mode is ``video_timing``).
    settings : ``In(SettingsSignature)``
    left, right : ``Out(FrameBufferReadSignature(geometry))``
    video : ``Out(VideoSignature)``

    Raises
    ------
    ValueError
        A layout that does not fit, overlaps or starts too early (:func:`check_layout`), a bad threshold or grey
        table, more than 8 bits of grey.
    """

    def __init__(self, timing=CEA_1080P60, geometry=SENSOR, layout=None, *, thresholds=DIFF_THRESHOLDS,
                 level_grey=DIFF_LEVEL_GREY):
        with rejecting(self):
            if layout is None:
                layout = DisplayLayout.centred(timing, geometry)
            self.video_timing = timing          # (the ``timing`` attribute is the TimingSignature port)
            self.geometry = geometry
            self.layout = layout
            self.regions = check_layout(layout, timing, geometry)
            self.thresholds = check_thresholds(thresholds, geometry.gray_bits)
            self.level_grey = tuple(int(v) for v in level_grey)
            if len(self.level_grey) != len(self.thresholds) + 1 or any(not 0 <= v <= 255 for v in self.level_grey):
                raise ValueError(f"level_grey needs {len(self.thresholds) + 1} entries in 0..255 (one per level), "
                                 f"got {level_grey!r}")
            if geometry.gray_bits > 8:
                raise ValueError(f"gray_bits = {geometry.gray_bits}: the display shows at most 8 bits of grey")
            g = geometry
            super().__init__({
                "timing": In(TimingSignature),
                "settings": In(SettingsSignature),
                "left": Out(FrameBufferReadSignature(g)),
                "right": Out(FrameBufferReadSignature(g)),
                "video": Out(VideoSignature),
            })
            self._subtractor = DisparitySubtractor(g, self.thresholds)
            forward(self, "settings", self._subtractor.settings)     # the switch registers go to the subtractor only

    def elaborate(self, platform):
        m = Module()
        inside, eol, vblank_1 = self._region_flags(m)
        de_d, hsync_d, vsync_d = self._delay_line(m)
        scanners = self._scanners(m, inside, eol, vblank_1)
        m.submodules.subtractor = sub = self._subtractor
        m.d.comb += [            # the disparity region's pixels (latency SUBTRACTOR_LATENCY = 4)
            sub.valid.eq(inside["disparity"]),
            sub.x.eq(scanners["disparity"].xb),
            sub.y.eq(scanners["disparity"].yb),
            sub.addr.eq(scanners["disparity"].addr),
        ]
        grey_5, show_image_5 = self._image_reads(m, inside, scanners)
        self._colour(m, grey_5, show_image_5, de_d[5])
        m.d.comb += [
            self.video.de.eq(de_d[LATENCY]),
            self.video.hsync.eq(hsync_d[LATENCY]),
            self.video.vsync.eq(vsync_d[LATENCY]),
        ]
        return m

    def _region_flags(self, m):
        """Clock n -> n + 1: region flags, end-of-region-line flags, vertical blanking."""
        raster = self.timing
        inside, eol = {}, {}
        for source, r in self.regions.items():
            inside[source] = Signal(name=f"in_{source}_1")
            eol[source] = Signal(name=f"eol_{source}_1")
            in_x = (raster.x >= r.x0) & (raster.x < r.x1)
            in_y = (raster.y >= r.y0) & (raster.y < r.y1)
            m.d.sync += [inside[source].eq(in_x & in_y), eol[source].eq(raster.x == r.x1 - 1)]
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
        """Clock n + 1: the running counters of the three regions."""
        scanners = {}
        for source, r in self.regions.items():
            sc = scanners[source] = _RegionScanner(self.geometry, r.scale)
            m.submodules[f"scan_{source}"] = sc
            m.d.comb += [sc.active.eq(inside[source]), sc.eol.eq(eol[source] & inside[source]),
                         sc.clear.eq(vblank_1)]
        return scanners

    def _image_reads(self, m, inside, scanners):
        """Clocks n + 2 .. n + 5: each read port serves its image region or the subtractor; the image grey."""
        g, sub = self.geometry, self._subtractor
        # n + 2: read addresses
        show_left_2, show_right_2 = Signal(name="show_left_2"), Signal(name="show_right_2")
        left_img_addr_2 = Signal(g.addr_bits, name="left_img_addr_2")
        right_img_addr_2 = Signal(g.addr_bits, name="right_img_addr_2")
        m.d.sync += [
            show_left_2.eq(inside["left"]),
            show_right_2.eq(inside["right"]),
            left_img_addr_2.eq(scanners["left"].addr),
            right_img_addr_2.eq(scanners["right"].addr),
        ]
        m.d.comb += [
            self.left.addr.eq(Mux(show_left_2, left_img_addr_2, sub.left.addr)),
            self.right.addr.eq(Mux(show_right_2, right_img_addr_2, sub.right.addr)),
            sub.left.data.eq(self.left.data),
            sub.right.data.eq(self.right.data),
        ]
        # n + 3 -> n + 4: register the image read data
        show_left_3, show_right_3 = Signal(name="show_left_3"), Signal(name="show_right_3")
        m.d.sync += [show_left_3.eq(show_left_2), show_right_3.eq(show_right_2)]
        left_q_4, right_q_4 = Signal(g.gray_bits, name="left_q_4"), Signal(g.gray_bits, name="right_q_4")
        show_left_4, show_right_4 = Signal(name="show_left_4"), Signal(name="show_right_4")
        m.d.sync += [
            left_q_4.eq(self.left.data),
            right_q_4.eq(self.right.data),
            show_left_4.eq(show_left_3),
            show_right_4.eq(show_right_3),
        ]
        # n + 4 -> n + 5: the image grey; the subtractor's level arrives at n + 5
        grey_5 = Signal(g.gray_bits, name="grey_5")
        show_image_5 = Signal(name="show_image_5")
        m.d.sync += [
            grey_5.eq(Mux(show_left_4, left_q_4, right_q_4)),
            show_image_5.eq(show_left_4 | show_right_4),
        ]
        assert SUBTRACTOR_LATENCY == 4, "the stage numbering above assumes the subtractor's 4-clock latency"
        return grey_5, show_image_5

    def _colour(self, m, grey_5, show_image_5, de_5):
        """Clock n + 5 -> n + 6: the colour chosen by region."""
        sub = self._subtractor
        grey8 = self._replicate_to_8_bits(grey_5)
        level_rgb = Signal(24, name="level_rgb")
        with m.Switch(sub.level):
            for level, v in enumerate(self.level_grey[:-1]):
                with m.Case(level):
                    m.d.comb += level_rgb.eq((v << 16) | (v << 8) | v)
            with m.Default():                       # the top level (the subtractor never exceeds it)
                v = self.level_grey[-1]
                m.d.comb += level_rgb.eq((v << 16) | (v << 8) | v)
        with m.If(~de_5):
            m.d.sync += self.video.rgb.eq(0)
        with m.Elif(sub.out_valid):
            m.d.sync += self.video.rgb.eq(Mux(sub.no_data, NO_DATA_RGB, level_rgb))
        with m.Elif(show_image_5):
            m.d.sync += self.video.rgb.eq(Cat(grey8, grey8, grey8))
        with m.Else():
            m.d.sync += self.video.rgb.eq(BACKGROUND_RGB)

    @staticmethod
    def _replicate_to_8_bits(grey):
        """The 8-bit value whose bits are ``grey``'s bits repeated from the MSB down (5 bits: g4..g0 g4 g3 g2)."""
        bits = []
        while len(bits) < 8:
            bits.extend(grey[i] for i in reversed(range(len(grey))))   # MSB first
        return Cat(*reversed(bits[:8]))
