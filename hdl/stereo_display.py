"""StereoDisplay: the pixel-clock side of the system: compositor, depth engine and the two read arbiters."""

from amaranth import Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.compositor import LATENCY as COMPOSITOR_LATENCY, Compositor, check_parameters, segmentation_fits
from hdl.depth import DepthEngine, schedule
from hdl.depth.engine import check_parameters as check_engine
from hdl.depth.ports import RowTagReadSignature
from hdl.disparity import SETTLE_CLOCKS
from hdl.frame_buffer import FrameBufferReadSignature
from spec.depth import DEPTH
from spec.display import DIFF_LEVEL_GREY, DIFF_THRESHOLDS
from spec.sensor import SENSOR
from spec.video import CEA_1080P60
from hdl.read_arbiter import ReadArbiter
from hdl.rectification_text import RectificationModeSignature
from hdl.reset_tree import add_reset_subtree
from hdl.switches import SettingsSignature
from hdl.video_bus import TimingSignature, VideoSignature

__all__ = ["StereoDisplay", "LATENCY", "ENGINE_START_DELAY", "check_engine_keeps_up", "check_display"]

#: Clocks from ``timing`` in to ``video`` out (the compositor's).
LATENCY = COMPOSITOR_LATENCY
#: Clocks from ``timing.frame_start`` to the engine's ``start``: the switch registers (loaded at the frame
#: start) have settled, and so has the engine's row offset (the clamped rectification, registered: one clock
#: more), so the map uses this frame's rectification.
ENGINE_START_DELAY = SETTLE_CLOCKS + 1


def check_engine_keeps_up(timing, layout, geometry, config, segmentation=False):
    """``ValueError`` unless the engine is sure to finish every depth row before the display shows it, even when
    the compositor reads a buffer in every active pixel (so the engine's reads get only the blanking clocks,
    ``h_total - h_active`` a line):

    * the first row: fetching 5 rows of both images (rows 0..4 start pass 1, which finishes row 0) takes at most
      ceil(5 W / blanking) lines; three passes (pass 0, pass 1 and the registered starts) at most
      3 (``pass_clocks`` + 3) clocks; the depth map (and with ``segmentation`` the difference map's region, which
      then shows the segmentation view from the same rows) must start after both and ``ENGINE_START_DELAY``;
    * every further row: a pass (``pass_clocks`` + 3) and the W reads of a row fit in the ``scale`` lines a
      buffer row is shown on.
    """
    plan, depth = schedule(geometry, config), layout.region("depth")
    w, blank = geometry.buf_width, timing.h_total - timing.h_active
    pass_clocks = plan.pass_clocks + 3
    if blank <= 0 or w > depth.scale * blank or pass_clocks > depth.scale * timing.h_total:
        raise ValueError(f"the depth engine ({pass_clocks} clocks and {w} reads a row) cannot keep up with a "
                         f"depth map shown at {depth.scale}x on {timing.h_total}-clock lines")
    first = -(-5 * w // blank) * timing.h_total + 3 * pass_clocks + ENGINE_START_DELAY
    start = depth.y0 * timing.h_total + depth.x0
    if segmentation:
        view = layout.region("disparity")
        start = min(start, view.y0 * timing.h_total + view.x0)
    if start < first:
        raise ValueError(f"the depth map (and the segmentation view) must start at least {first} clocks into the frame (line "
                         f"{-(-first // timing.h_total)}) for the engine's first row to be ready")


def check_display(timing, geometry, layout, *, config=DEPTH, out_rows=4, thresholds=DIFF_THRESHOLDS,
                  level_grey=DIFF_LEVEL_GREY):
    """The layout (``None``: centred) of a :class:`StereoDisplay`; ``ValueError`` for what it rejects (the
    compositor's and the engine's checks, :func:`check_engine_keeps_up`)."""
    layout = check_parameters(timing, geometry, layout, config, thresholds, level_grey)[0]
    check_engine(geometry, config, out_rows)
    check_engine_keeps_up(timing, layout, geometry, config, segmentation_fits(layout))
    return layout


class StereoDisplay(wiring.Component):
    """The :class:`hdl.compositor.Compositor` and the :class:`hdl.depth.DepthEngine` sharing each frame buffer's
    one read port through a :class:`hdl.read_arbiter.ReadArbiter` (the compositor has priority).

    The engine starts a map :data:`ENGINE_START_DELAY` clocks after every ``timing.frame_start`` and reads the
    left image moved up by the rectification register (signed, clamped to the image: row y is row min(max(y + r, 0), H - 1));
    the compositor shows the finished rows from the engine's result ring and releases them.

    Parameters
    ----------
    timing, geometry, layout, thresholds, level_grey
        As for :class:`hdl.compositor.Compositor`.
    config : :class:`spec.depth.DepthConfig`
    out_rows : int
        Rows in the engine's result ring.

    Attributes
    ----------
    timing : ``In(TimingSignature)``
    settings : ``In(SettingsSignature)``
    segment : ``In(1)``
        The segmentation view in the difference map's place (the compositor's).
    rectification_mode : ``In(RectificationModeSignature)``
        Automatic mode and held verdict for the rectification text (the compositor's).
    left, right : ``Out(FrameBufferReadSignature(geometry))``
        To the frame buffers' read ports.
    left_tags, right_tags : ``Out(RowTagReadSignature(buf_height))``
        The engine's, to each buffer's row tags (:class:`hdl.row_tags.RowTagTracker`).
    video : ``Out(VideoSignature)``

    Clock domain: ``sync`` (the parent renames it to ``pix``). Latency: :data:`LATENCY` clocks.

    Raises
    ------
    ValueError
        The compositor's and the engine's parameter checks; a layout the engine cannot keep up with
        (:func:`check_engine_keeps_up`).
    """

    def __init__(self, timing=CEA_1080P60, geometry=SENSOR, layout=None, *, config=DEPTH, out_rows=4,
                 thresholds=DIFF_THRESHOLDS, level_grey=DIFF_LEVEL_GREY):
        layout = check_display(timing, geometry, layout, config=config, out_rows=out_rows, thresholds=thresholds,
                               level_grey=level_grey)
        self.video_timing, self.geometry, self.layout, self.config, self.out_rows = timing, geometry, layout, config, out_rows
        self.thresholds, self.level_grey = thresholds, level_grey
        super().__init__({
            "timing": In(TimingSignature),
            "settings": In(SettingsSignature),
            "segment": In(1),
            "rectification_mode": In(RectificationModeSignature),
            "left": Out(FrameBufferReadSignature(geometry)),
            "right": Out(FrameBufferReadSignature(geometry)),
            "left_tags": Out(RowTagReadSignature(geometry.buf_height)),
            "right_tags": Out(RowTagReadSignature(geometry.buf_height)),
            "video": Out(VideoSignature),
        })

    def elaborate(self, platform):
        m = Module()
        comp = Compositor(self.video_timing, self.geometry, self.layout, config=self.config, out_rows=self.out_rows,
                          thresholds=self.thresholds, level_grey=self.level_grey)
        engine = DepthEngine(self.geometry, self.config, out_rows=self.out_rows)
        add_reset_subtree(m, "compositor", comp)
        add_reset_subtree(m, "engine", engine)
        for name in ("timing", "settings", "rectification_mode", "video"):
            wiring.connect(m, wiring.flipped(getattr(self, name)), getattr(comp, name))
        m.d.comb += comp.segment.eq(self.segment)
        for side in ("left", "right"):
            arbiter = add_reset_subtree(m, f"{side}_arbiter", ReadArbiter(self.geometry))
            wiring.connect(m, getattr(comp, side), arbiter.display)
            wiring.connect(m, getattr(engine, side), arbiter.engine)
            wiring.connect(m, wiring.flipped(getattr(self, side)), arbiter.buffer)
            wiring.connect(m, wiring.flipped(getattr(self, f"{side}_tags")), getattr(engine, f"{side}_tags"))
        wiring.connect(m, comp.depth, engine.result)
        start = self.timing.frame_start
        for i in range(ENGINE_START_DELAY):
            delayed = Signal(name=f"engine_start_{i + 1}")
            m.d.sync += delayed.eq(start)
            start = delayed
        h = self.geometry.buf_height
        rect = self.settings.rectification
        # The clamp registered: not in one clock with the row ring's offset multiply (ENGINE_START_DELAY).
        row_offset = Signal(range(-(h - 1), h), name="engine_row_offset")
        m.d.sync += row_offset.eq(Mux(rect >= h, h - 1, Mux(rect <= -h, -(h - 1), rect)))
        m.d.comb += [engine.start.eq(start), engine.left_row_offset.eq(row_offset)]
        return m
