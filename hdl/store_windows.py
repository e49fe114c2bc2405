"""StoreWindows: the compositor's and the depth engine's frame-buffer read ports served from four read streams of
the frame store (:class:`hdl.frame_store.frame_store.FrameStore`), each through a
:class:`~hdl.frame_store.row_window.RowWindow` of its own (docs/frame_store.md, "Readers").

Stream 0 is the compositor's left port, 1 its right port (both urgent in the frame store), 2 the engine's left
port, 3 its right port. Each window is restarted where its consumer begins a new in-order row sequence:

* the compositor's two windows after ``taken`` (the display frame's pair is held), first row 0, step the panel's
  ``shrink`` (a half-size panel reads rows 0, 2, 4, ...: its window asks for those only): the left and right
  panels;
* the compositor's two windows again at the start of the first line after the panels (the clock after ``x = 0``:
  the line's start and the rectification registered), before the difference map's (or the segmentation view's)
  first line: left first row ``min(max(r, 0), H - 1)`` (``r`` the rectification: the subtractor reads the left
  image ``r`` rows lower), right first row 0, both step 1;
* the engine's two windows at ``engine_start`` (the engine's ``start``): left first row ``engine_left_row``, right
  first row 0.

``display_missed`` is a compositor read refused whose byte the picture would use: a panel's or the difference
map's pixel shown with a byte the block-RAM build would have had (the compositor cannot wait). The subtractor drives
address 0 for a shifted pixel outside the left image (its no-data pixels: :mod:`hdl.disparity`); the left window
refuses such a read when row 0 lies before its first row, which costs nothing, so a refused read of address 0
*below* the left window is not a miss. No read the picture uses looks so: the subtractor reads the left rows in
order from the window's first row, so once the window has moved past row 0 (or starts below it) it never reads row
0 again in that map.
"""

from amaranth import Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.depth.ports import SharedReadSignature
from hdl.frame_store.row_reader import RowStreamSignature
from hdl.frame_store.row_window import RowWindow
from hdl.video_bus import TimingSignature
from spec.sensor import SENSOR

__all__ = ["StoreWindows", "STREAMS", "check_store_windows"]

#: The four read streams: (camera, urgent) in the frame store's ``streams`` order: the compositor's left and
#: right (urgent), the engine's left and right.
STREAMS = ((0, True), (1, True), (0, False), (1, False))


def check_store_windows(layout):
    """The first line after the panels: ``ValueError`` unless it comes before the difference map's first line
    (the compositor's windows restart on it) and the difference map shows every buffer row (its windows restart
    with a step of 1; a panel at 1 / ``shrink`` size reads every ``shrink``-th row: its window's step)."""
    maps_region = layout.region("disparity")
    if maps_region.shrink != 1:
        raise ValueError(f"the difference map at 1/{maps_region.shrink} size skips buffer rows; the frame store's "
                         "windows serve it every row (only the camera panels may be shrunk)")
    panels_end = max(layout.region("left").y1, layout.region("right").y1)
    maps = maps_region.y0
    if panels_end >= maps:
        raise ValueError(f"the difference map (line {maps}) must start below the panels (last line "
                         f"{panels_end - 1}) for the frame store's windows to restart between them")
    return panels_end


class StoreWindows(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
    layout : :class:`spec.layout.DisplayLayout`
        The compositor's (the panels' last line).
    slots : int
        Each stream's ring slots.
    rectification_bits : int
        The width of the signed ``rectification``.

    Attributes
    ----------
    display_left, display_right, engine_left, engine_right : ``In(SharedReadSignature(geometry))``
        The consumers' ports.
    timing : ``In(TimingSignature)``
        The sync generator's raster position.
    rectification : ``In(signed(rectification_bits))``
        The subtractor's row offset (the settings in use).
    taken : ``In(1)``
        The frame store's: the display frame's pair is held.
    engine_start : ``In(1)``
        The engine's ``start``; ``engine_left_row`` (``In(range(buf_height))``) is the first left row it reads.
    streams : ``Out(RowStreamSignature(buf_height, buf_width, slots)).array(4)``
        To the frame store's streams, in :data:`STREAMS` order.
    display_missed : ``Out(1)``
        A compositor read refused in this clock, but for the subtractor's no-data reads (above).

    Clock domain: ``sync`` (the parent renames it to ``pix``). Latency: as :class:`RowWindow`.

    Raises
    ------
    ValueError
        :func:`check_store_windows`; :class:`RowWindow`'s checks.
    """

    def __init__(self, geometry=SENSOR, layout=None, *, slots=4, rectification_bits=7):
        self.panels_end = check_store_windows(layout)
        self.geometry, self.layout, self.slots = geometry, layout, slots
        h, w = geometry.buf_height, geometry.buf_width
        super().__init__({
            **{name: In(SharedReadSignature(geometry))
               for name in ("display_left", "display_right", "engine_left", "engine_right")},
            "timing": In(TimingSignature),
            "rectification": In(signed(rectification_bits)),
            "taken": In(1),
            "engine_start": In(1),
            "engine_left_row": In(range(h)),
            "streams": Out(RowStreamSignature(h, w, slots)).array(len(STREAMS)),
            "display_missed": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        h = self.geometry.buf_height
        r = self.rectification
        # The maps' restart and its first row, registered: the windows restart in the line's second clock.
        shifted = Signal(range(h), name="shifted_first_row")
        maps = Signal(name="maps_restart")
        m.d.sync += [shifted.eq(Mux(r < 0, 0, Mux(r >= h, h - 1, r))),
                     maps.eq((self.timing.y == self.panels_end) & (self.timing.x == 0))]
        shrink = [self.layout.region(side).shrink for side in ("left", "right")]
        restarts = (   # consumer, restart, first row, (the step after taken, the step after the maps' restart)
            (self.display_left, self.taken | maps, Mux(self.taken, 0, shifted), (shrink[0], 1)),
            (self.display_right, self.taken | maps, 0, (shrink[1], 1)),
            (self.engine_left, self.engine_start, self.engine_left_row, (1, 1)),
            (self.engine_right, self.engine_start, 0, (1, 1)),
        )
        windows = []
        for i, (consumer, restart, first_row, steps) in enumerate(restarts):
            m.submodules[f"window_{i}"] = window = RowWindow(self.geometry, self.slots, max_step=max(steps))
            wiring.connect(m, wiring.flipped(consumer), window.consumer)
            wiring.connect(m, window.stream, wiring.flipped(self.streams[i]))
            m.d.comb += [window.restart.eq(restart), window.first_row.eq(first_row)]
            if max(steps) > 1:
                m.d.comb += window.row_step.eq(Mux(self.taken, *steps))
            windows.append(window)
        left, right = windows[:2]
        no_data = left.below & (self.display_left.port.addr == 0)
        m.d.comb += self.display_missed.eq((left.missed & ~no_data) | right.missed)
        return m
