"""MapWriter: the depth engine's maps into the frame store, whole (docs/frame_store.md, "Depth maps in the store").

The writer is the reader of the engine's ring of result rows (:class:`hdl.depth.ports.ResultReadSignature`): at the
engine's ``start`` it begins a map; it reads each row as ``rows_ready`` passes it, a code every ``pace`` clocks while
the store has room for its bursts (``room``: it waits, so no burst is lost), and releases the row
(``rows_released``) once its last code is read. It gives the codes to the frame store as a camera's
capture gives its pixels (``feed``: :class:`hdl.frame_store.frame_store.CameraFeedSignature` of
:func:`map_geometry`): ``frame_start`` at the map's start, ``row_start``, the row's ``width`` writes and ``row_end``
for each row, then ``frame_done`` with ``frame_ok`` once the map's last row is written. The store's map writer path
(:class:`~hdl.frame_store.camera_writer.CameraWriter`) publishes a map only on that ``frame_done``: a map the engine
abandons (its ``start`` again before the map's end) gets a new ``frame_start`` and no ``frame_done``, so it is never
published, and a map any of whose bursts the store could not take ends not ok and is not published either.
"""

from dataclasses import replace

from amaranth import Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.depth.ports import ResultReadSignature
from hdl.frame_store.frame_store import CameraFeedSignature

__all__ = ["MapWriter", "map_geometry"]


def map_geometry(geometry, config):
    """The geometry of a depth map as the frame store's writer sees it: ``geometry``'s buffer size, a pixel of
    ``config.code_bits`` bits."""
    return replace(geometry, grey_bits=config.code_bits)


class MapWriter(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
        The buffers' size (the map's).
    config : :class:`spec.depth.DepthConfig`
        The engine's (``code_bits``).
    out_rows : int
        Rows of the engine's result ring.
    pace : int
        Clocks a code at the most (1: a code every clock).

    Attributes
    ----------
    start : ``In(1)``
        The engine's ``start``: a map begins (one in progress is abandoned).
    result : ``Out(ResultReadSignature((out_rows * W - 1).bit_length(), code_bits, H))``
        To the engine's ring.
    feed : ``Out(CameraFeedSignature(map_geometry(geometry, config)))``
        To the frame store's map input.
    room : ``In(1)``
        The store's map FIFO has room (``FrameStore.map_room``): a code is read only while it is high.
    busy : ``Out(1)``
        From ``start`` until the map's ``frame_done`` is given (or, after an abandoned map, the next one's).

    Clock domain: ``sync`` (the parent renames it to ``pix``). Latency: ``frame_start`` in the clock after ``start``;
    a ring read's code is written in the next clock; ``row_end`` a clock after a row's last write, ``frame_done``
    a clock after the last ``row_end``.

    Raises
    ------
    ValueError
        ``out_rows`` below 2, ``pace`` below 1.
    """

    def __init__(self, geometry, config, *, out_rows=4, pace=1):
        if out_rows < 2 or pace < 1:
            raise ValueError(f"out_rows must be at least 2 and pace at least 1, got {out_rows} and {pace}")
        self.geometry, self.config, self.out_rows, self.pace = geometry, config, out_rows, pace
        w, h = geometry.buf_width, geometry.buf_height
        super().__init__({
            "start": In(1),
            "result": Out(ResultReadSignature((out_rows * w - 1).bit_length(), config.code_bits, h)),
            "feed": Out(CameraFeedSignature(map_geometry(geometry, config))),
            "room": In(1),
            "busy": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        w, h = self.geometry.buf_width, self.geometry.buf_height
        result, write, status = self.result, self.feed.write, self.feed.status
        row = Signal(range(h + 1))                  # the row being written (h: the map is written)
        x = Signal(range(w))
        base = Signal(range(self.out_rows * w))     # the row's first ring address: (row mod out_rows) * W
        address = Signal(range(h * w))              # row * W + x of the next read
        written = Signal(range(h * w))              # of the code on ``data``
        wait = Signal(range(self.pace))
        issued = Signal()                           # a ring read issued last clock: its code is on ``data``
        m.d.sync += [issued.eq(0), status.frame_start.eq(self.start), status.row_start.eq(0),
                     status.row_end.eq(0), status.frame_done.eq(0), status.frame_ok.eq(0)]
        m.d.comb += [result.addr.eq(base + x), write.data.eq(result.data), write.en.eq(issued),
                     write.addr.eq(written), status.in_frame.eq(self.busy)]

        def started():                              # in every state: a start begins the map again
            with m.If(self.start):
                m.next = "WAIT"

        with m.FSM(name="map_writer"):
            with m.State("IDLE"):
                started()
            with m.State("WAIT"):                   # for the row (row < h)
                m.d.comb += self.busy.eq(1)
                with m.If(row < result.rows_ready):
                    m.d.sync += [status.row_start.eq(1), x.eq(0), wait.eq(0)]
                    m.next = "READ"
                started()
            with m.State("READ"):
                m.d.comb += self.busy.eq(1)
                if self.pace > 1:
                    with m.If((wait != 0) | self.room):
                        m.d.sync += wait.eq(Mux(wait == self.pace - 1, 0, wait + 1))
                with m.If((wait == 0) & self.room):
                    m.d.sync += [issued.eq(1), written.eq(address), address.eq(address + 1)]
                    with m.If(x == w - 1):
                        m.next = "ROW_END"
                    with m.Else():
                        m.d.sync += x.eq(x + 1)
                started()
            with m.State("ROW_END"):                # the row's last write is in this clock
                m.d.comb += self.busy.eq(1)
                m.d.sync += [status.row_end.eq(1), row.eq(row + 1), result.rows_released.eq(row + 1), x.eq(0),
                             base.eq(Mux(base == (self.out_rows - 1) * w, 0, base + w))]
                with m.If(row == h - 1):
                    m.next = "DONE"
                with m.Else():
                    m.next = "WAIT"
                started()
            with m.State("DONE"):                   # the last row_end is in this clock: the map is whole
                m.d.comb += self.busy.eq(1)
                m.d.sync += [status.frame_done.eq(1), status.frame_ok.eq(1)]
                m.next = "IDLE"
                started()
        with m.If(self.start):
            m.d.sync += [row.eq(0), x.eq(0), base.eq(0), address.eq(0), result.rows_released.eq(0)]
        return m
