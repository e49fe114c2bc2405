"""StereoDisplay: the pixel-clock side of the system: compositor, depth engine and the read ports they share: two
read arbiters on the block-RAM buffers, or the frame store's read streams through their windows."""

from amaranth import Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.compositor import LATENCY as COMPOSITOR_LATENCY, Compositor, check_parameters, segmentation_fits
from hdl.depth import DepthEngine, schedule
from hdl.depth.engine import check_parameters as check_engine, row_lag, tag_delay
from hdl.depth.ports import RowTagReadSignature
from hdl.disparity import SETTLE_CLOCKS
from hdl.frame_buffer import FrameBufferReadSignature
from spec.depth import DEPTH
from spec.display import DIFF_LEVEL_GREY
from spec.sensor import SENSOR, SENSOR_FPS
from spec.video import CEA_1080P60
from hdl.frame_store.frame_store import CameraFeedSignature
from hdl.frame_store.row_reader import RowStreamSignature
from hdl.map_window import MapWindow
from hdl.map_writer import MapWriter, map_geometry
from hdl.read_arbiter import ReadArbiter
from hdl.store_windows import STREAMS, StoreWindows, check_store_windows
from hdl.rectification_text import RectificationModeSignature
from hdl.reset_tree import add_reset_subtree
from hdl.switches import SettingsSignature
from hdl.video_bus import TimingSignature, VideoSignature

__all__ = ["StereoDisplay", "LATENCY", "ENGINE_START_DELAY", "MEMORIES", "MAPS", "MAP_PACE", "check_engine_keeps_up",
           "check_map_rate", "map_clocks", "check_display"]

#: Clocks from ``timing`` in to ``video`` out (the compositor's).
LATENCY = COMPOSITOR_LATENCY
#: Clocks from ``timing.frame_start`` to the engine's ``start``: the switch registers (loaded at the frame
#: start) have settled, and so has the engine's row offset (the clamped rectification, registered: one clock
#: more), so the map uses this frame's rectification.
ENGINE_START_DELAY = SETTLE_CLOCKS + 1
#: Where the camera frames are: ``"bram"`` a block-RAM frame buffer per camera, ``"ddr2"`` the frame store.
MEMORIES = ("bram", "ddr2")
#: Where the depth maps are: ``"ring"`` the engine's ring of result rows, read by the compositor as the engine
#: writes it (a map a display frame); ``"store"`` (with ``"ddr2"`` only) whole maps in the frame store, the latest
#: whole one shown (docs/frame_store.md, "Depth maps in the store").
MAPS = ("ring", "store")
#: With ``maps="store"``: the map writer's clocks a code at the most (:class:`hdl.map_writer.MapWriter`'s ``pace``;
#: it also waits while the store's map FIFO has no room). 4: even with the engine's rows drained one after another
#: the writer's bursts never queue in MIG's in-order FIFOs ahead of the display's reads (at 1 and 2 they do:
#: docs/frame_store.md, "The worst case"), and a row still drains within an engine pass.
MAP_PACE = 4
#: Clocks from the display frame's start to the engine's start with the frame store, at most: the start delay, the
#: take's two pulse synchronisers and the ownership's answer (a few clocks of each domain; 32 is ample).
TAKE_CLOCKS = 32


def map_clocks(geometry, config, pace=MAP_PACE):
    """Pixel clocks from a display frame's start to a map whole in the map writer, with every engine read granted
    (docs/depth.md, "Frame and latency"): the take and the start (:data:`TAKE_CLOCKS`), rows 0..3 fetched (4 W) and
    their tag samples, ``H + lag`` passes of ``pass_clocks + 3`` (``hdl.depth.engine.row_lag``: the median's
    ``ROW_LAG``, 1 for the 3 x 3, 2 for the separable 5 x 5, one more with ``left_right``), and the last row
    drained, a code every ``pace`` clocks (the other rows are drained while later passes run: a row takes ``pace W
    + 3`` clocks, less than a pass)."""
    w, h, lag = geometry.buf_width, geometry.buf_height, row_lag(config)
    return TAKE_CLOCKS + 4 * w + tag_delay(config) + (h + lag) * (schedule(geometry, config).pass_clocks + 3) \
        + pace * w + 3


def check_map_rate(timing, geometry, config, pace=MAP_PACE, camera_fps=SENSOR_FPS):
    """With the maps in the frame store: ``ValueError`` unless a map a camera frame (``camera_fps``) is computed.
    The engine starts only at a display frame's start, when the last map is whole, so a map takes
    ``ceil(map_clocks / frame clocks)`` display frames (:func:`map_clocks`); they must fit in a camera frame, and
    the writer must drain a row (``pace W + 3`` clocks) within a pass. Returns the display frames a map takes."""
    drain, pass_clocks = pace * geometry.buf_width + 3, schedule(geometry, config).pass_clocks
    if drain > pass_clocks:
        raise ValueError(f"the map writer drains a row in {drain} clocks (a code every {pace}), longer than the "
                         f"engine's pass of {pass_clocks}: its rows would back up")
    frame = timing.h_total * timing.v_total
    frames = -(-map_clocks(geometry, config, pace) // frame)
    if frames * frame * camera_fps > timing.pixel_hz:
        raise ValueError(f"a depth map takes {frames} display frames ({frames * frame / timing.pixel_hz * 1e3:.1f} ms), "
                         f"longer than a camera frame at {camera_fps} frames a second")
    return frames


def check_engine_keeps_up(timing, layout, geometry, config, segmentation=False):
    """``ValueError`` unless the engine is sure to finish every depth row before the display shows it, even when
    the compositor reads a buffer in every active pixel (so the engine's reads get only the blanking clocks,
    ``h_total - h_active`` a line):

    * the first row: fetching 4 + L rows of both images (L = ``hdl.depth.engine.row_lag``: rows 0..3 + L start
      pass L, which finishes row 0) takes at most ceil((4 + L) W / blanking) lines; L + 2 passes (passes 0..L and the
      registered starts) at most (L + 2) (``pass_clocks`` + 3) clocks; the depth map (and with ``segmentation`` the difference map's region, which
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
    lag = row_lag(config)
    first = -(-(4 + lag) * w // blank) * timing.h_total + (2 + lag) * pass_clocks + ENGINE_START_DELAY
    start = depth.y0 * timing.h_total + depth.x0
    if segmentation:
        view = layout.region("disparity")
        start = min(start, view.y0 * timing.h_total + view.x0)
    if start < first:
        raise ValueError(f"the depth map (and the segmentation view) must start at least {first} clocks into the frame (line "
                         f"{-(-first // timing.h_total)}) for the engine's first row to be ready")


def check_display(timing, geometry, layout, *, config=DEPTH, out_rows=4, thresholds=None,
                  level_grey=DIFF_LEVEL_GREY, memory="bram", maps="ring"):
    """The layout (``None``: centred) of a :class:`StereoDisplay`; ``ValueError`` for what it rejects (the
    compositor's and the engine's checks, a ``memory`` not in :data:`MEMORIES`, ``maps`` not in :data:`MAPS` or
    ``"store"`` without ``"ddr2"``; with ``"ring"`` :func:`check_engine_keeps_up`, with ``"store"``
    :func:`check_map_rate`; with ``"ddr2"`` :func:`hdl.store_windows.check_store_windows`)."""
    if memory not in MEMORIES:
        raise ValueError(f"memory must be one of {', '.join(map(repr, MEMORIES))}, not {memory!r}")
    check_maps(memory, maps)
    layout = check_parameters(timing, geometry, layout, config, thresholds, level_grey)[0]
    check_engine(geometry, config, out_rows)
    if maps == "store":
        check_map_rate(timing, geometry, config)
    else:
        check_engine_keeps_up(timing, layout, geometry, config, segmentation_fits(layout))
    if memory == "ddr2":
        check_store_windows(layout)
    return layout


def check_maps(memory, maps):
    """``ValueError`` unless ``maps`` is one of :data:`MAPS`, ``"store"`` only with ``memory="ddr2"``."""
    if maps not in MAPS:
        raise ValueError(f"maps must be one of {', '.join(map(repr, MAPS))}, not {maps!r}")
    if maps == "store" and memory != "ddr2":
        raise ValueError(f"maps='store' keeps the depth maps in the frame store: it needs memory='ddr2', "
                         f"not {memory!r}")


class StereoDisplay(wiring.Component):
    """The :class:`hdl.compositor.Compositor` and the :class:`hdl.depth.DepthEngine` sharing each frame buffer's
    one read port through a :class:`hdl.read_arbiter.ReadArbiter` (the compositor has priority).

    The engine starts a map :data:`ENGINE_START_DELAY` clocks after every ``timing.frame_start`` and reads the
    left image moved up by the rectification register (signed, clamped to the image: row y is row min(max(y + r, 0), H - 1));
    the compositor shows the finished rows from the engine's result ring and releases them.

    With ``memory="ddr2"`` the frames are in the frame store (docs/frame_store.md): the two arbiters give way to
    :class:`hdl.store_windows.StoreWindows` (a read stream and a window per consumer and camera), ``take`` pulses
    at every ``timing.frame_start``, and the engine starts its map in the clock after both :data:`ENGINE_START_DELAY`
    clocks have passed and the frame store has answered the take (``taken``), so the map reads the display frame's
    pair.
    A held pair is whole: the engine's row tags read 0, never busy.

    Parameters
    ----------
    timing, geometry, layout, thresholds, level_grey
        As for :class:`hdl.compositor.Compositor`.
    config : :class:`spec.depth.DepthConfig`
    out_rows : int
        Rows in the engine's result ring.
    memory : str
        One of :data:`MEMORIES`: ``"bram"`` (the ports ``left``, ``right``, ``left_tags``, ``right_tags``) or
        ``"ddr2"`` (the ports ``streams``, ``take``, ``taken``).
    slots : int
        With ``"ddr2"``: each read stream's ring slots.
    maps : str
        One of :data:`MAPS`. ``"store"`` (with ``"ddr2"``): a :class:`hdl.map_writer.MapWriter` drains the engine's
        ring into the frame store's map buffers (``map_feed``) and the compositor reads the latest whole map
        through a :class:`hdl.map_window.MapWindow` (``map_stream``, ``map_take`` at every display frame's start,
        ``map_taken``, ``map_valid``); the pair is taken (``take``) only at a display frame's start when the engine
        and the map writer are idle (the last map whole), and the engine starts on it, so each map is of one pair
        and the camera panels and the difference map show the pair of the map being computed (the compositor's
        windows restart at every display frame's start all the same).

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
    streams : ``Out(RowStreamSignature(buf_height, buf_width, slots)).array(4)``
        With ``"ddr2"``: to the frame store's read streams, in :data:`hdl.store_windows.STREAMS` order.
    take : ``Out(1)``, taken : ``In(1)``
        With ``"ddr2"``: the frame store's hold of a pair (``take`` = ``timing.frame_start``).
    display_missed : ``Out(1)``
        With ``"ddr2"``: a compositor read its window refused (:class:`hdl.store_windows.StoreWindows`).
    map_feed : ``Out(CameraFeedSignature(map_geometry(geometry, config)))``
        With ``maps="store"``: to the frame store's map input.
    map_stream : ``Out(RowStreamSignature(buf_height, buf_width, out_rows, 8 * bytes a code))``
    map_take : ``Out(1)``; map_taken, map_valid, map_room : ``In(1)``
        With ``maps="store"``: the frame store's map stream and hold, and its room for the map writer's codes.
    video : ``Out(VideoSignature)``

    Clock domain: ``sync`` (the parent renames it to ``pix``). Latency: :data:`LATENCY` clocks.

    Raises
    ------
    ValueError
        The compositor's and the engine's parameter checks; a layout the engine cannot keep up with
        (:func:`check_engine_keeps_up`), or with ``maps="store"`` a map longer than a camera frame
        (:func:`check_map_rate`); ``maps`` not one of :data:`MAPS`, ``"store"`` without ``"ddr2"``.
    """

    def __init__(self, timing=CEA_1080P60, geometry=SENSOR, layout=None, *, config=DEPTH, out_rows=4,
                 thresholds=None, level_grey=DIFF_LEVEL_GREY, memory="bram", slots=4, maps="ring"):
        layout = check_display(timing, geometry, layout, config=config, out_rows=out_rows, thresholds=thresholds,
                               level_grey=level_grey, memory=memory, maps=maps)
        self.video_timing, self.geometry, self.layout, self.config, self.out_rows = timing, geometry, layout, config, out_rows
        self.thresholds, self.level_grey, self.memory, self.slots = thresholds, level_grey, memory, slots
        self.maps = maps
        if memory == "bram":
            ports = {
                "left": Out(FrameBufferReadSignature(geometry)),
                "right": Out(FrameBufferReadSignature(geometry)),
                "left_tags": Out(RowTagReadSignature(geometry.buf_height)),
                "right_tags": Out(RowTagReadSignature(geometry.buf_height)),
            }
        else:
            ports = {
                "streams": Out(RowStreamSignature(geometry.buf_height, geometry.buf_width, slots)).array(len(STREAMS)),
                "take": Out(1),
                "taken": In(1),
                "display_missed": Out(1),
            }
        if maps == "store":
            code_bytes = -(-config.code_bits // 8)
            ports.update({
                "map_feed": Out(CameraFeedSignature(map_geometry(geometry, config))),
                "map_stream": Out(RowStreamSignature(geometry.buf_height, geometry.buf_width, out_rows,
                                                     8 * code_bytes)),
                "map_take": Out(1),
                "map_taken": In(1),
                "map_valid": In(1),
                "map_room": In(1),
            })
        super().__init__({
            "timing": In(TimingSignature),
            "settings": In(SettingsSignature),
            "segment": In(1),
            "rectification_mode": In(RectificationModeSignature),
            **ports,
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
        if self.memory == "bram":
            for side in ("left", "right"):
                arbiter = add_reset_subtree(m, f"{side}_arbiter", ReadArbiter(self.geometry))
                wiring.connect(m, getattr(comp, side), arbiter.display)
                wiring.connect(m, getattr(engine, side), arbiter.engine)
                wiring.connect(m, wiring.flipped(getattr(self, side)), arbiter.buffer)
                wiring.connect(m, wiring.flipped(getattr(self, f"{side}_tags")), getattr(engine, f"{side}_tags"))
        idle = None
        if self.maps == "store":
            idle = self._map_store(m, comp, engine)
        else:
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
        if self.memory == "ddr2":
            start = self._store_windows(m, comp, engine, start, row_offset, idle)
        m.d.comb += [engine.start.eq(start), engine.left_row_offset.eq(row_offset)]
        if self.maps == "store":
            m.d.comb += self.map_writer.start.eq(start)
        return m

    def _map_store(self, m, comp, engine):
        """``maps="store"``: the map writer on the engine's ring, the map window on the compositor's. Returns
        ``idle``: the engine and the writer have no map in hand (the pair may be taken and a map started)."""
        self.map_writer = writer = add_reset_subtree(m, "map_writer", MapWriter(
            self.geometry, self.config, out_rows=self.out_rows, pace=MAP_PACE))
        wiring.connect(m, writer.result, engine.result)
        wiring.connect(m, writer.feed, wiring.flipped(self.map_feed))
        m.d.comb += writer.room.eq(self.map_room)
        # In the display's reset as the store windows are: it asks for rows combinationally.
        m.submodules.map_window = window = MapWindow(self.geometry, self.config.code_bits, slots=self.out_rows,
                                                     pixel_bits=len(self.map_stream.read.data))
        wiring.connect(m, comp.depth, window.result)
        wiring.connect(m, window.stream, wiring.flipped(self.map_stream))
        m.d.comb += [self.map_take.eq(self.timing.frame_start), window.take.eq(self.timing.frame_start),
                     window.taken.eq(self.map_taken), window.valid.eq(self.map_valid)]
        idle = Signal(name="map_idle")
        m.d.comb += idle.eq(~engine.busy & ~writer.busy)
        return idle

    def _store_windows(self, m, comp, engine, delayed_start, row_offset, idle):
        """The frame store's side: the windows, ``take`` (at the display frame's start when ``idle``), and the
        engine's start once the delay has passed and the pair is taken (whichever comes last). Returns the
        engine's start."""
        # In the display's reset, not a subtree of its own: a window asks for rows combinationally, so it must leave
        # reset in the clock its stream does (the system puts the frame store in a ``pix`` reset subtree too).
        m.submodules.store_windows = windows = StoreWindows(
            self.geometry, self.layout, slots=self.slots, rectification_bits=len(self.settings.rectification))
        for side in ("left", "right"):
            wiring.connect(m, getattr(comp, side), getattr(windows, f"display_{side}"))
            wiring.connect(m, getattr(engine, side), getattr(windows, f"engine_{side}"))
        for i in range(len(STREAMS)):
            wiring.connect(m, windows.streams[i], wiring.flipped(self.streams[i]))
        wiring.connect(m, wiring.flipped(self.timing), windows.timing)
        delay_done, taken = Signal(name="engine_delay_done"), Signal(name="engine_pair_taken")
        # Both have come: the engine starts in the next clock (a register, so that the frame store's ``taken`` does
        # not reach through the engine's start into its rings and reads in one clock).
        ready, start = Signal(name="engine_ready"), Signal(name="engine_start")
        m.d.comb += ready.eq((delay_done | delayed_start) & (taken | self.taken))
        m.d.sync += start.eq(ready)
        with m.If(self.timing.frame_start):
            m.d.sync += [delay_done.eq(0), taken.eq(0)]
        with m.Elif(ready):
            m.d.sync += [delay_done.eq(0), taken.eq(0)]
        with m.Else():
            with m.If(delayed_start):
                m.d.sync += delay_done.eq(1)
            with m.If(self.taken):
                m.d.sync += taken.eq(1)
        restart = self.taken
        if self.maps == "store":
            # No take while a map is in hand: the compositor's windows restart on the held pair a clock after the
            # frame's start instead of at ``taken``.
            kept = Signal(name="pair_kept")
            m.d.sync += kept.eq(self.timing.frame_start & ~idle)
            restart = self.taken | kept
        m.d.comb += [
            self.take.eq(self.timing.frame_start if idle is None else self.timing.frame_start & idle),
            windows.rectification.eq(self.settings.rectification),
            windows.taken.eq(restart),
            windows.engine_start.eq(start),
            windows.engine_left_row.eq(Mux(row_offset < 0, 0, row_offset)),
            self.display_missed.eq(windows.display_missed),
        ]
        return start
