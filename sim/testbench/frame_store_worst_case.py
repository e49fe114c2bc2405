"""The frame store's worst case (docs/frame_store.md, "The worst case"): ``FrameStore`` on the MIG model with the
largest read latency and a refresh every tREFI, both cameras writing at their full rate, the depth engine's streams
reading as fast as they are granted and the display's streams reading a 1080p line's pattern, every clock domain at
its real frequency. Everything per clock is gateware (sources, consumers, the landing times, counters); Python
only starts the cameras, takes the pair and reads the counters at the end. A MIG violation stops the run
(:class:`sim.models.mig.MIGProtocolViolation`), so a result's report says "none".

* **Cameras** (:class:`CameraSource`): the capture's output protocol with a kept pixel every ``gap`` PCLK: 8 is the
  capture's rate (1600-pixel lines of two bytes a pixel at 80 MHz, every 4th pixel kept: 100 ns a pixel), and here
  *every* buffer row streams at that rate (the sensor streams one kept line in four): four times the real average.
* **Display** (:class:`DisplayReads`): each display stream a ``RowWindow`` read as a panel at 1x is -- buffer row
  ``y`` on one display line, ``width`` consecutive pixels from column ``x0`` of the 2200-clock line -- after
  ``blank_lines`` lines in which the window is restarted at row 0. Four such streams at once: twice the real peak
  (the 1x panels' two; the 2x panels read a row every two lines).
* **Engine** (:class:`GreedyRows`): each engine stream asks for its next row whenever its request FIFO has room.

``WorstCase(build=800)`` is the 800 x 600 build's store (``hdl.config.DesignConfig.full_800``: the maps in the
store): 800-pixel 8-bit rows, every buffer row written at the averaging capture's rate (a pixel every 4 PCLK: twice
the real average); the display's two camera streams as its compositor reads them (the half-size panels, every
second row and pixel, then -- the windows restarted on a line between them -- the difference map's every row at
1:1) and its map stream (:class:`MapReads` through :class:`hdl.map_window.MapWindow`: the depth panel at 1:1, two
bytes a code, taken at every display frame's start); the map writer (:class:`GreedyMaps`: the real
:class:`hdl.map_writer.MapWriter` on a ring given a row every engine pass, :data:`MAP_ROW_CLOCKS`, each drained at a
code a clock while the store has room, map after map; faster with ``map_row_clocks`` and ``map_backlog``).
"""

from dataclasses import dataclass, replace

from amaranth import Array, Cat, ClockDomain, DomainRenamer, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out
from amaranth.sim import Simulator

from hdl.depth.engine import schedule
from hdl.depth.ports import ResultReadSignature, SharedReadSignature
from hdl.frame_store.frame_store import CameraFeedSignature, FrameStore
from hdl.frame_store.layout import BURST_BYTES, FrameStoreLayout
from hdl.frame_store.row_reader import RowStreamSignature
from hdl.frame_store.row_window import RowWindow
from hdl.map_window import MapWindow
from hdl.map_writer import MapWriter
from hdl.stereo_display import MAP_PACE, check_map_rate
from sim.models.mig import READ_LATENCY_RANGE, MIGModel, layout_window, watch_violations
from spec.board import CLOCKS
from spec.depth import DEPTH_800
from spec.layout import DisplayLayout
from spec.memory import MIG
from spec.sensor import SENSOR, SENSOR_800, SensorGeometry
from spec.video import CEA_1080P60

__all__ = ["WorstCase", "WorstCaseResult", "run_worst_case", "CameraSource", "camera_frame_clocks",
           "ReadPass", "DisplayReads", "MapReads", "GreedyRows", "GreedyMaps", "PortCounters", "CAMERA_GAP",
           "CAMERA_GAP_800", "BUILDS", "MAP_ROW_CLOCKS", "PEAK_MBPS"]

#: Pix clocks from both cameras' ``frame_done`` to the take: their last bursts and ends written, the pair formed.
PAIR_CLOCKS = 300
#: Bytes in a DRAM row (a column address's 1024 words of 8 bytes).
DRAM_ROW_BYTES = (1 << MIG.COL_BITS) * 8
#: PCLK clocks per kept pixel: two bytes a pixel, every 4th pixel kept.
CAMERA_GAP = 2 * 4
#: PCLK clocks per buffer pixel of the averaging capture (the 800 x 600 build): two bytes a pixel, a 2 x 2 block's
#: mean written with the block's last pixel (every second pixel of every second line).
CAMERA_GAP_800 = 2 * 2
#: The builds the worst case models: 400 (the 400 x 300 store, maps in the engine's ring) and 800 (the 800 x 600
#: build's store, the maps in it).
BUILDS = (400, 800)
#: Pix clocks between the 800 build's map rows: an engine pass (``pass_clocks`` and 3 to start it), a row each.
MAP_ROW_CLOCKS = schedule(SENSOR_800, DEPTH_800).pass_clocks + 3
#: MIG's user interface at its full rate: a 128-bit word every clk0, in MB/s.
PEAK_MBPS = MIG.CLK0_HZ * MIG.DATA_WIDTH // 8 / 1e6


def camera_frame_clocks(geometry, gap):
    """Clocks a :class:`CameraSource` frame takes at a pixel every ``gap`` clocks: ``frame_start`` and 4 clocks,
    per row ``row_start``, the pixels and ``row_end``, 6 clocks between rows, ``frame_done``."""
    rows = geometry.buf_height
    return 1 + 4 + rows * (2 + geometry.buf_width * gap) + (rows - 1) * 6 + 1


class CameraSource(wiring.Component):
    """A capture's output protocol at a pixel every ``gap`` clocks (``fast``: every clock), frame after frame:
    ``frame_start``, 3 clocks, per row ``row_start``, a clock, ``width`` writes ``gap`` clocks apart, ``row_end`` a
    clock after the last, 6 clocks; after ``height`` rows ``frame_done`` with ``frame_ok``. Starts on ``run``.
    ``frames``: frames completed."""

    def __init__(self, geometry, gap=CAMERA_GAP):
        self.geometry, self.gap = geometry, gap
        super().__init__({"feed": Out(CameraFeedSignature(geometry)), "run": In(1), "fast": In(1),
                          "frames": Out(16)})

    def elaborate(self, platform):
        m = Module()
        g, st, wr = self.geometry, self.feed.status, self.feed.write
        col, row = Signal(range(g.buf_width + 1)), Signal(range(g.buf_height + 1))
        wait, phase = Signal(range(8)), Signal(range(self.gap))
        pixel_due = Signal()
        m.d.comb += pixel_due.eq(self.fast | (phase == self.gap - 1))
        m.d.comb += [wr.data.eq(col[:g.grey_bits] ^ row[:g.grey_bits]), wr.addr.eq(0)]
        with m.FSM():
            with m.State("IDLE"):
                with m.If(self.run):
                    m.next = "START"
            with m.State("START"):
                m.d.comb += st.frame_start.eq(1)
                m.d.sync += [wait.eq(3), row.eq(0)]
                m.next = "GAP"
            with m.State("GAP"):
                m.d.sync += wait.eq(wait - 1)
                with m.If(wait == 0):
                    m.next = "ROW"
            with m.State("ROW"):
                m.d.comb += st.row_start.eq(1)
                m.d.sync += [col.eq(0), phase.eq(0)]
                m.next = "PIXELS"
            with m.State("PIXELS"):
                m.d.sync += phase.eq(phase + 1)
                with m.If(pixel_due):
                    m.d.comb += wr.en.eq(1)
                    m.d.sync += [col.eq(col + 1), phase.eq(0)]
                    with m.If(col == g.buf_width - 1):
                        m.next = "ROW_END"
            with m.State("ROW_END"):
                m.d.comb += st.row_end.eq(1)
                m.d.sync += [row.eq(row + 1), wait.eq(5)]
                with m.If(row == g.buf_height - 1):
                    m.next = "DONE"
                with m.Else():
                    m.next = "ROW_GAP"
            with m.State("ROW_GAP"):
                m.d.sync += wait.eq(wait - 1)
                with m.If(wait == 0):
                    m.next = "ROW"
            with m.State("DONE"):
                m.d.comb += [st.frame_done.eq(1), st.frame_ok.eq(1)]
                m.d.sync += self.frames.eq(self.frames + 1)
                m.next = "START"
        return m


@dataclass(frozen=True)
class ReadPass:
    """A panel's rows as one stream's window reads them: the window restarted (first row 0, ``row_step``) in the
    first clock of line ``restart_line``; on line ``first_line + k`` (``k < lines``) row ``k * row_step``, its
    pixels ``x * column_step`` read at clocks ``x0 + x`` (``x < columns``)."""
    restart_line: int
    first_line: int
    lines: int
    x0: int
    columns: int
    row_step: int = 1
    column_step: int = 1


class DisplayReads(wiring.Component):
    """A display stream's reads on a ``RowWindow``: lines of ``line_clocks``, frames of ``frame_lines`` lines, the
    rows of each :class:`ReadPass` of ``passes`` (in order, one after the other in the frame). Starts at a frame's
    start on ``run``. ``restart``, ``row_step``: the window's.

    Measured from ``landed`` (the stream's): ``missed`` counts refused reads, ``rows`` the rows landed; at each row's
    first pixel, ``late`` counts rows not landed yet, ``least_slack`` is the fewest clocks a row landed before it,
    ``least_lead`` the fewest rows landed beyond it (the stream's ring holds ``slots`` rows, so a row's landing time
    is kept until it is shown)."""

    def __init__(self, geometry, passes, slots, frame_lines, line_clocks=CEA_1080P60.h_total):
        for p in passes:
            if p.x0 + p.columns > line_clocks or (p.columns - 1) * p.column_step >= geometry.buf_width:
                raise ValueError(f"a panel at column {p.x0} does not fit a line of {line_clocks} clocks or the row")
            if not p.restart_line < p.first_line + p.lines <= frame_lines \
                    or (p.lines - 1) * p.row_step >= geometry.buf_height:
                raise ValueError(f"a panel's lines {p.first_line}..{p.first_line + p.lines - 1} do not fit the "
                                 f"frame's {frame_lines} or its rows the buffer")
        self.geometry, self.passes, self.slots = geometry, tuple(passes), slots
        self.line_clocks, self.frame_lines = line_clocks, frame_lines
        self.max_step = max(p.row_step for p in passes)
        super().__init__({"window": Out(SharedReadSignature(geometry)), "restart": Out(1),
                          "row_step": Out(range(1, self.max_step + 1)), "run": In(1),
                          "missed_in": In(1), "landed": In(1), "missed": Out(32), "late": Out(32), "rows": Out(32),
                          "least_slack": Out(32, init=2**32 - 1), "least_lead": Out(8, init=255)})

    def elaborate(self, platform):
        m = Module()
        g = self.geometry
        h, line, running = _raster(m, self.run, self.line_clocks, self.frame_lines)
        k = Signal(range(g.buf_height + 1))             # the row's number in its pass
        first_pixel = Signal()
        for p in self.passes:
            with m.If((self.run | running) & (line == p.restart_line) & (h == 0)):
                m.d.comb += [self.restart.eq(1), self.row_step.eq(p.row_step)]
            in_lines = running & (line >= p.first_line) & (line < p.first_line + p.lines)
            with m.If(in_lines):
                m.d.comb += k.eq(line - p.first_line)
                with m.If((h >= p.x0) & (h < p.x0 + p.columns)):
                    m.d.comb += [self.window.request.eq(1),
                                 self.window.port.addr.eq(k * p.row_step * g.buf_width + (h - p.x0) * p.column_step)]
                m.d.comb += first_pixel.eq(h == p.x0)
        m.d.sync += [self.missed.eq(self.missed + (running & self.missed_in)),
                     self.rows.eq(self.rows + (running & self.landed))]
        _measure(m, self, self.restart, self.landed, k, first_pixel, self.slots, g.buf_height)
        return m


class MapReads(wiring.Component):
    """The compositor's depth panel at 1:1 on a :class:`hdl.map_window.MapWindow` (the engine's ring's protocol):
    lines of ``line_clocks``, frames of ``frame_lines``; ``take`` in a frame's first clock (the store takes the
    latest whole map), ``rows_released`` 0 from then; on line ``first_line + k`` (``k < lines``) ring row
    ``k mod slots``'s codes read at clocks ``x0 + x`` (``x < W``), and row ``k`` released after its last code.
    Starts at a frame's start on ``run``.

    Measured: ``missed`` counts the reads of a row not ready (``rows_ready <= k``: shown "not ready"), ``rows`` the
    stream's rows landed (``landed``); at each row's first code ``late``, ``least_slack`` and ``least_lead`` as
    :class:`DisplayReads` has them, from the window's ``rows_ready``."""

    def __init__(self, geometry, slots, first_line, lines, x0, frame_lines, line_clocks=CEA_1080P60.h_total,
                 code_bits=DEPTH_800.code_bits):
        w, h = geometry.buf_width, geometry.buf_height
        if x0 + w > line_clocks or first_line + lines > frame_lines or lines > h or first_line < 1:
            raise ValueError(f"a map panel at column {x0}, lines {first_line}.. does not fit the frame")
        self.geometry, self.slots, self.first_line, self.lines, self.x0 = geometry, slots, first_line, lines, x0
        self.line_clocks, self.frame_lines = line_clocks, frame_lines
        super().__init__({"result": Out(ResultReadSignature((slots * w - 1).bit_length(), code_bits, h)),
                          "take": Out(1), "run": In(1), "landed": In(1),
                          "missed": Out(32), "late": Out(32), "rows": Out(32),
                          "least_slack": Out(32, init=2**32 - 1), "least_lead": Out(8, init=255)})

    def elaborate(self, platform):
        m = Module()
        g, n, x0 = self.geometry, self.slots, self.x0
        w = g.buf_width
        h, line, running = _raster(m, self.run, self.line_clocks, self.frame_lines)
        k = Signal(range(g.buf_height + 1))
        ring_row = Signal(range(n))                     # k mod slots
        in_lines = running & (line >= self.first_line) & (line < self.first_line + self.lines)
        reading = in_lines & (h >= x0) & (h < x0 + w)
        ready, was_ready = self.result.rows_ready, Signal.like(self.result.rows_ready)
        m.d.comb += [k.eq(line - self.first_line), self.take.eq((self.run | running) & (line == 0) & (h == 0)),
                     self.result.addr.eq(Mux(reading, ring_row * w + h - x0, 0))]
        m.d.sync += was_ready.eq(ready)
        with m.If(self.take):
            m.d.sync += [self.result.rows_released.eq(0), ring_row.eq(0)]
        with m.Elif(in_lines & (h == x0 + w - 1)):
            m.d.sync += [self.result.rows_released.eq(k + 1), ring_row.eq(Mux(ring_row == n - 1, 0, ring_row + 1))]
        m.d.sync += [self.missed.eq(self.missed + (reading & (ready <= k))),
                     self.rows.eq(self.rows + (running & self.landed))]
        _measure(m, self, self.take, ready > was_ready, k, in_lines & (h == x0), n, g.buf_height, count=ready)
        return m


def _raster(m, run, line_clocks, frame_lines):
    """The display's raster from ``run`` on: the clock in the line, the line in the frame, running."""
    h, line, running = Signal(range(line_clocks)), Signal(range(frame_lines)), Signal()
    with m.If(run | running):
        m.d.sync += [running.eq(1), h.eq(h + 1)]
        with m.If(h == line_clocks - 1):
            m.d.sync += [h.eq(0), line.eq(Mux(line == frame_lines - 1, 0, line + 1))]
    return h, line, running


def _measure(m, reads, restart, landed, y, first_pixel, slots, height, count=None):
    """``reads``' ``late``, ``least_slack`` and ``least_lead``: each landing's time kept in a ring of ``slots``;
    at each ``first_pixel`` of the ``y``-th row since ``restart``, the rows landed since it (``count``, by default
    counted from ``landed``) against ``y``."""
    now = Signal(32)
    m.d.sync += now.eq(now + 1)
    times = Array(Signal(32, name=f"landed_at_{k}") for k in range(slots))
    write, read = Signal(range(slots)), Signal(range(slots))
    if count is None:
        count = Signal(range(height + slots + 1))
        with m.If(restart):
            m.d.sync += count.eq(0)
        with m.Elif(landed):
            m.d.sync += count.eq(count + 1)
    with m.If(restart):
        m.d.sync += [write.eq(0), read.eq(0)]
    with m.Else():
        with m.If(landed):
            m.d.sync += [times[write].eq(now), write.eq(Mux(write == slots - 1, 0, write + 1))]
        with m.If(first_pixel):
            m.d.sync += read.eq(Mux(read == slots - 1, 0, read + 1))
            with m.If(count > y):
                slack, lead = now - times[read], count - y - 1
                with m.If(slack < reads.least_slack):
                    m.d.sync += reads.least_slack.eq(slack)
                with m.If(lead < reads.least_lead):
                    m.d.sync += reads.least_lead.eq(lead)
            with m.Else():
                m.d.sync += reads.late.eq(reads.late + 1)


class GreedyRows(wiring.Component):
    """A stream's consumer that asks for rows 0, 1, ... (cyclically) whenever its request FIFO has room, from
    ``run`` on; ``landed`` counts the rows that landed."""

    def __init__(self, height, width, slots):
        self.height = height
        super().__init__({"stream": Out(RowStreamSignature(height, width, slots)), "run": In(1),
                          "landed": Out(32)})

    def elaborate(self, platform):
        m = Module()
        fetch = self.stream.fetch
        row = Signal(range(self.height))
        m.d.comb += [fetch.row.eq(row), fetch.en.eq(self.run & fetch.rdy)]
        with m.If(fetch.en):
            m.d.sync += row.eq(Mux(row == self.height - 1, 0, row + 1))
        m.d.sync += self.landed.eq(self.landed + self.stream.landed)
        return m


class GreedyMaps(wiring.Component):
    """The map writer: the real :class:`hdl.map_writer.MapWriter` (``writer``: a code every ``pace`` clocks while
    the store has ``room``) on a ring with ``backlog`` rows ready at the map's start (drained back to back) and one
    more every ``row_clocks`` clocks, as the engine's passes make them (0, or ``fast`` high: every row ready at
    once, so the writer drains row after row at its fastest), a code being its ring address; started again in the
    clock after each map's ``frame_done``, from ``run`` on. ``maps``: maps whose ``frame_done`` was given."""

    def __init__(self, geometry, config, out_rows=2, row_clocks=0, backlog=0, pace=MAP_PACE):
        self.writer = MapWriter(geometry, config, out_rows=out_rows, pace=pace)
        self.row_clocks, self.backlog = row_clocks, min(backlog, geometry.buf_height)
        super().__init__({"feed": Out(CameraFeedSignature(self.writer.feed.signature.geometry)), "room": In(1),
                          "run": In(1), "fast": In(1), "maps": Out(16)})

    def elaborate(self, platform):
        m = Module()
        m.submodules.writer = writer = self.writer
        h = self.writer.geometry.buf_height
        wiring.connect(m, wiring.flipped(self.feed), writer.feed)
        ring, started = writer.result, Signal()
        m.d.sync += [started.eq(writer.start), self.maps.eq(self.maps + writer.feed.status.frame_done),
                     ring.data.eq(ring.addr)]
        m.d.comb += [writer.room.eq(self.room), writer.start.eq(self.run & ~writer.busy & ~started)]
        if self.row_clocks:
            ready, wait = Signal(range(h + 1)), Signal(range(self.row_clocks))
            m.d.sync += wait.eq(Mux(wait == self.row_clocks - 1, 0, wait + 1))
            with m.If(writer.start):
                m.d.sync += [ready.eq(self.backlog), wait.eq(0)]
            with m.Elif((wait == self.row_clocks - 1) & (ready < h)):
                m.d.sync += ready.eq(ready + 1)
            m.d.comb += ring.rows_ready.eq(Mux(self.fast, h, ready))
        else:
            m.d.comb += ring.rows_ready.eq(h)
        return m


class PortCounters(wiring.Component):
    """Counts at MIG's user interface while ``run``: clocks, read words (``read_valid``), written words
    (``write_wren``), write commands per camera (by address: camera ``c``'s buffers) and into the map buffers
    (``map_bursts``, with ``layout.maps``), refreshes started."""

    def __init__(self, layout):
        self.layout = layout
        super().__init__({"read_valid": In(1), "write_wren": In(1), "cmd_wren": In(1), "cmd": In(MIG.CMD_WIDTH),
                          "addr": In(MIG.ADDR_WIDTH), "refreshing": In(1), "run": In(1),
                          "clocks": Out(32), "read_words": Out(32), "write_words": Out(32),
                          "refreshes": Out(32), "camera_bursts": Out(32).array(layout.cameras),
                          "map_bursts": Out(32)})

    def elaborate(self, platform):
        m = Module()
        lay = self.layout
        was_refreshing = Signal()
        m.d.sync += was_refreshing.eq(self.refreshing)

        def into(layout, camera):
            bases = [layout.buffer_base(camera, b) for b in range(layout.buffers)]
            return Cat((self.addr >= lo) & (self.addr < lo + layout.buffer_words) for lo in bases).any()

        with m.If(self.run):
            m.d.sync += [self.clocks.eq(self.clocks + 1),
                         self.read_words.eq(self.read_words + self.read_valid),
                         self.write_words.eq(self.write_words + self.write_wren),
                         self.refreshes.eq(self.refreshes + (self.refreshing & ~was_refreshing))]
            write = self.cmd_wren & (self.cmd == MIG.CMD_WRITE)
            for c in range(lay.cameras):
                m.d.sync += self.camera_bursts[c].eq(self.camera_bursts[c] + (write & into(lay, c)))
            if lay.maps:
                m.d.sync += self.map_bursts.eq(self.map_bursts + (write & into(lay.map_layout, 0)))
        return m


@dataclass(frozen=True)
class WorstCase:
    """The scenario. ``build``: 400 (the 400 x 300 store) or 800 (the 800 x 600 build's store with its map buffers,
    its map writer and map stream; ``rows`` even); ``rows``: buffer rows (the layout's height; the full width, so a
    row is 13 bursts (400) or 25 (800) as in the design); ``frames``: display frames measured (``frame_lines``
    lines each); ``latency``: the MIG model's read latency (clk0) within ``latency_range``; ``display_urgent``: the
    display's camera streams served before the writers (the design) or after them (the map stream is urgent in the
    store); ``display_columns`` (400): one display stream per entry, a 1x panel's first column, cameras
    alternating; ``gap_lines`` (800): the lines between the half-size panels and the maps (the windows restart on
    the first; the design has 40); ``engine_streams``: greedy readers, cameras alternating, listed first (so they
    come before non-urgent display streams); ``slots``: every read stream's row slots (the map stream's too);
    ``camera_gap``: PCLK clocks a buffer pixel (``None``: the build's capture, :data:`CAMERA_GAP` or
    :data:`CAMERA_GAP_800`); ``mig_fifo_depth``: the model's address FIFO's depth (MIG's 1024; the write-data
    FIFO's is at most MIG's 512); ``stride``: bytes from a buffer row to the next, by default a DRAM row (8 KB), so
    every camera buffer row lies in its own DRAM row: two streams of one bank never share an open row (at full
    size, a 416-byte stride, rows up to 19 apart may; the map buffers keep their 1600-byte rows); ``banks``: the
    banks the layout spreads the buffers over (1: all in bank 0)."""
    rows: int = 6
    frames: int = 3
    blank_lines: int = 2
    latency: int = READ_LATENCY_RANGE[1]
    latency_range: tuple = READ_LATENCY_RANGE
    display_urgent: bool = True
    display_columns: tuple = (540, 980, 100, 940)
    engine_streams: int = 2
    slots: int = 2
    camera_gap: int | None = None
    mig_fifo_depth: int = MIG.AF_DEPTH
    stride: int = DRAM_ROW_BYTES
    banks: int = MIG.BANKS
    build: int = 400
    gap_lines: int = 1
    map_row_clocks: int | None = None
    map_backlog: int = 0
    map_pace: int = MAP_PACE

    def __post_init__(self):
        if self.build not in BUILDS:
            raise ValueError(f"build must be one of {BUILDS}, got {self.build}")
        if self.build == 800 and (self.rows % 2 or self.rows < 2 or self.gap_lines < 1):
            raise ValueError(f"the 800 build's half-size panels need an even number of rows and a gap line, got "
                             f"{self.rows} rows and {self.gap_lines} gap lines")
        if (self.map_row_clocks is not None and self.map_row_clocks < 0) or self.map_backlog < 0 \
                or self.map_pace < 1:
            raise ValueError(f"the map writer's rows come at least 0 clocks apart, its backlog is at least 0 rows "
                             f"and its pace at least a clock, got {self.map_row_clocks}, {self.map_backlog} and "
                             f"{self.map_pace}")

    @property
    def maps(self):
        """The maps are in the store (the 800 build)."""
        return self.build == 800

    @property
    def map_rows_every(self):
        """Pix clocks between the map writer's rows (0: back to back)."""
        return MAP_ROW_CLOCKS if self.map_row_clocks is None else self.map_row_clocks

    @property
    def gap(self):
        """PCLK clocks a buffer pixel."""
        if self.camera_gap is not None:
            return self.camera_gap
        return CAMERA_GAP_800 if self.maps else CAMERA_GAP

    @property
    def geometry(self):
        if self.maps:
            return replace(SENSOR_800, height=SENSOR_800.scale * self.rows)
        return SensorGeometry(width=1600, height=4 * self.rows)

    @property
    def layout(self):
        maps = dict(maps=3, map_bits=DEPTH_800.code_bits) if self.maps else {}
        return FrameStoreLayout(width=self.geometry.buf_width, height=self.rows, stride=self.stride,
                                banks=self.banks, **maps)

    @property
    def screen(self):
        """The 800 build's display layout (the regions' columns)."""
        return DisplayLayout.full_maps(CEA_1080P60, SENSOR_800, DEPTH_800)

    @property
    def top_lines(self):
        """The half-size panels' lines (800)."""
        return self.rows // 2

    @property
    def frame_lines(self):
        if self.maps:
            return self.blank_lines + self.top_lines + self.gap_lines + self.rows
        return self.blank_lines + self.rows

    @property
    def maps_line(self):
        """The first line of the 800 build's difference map and depth panel."""
        return self.blank_lines + self.top_lines + self.gap_lines

    @property
    def display_passes(self):
        """Per display stream, its :class:`ReadPass` es."""
        w = self.geometry.buf_width
        if not self.maps:
            return tuple((ReadPass(0, self.blank_lines, self.rows, x0, w),) for x0 in self.display_columns)
        screen = self.screen
        maps_x0 = screen.region("disparity").x0
        return tuple((ReadPass(0, self.blank_lines, self.top_lines, screen.region(side).x0, w // 2, 2, 2),
                      ReadPass(self.blank_lines + self.top_lines, self.maps_line, self.rows, maps_x0, w))
                     for side in ("left", "right"))

    @property
    def streams(self):
        engine = [(i % 2, False) for i in range(self.engine_streams)]
        return tuple(engine + [(i % 2, self.display_urgent) for i in range(len(self.display_passes))])

    def describe(self):
        """A line: the build's streams."""
        if self.maps:
            every = self.map_rows_every
            writer = f"given a row every {every} pix clocks" if every else "draining row after row"
            if every and self.map_backlog:
                writer = f"given {self.map_backlog} rows at a map's start, then a row every {every} pix clocks"
            if self.map_pace != 1:
                writer += f", a code every {self.map_pace} clocks"
            return (f"the 800 x 600 build's store: {self.frames} display frames of {self.frame_lines} lines "
                    f"({self.blank_lines} blank, {self.top_lines} of half-size panels, {self.gap_lines} gap, "
                    f"{self.rows} of the difference map and the depth panel at 1:1), 2 camera display streams and "
                    f"the map stream, the map writer {writer}")
        return (f"{self.frames} display frames of {self.blank_lines} + {self.rows} lines, "
                f"{len(self.display_columns)} display streams at 1:1")


@dataclass
class WorstCaseResult:
    """What a run measured. Times in seconds; rates in MB/s (10**6 bytes a second) of bursts moved (32 bytes each,
    a row's padding included). The display lists have one entry per display stream: the camera streams, then (800)
    the map stream."""
    seconds: float
    line_clocks: int
    missed: list                # refused display reads (the map stream's: reads of a row not ready)
    late: list                  # rows not landed at their first pixel
    slack_clocks: list          # the least pix clocks a row landed before its first pixel
    lead_rows: list             # the fewest rows landed beyond the one starting to show
                                # (both None for a stream whose rows all came late)
    display_mbps: list          # each camera display stream's
    engine_mbps: list
    camera_mbps: list
    efficiency: float           # (read words + written words) / clk0 clocks at MIG's user interface
    refreshes: int
    clocks: int = 0
    display_need_mbps: float = 0.0      # what each display stream needs: its rows over the frame's lines
    display_peak_mbps: float = 0.0      # ... on a line that shows a row: a row a line
    camera_need_mbps: float = 0.0       # what each camera writes at its rate
    engine_need_mbps: float = 0.0       # the design's engine: every row once per map, at the build's map rate
    map_frames: int = 1                 # display frames a full-size map takes (the build's)
    map_mbps: float | None = None       # the map stream's (800), needed, on a line that shows a row
    map_need_mbps: float = 0.0
    map_peak_mbps: float = 0.0
    writer_mbps: float | None = None    # the map writer's (800): delivered, the design's need, maps written
    writer_need_mbps: float = 0.0
    maps_written: int = 0
    writer_pace: int = 1

    @property
    def least_slack(self):
        """The least slack of all display streams in pix clocks (0 when a stream had no row land in time)."""
        return min(0 if c is None else c for c in self.slack_clocks)

    def report(self):
        pix = CLOCKS.PIXEL_HZ
        maps = self.map_mbps is not None
        per_map = "a full-size map per display frame" if self.map_frames == 1 else \
            f"a full-size map every {self.map_frames} display frames"
        lines = [
            f"simulated {self.seconds * 1e6:.1f} us ({self.clocks} clk0, {self.refreshes} refreshes)",
            f"display streams{' (left, right, map)' if maps else ''}: refused reads {self.missed}, rows late "
            f"{self.late}; least slack "
            f"{[None if c is None else round(c / pix * 1e6, 2) for c in self.slack_clocks]} us "
            f"({self.least_slack / self.line_clocks:.0%} of a line); fewest rows landed ahead {self.lead_rows}",
            "DDR2 bandwidth per stream, MB/s needed -> delivered:",
            f"  display (read) {self.display_need_mbps:.1f} ({self.display_peak_mbps:.1f} on a line showing a row) "
            f"-> {_rounded(self.display_mbps)}",
        ]
        if maps:
            lines.append(f"  map stream (read) {self.map_need_mbps:.1f} ({self.map_peak_mbps:.1f} on a line showing a "
                         f"row) -> {self.map_mbps:.1f}")
        lines += [
            f"  cameras (write) {self.camera_need_mbps:.1f} -> {_rounded(self.camera_mbps)}",
            f"  engine (read) {self.engine_need_mbps:.1f} ({per_map}; here as fast as granted) -> "
            f"{_rounded(self.engine_mbps)}",
        ]
        if maps:
            lines.append(f"  map writer (write) {self.writer_need_mbps:.1f} ({per_map}; here a code every "
                         f"{self.writer_pace} clock(s) while the store has room) -> {self.writer_mbps:.1f} "
                         f"({self.maps_written} maps written)")
        lines.append(f"all streams {self.efficiency * PEAK_MBPS:.0f} MB/s of the interface's {PEAK_MBPS:.0f}: "
                     f"efficiency (data clocks / clocks) {self.efficiency:.1%}; MIG violations: none")
        return "\n".join(lines)


def _rounded(rates):
    return [round(x, 1) for x in rates]


def _design(case):
    m = Module()
    m.domains += [ClockDomain(d) for d in ("pix", "mem", "cam_a", "cam_b")]
    lay, g = case.layout, case.geometry
    m.submodules.store = store = FrameStore(lay, g, streams=case.streams, slots=case.slots, map_slots=case.slots)
    depth = case.mig_fifo_depth
    mig = MIGModel(af_depth=depth, wdf_depth=min(depth, MIG.WDF_DEPTH), **layout_window(lay),
                   init_clocks=40, latency_range=case.latency_range)
    m.submodules.mig = DomainRenamer("mem")(mig)
    wiring.connect(m, store.mig, mig.user)
    parts = {"store": store, "mig": mig, "cameras": [], "displays": [], "engines": [], "maps": None}
    for c, domain in enumerate(("cam_a", "cam_b")):
        src = CameraSource(g, case.gap)
        m.submodules[f"camera_{c}"] = DomainRenamer(domain)(src)
        wiring.connect(m, src.feed, store.cameras[c])
        parts["cameras"].append(src)
    for i in range(case.engine_streams):
        greedy = GreedyRows(lay.height, lay.width, case.slots)
        m.submodules[f"engine_{i}"] = DomainRenamer("pix")(greedy)
        wiring.connect(m, greedy.stream, store.streams[i])
        parts["engines"].append(greedy)
    for k, passes in enumerate(case.display_passes):
        i = case.engine_streams + k
        reads = DisplayReads(g, passes, case.slots, case.frame_lines)
        window = RowWindow(g, slots=case.slots, max_step=reads.max_step)
        m.submodules[f"window_{k}"] = DomainRenamer("pix")(window)
        m.submodules[f"display_{k}"] = DomainRenamer("pix")(reads)
        wiring.connect(m, window.stream, store.streams[i])
        wiring.connect(m, reads.window, window.consumer)
        m.d.comb += [window.restart.eq(reads.restart), window.first_row.eq(0), reads.missed_in.eq(window.missed),
                     reads.landed.eq(store.streams[i].landed)]
        if reads.max_step > 1:
            m.d.comb += window.row_step.eq(reads.row_step)
        parts["displays"].append(reads)
    if case.maps:
        parts["maps"] = maps = GreedyMaps(g, DEPTH_800, out_rows=case.slots, row_clocks=case.map_rows_every,
                                             backlog=case.map_backlog, pace=case.map_pace)
        m.submodules.map_writer = DomainRenamer("pix")(maps)
        wiring.connect(m, maps.feed, store.map_feed)
        m.d.comb += maps.room.eq(store.map_room)
        window = MapWindow(g, DEPTH_800.code_bits, slots=case.slots, pixel_bits=8 * lay.map_layout.pixel_bytes)
        reads = MapReads(g, case.slots, case.maps_line, case.rows, case.screen.region("depth").x0, case.frame_lines)
        m.submodules.map_window = DomainRenamer("pix")(window)
        m.submodules.map_reads = DomainRenamer("pix")(reads)
        wiring.connect(m, window.stream, store.map_stream)
        wiring.connect(m, reads.result, window.result)
        m.d.comb += [store.map_take.eq(reads.take), window.take.eq(reads.take), window.taken.eq(store.map_taken),
                     window.valid.eq(store.map_valid), reads.landed.eq(store.map_stream.landed)]
        parts["displays"].append(reads)
    m.submodules.counters = counters = DomainRenamer("mem")(PortCounters(lay))
    user = store.mig
    m.d.comb += [counters.read_valid.eq(user.read.valid), counters.write_wren.eq(user.write.wren),
                 counters.cmd_wren.eq(user.command.wren), counters.cmd.eq(user.command.cmd),
                 counters.addr.eq(user.command.addr), counters.refreshing.eq(mig.refreshing)]
    parts["counters"] = counters
    parts["now"] = now = Signal(32)
    m.d.pix += now.eq(now + 1)
    return m, parts


def run_worst_case(case=WorstCase()):
    """Simulate ``case``: the cameras' first frames (fast; with the maps, the first map too), the pair taken, then
    ``case.frames`` display frames measured. Returns a :class:`WorstCaseResult`; raises
    :class:`sim.models.mig.MIGProtocolViolation` on the MIG model's first violation."""
    m, p = _design(case)
    store, mig, counters, maps = p["store"], p["mig"], p["counters"], p["maps"]
    marks = {}

    async def scenario(ctx):
        ctx.set(mig.latency, case.latency)
        for cam in p["cameras"]:
            ctx.set(cam.fast, 1)
            ctx.set(cam.run, 1)
        if maps is not None:
            ctx.set(maps.fast, 1)
            ctx.set(maps.run, 1)
        first = (p["cameras"][0].frames >= 1) & (p["cameras"][1].frames >= 1)
        await ctx.tick("pix").until(first if maps is None else first & (maps.maps >= 1))
        for cam in p["cameras"] + ([] if maps is None else [maps]):
            ctx.set(cam.fast, 0)
        await ctx.tick("pix").repeat(PAIR_CLOCKS)      # the frames' ends through the FIFOs, the pair formed
        ctx.set(store.take, 1)
        await ctx.tick("pix")
        ctx.set(store.take, 0)
        await ctx.tick("pix").until(store.taken)
        marks["start"] = ctx.get(p["now"])
        marks["maps_before"] = 0 if maps is None else ctx.get(maps.maps)
        for part in p["displays"] + p["engines"] + [counters]:
            ctx.set(part.run, 1)
        line = p["displays"][0].line_clocks
        await ctx.tick("pix").repeat(case.frames * case.frame_lines * line)
        marks["counts"] = {name: ctx.get(getattr(counters, name)) for name in
                           ("clocks", "read_words", "write_words", "refreshes", "map_bursts")}
        marks["camera_bursts"] = [ctx.get(counters.camera_bursts[c]) for c in range(2)]
        marks["engine_rows"] = [ctx.get(e.landed) for e in p["engines"]]
        marks["display"] = [{name: ctx.get(getattr(d, name)) for name in ("missed", "late", "least_slack",
                                                                          "least_lead", "rows")}
                            for d in p["displays"]]
        marks["maps"] = 0 if maps is None else ctx.get(maps.maps) - marks["maps_before"]

    sim = Simulator(m)
    sim.add_clock(1 / CLOCKS.PIXEL_HZ, domain="pix")
    sim.add_clock(1 / MIG.CLK0_HZ, domain="mem")
    sim.add_clock(1 / CLOCKS.CAM_PCLK_HZ, domain="cam_a")
    sim.add_clock(1 / CLOCKS.CAM_PCLK_HZ, phase=3e-9, domain="cam_b")
    sim.add_testbench(watch_violations(mig), background=True)
    sim.add_testbench(scenario)
    sim.run()
    return _result(case, p["displays"][0].line_clocks, marks)


def _measured(value, bits):
    """A least-value register's reading, ``None`` while it holds its initial all-ones (no row landed in time)."""
    return None if value == (1 << bits) - 1 else value


def _result(case, line, marks):
    """The figures from the counters."""
    counts, display = marks["counts"], marks["display"]
    seconds = counts["clocks"] / MIG.CLK0_HZ
    lay = case.layout
    row_bytes = lay.bursts_per_row * BURST_BYTES
    line_s = line / CLOCKS.PIXEL_HZ
    frame_s = case.frame_lines * line_s
    camera_s = camera_frame_clocks(case.geometry, case.gap) / CLOCKS.CAM_PCLK_HZ
    if case.maps:
        full, map_frames = SENSOR_800, check_map_rate(CEA_1080P60, SENSOR_800, DEPTH_800)
        full_map = FrameStoreLayout(width=full.buf_width, height=full.buf_height, maps=3, map_bits=DEPTH_800.code_bits)
        map_row_bytes = lay.map_layout.bursts_per_row * BURST_BYTES
    else:
        full, map_frames = SENSOR, 1
    full_layout = FrameStoreLayout(width=full.buf_width, height=full.buf_height)
    maps_per_s = CEA_1080P60.frame_hz / map_frames
    shown_rows = sum(p.lines for p in case.display_passes[0])
    cameras = len(case.display_passes)
    figures = {}
    if case.maps:
        figures = dict(
            map_mbps=display[cameras]["rows"] * map_row_bytes / seconds / 1e6,
            map_need_mbps=case.rows * map_row_bytes / frame_s / 1e6, map_peak_mbps=map_row_bytes / line_s / 1e6,
            writer_mbps=counts["map_bursts"] * BURST_BYTES / seconds / 1e6,
            writer_need_mbps=full.buf_height * full_map.map_layout.bursts_per_row * BURST_BYTES * maps_per_s / 1e6,
            maps_written=marks["maps"], writer_pace=case.map_pace)
    return WorstCaseResult(
        display_need_mbps=shown_rows * row_bytes / frame_s / 1e6,
        display_peak_mbps=row_bytes / line_s / 1e6,
        camera_need_mbps=case.rows * row_bytes / camera_s / 1e6,
        engine_need_mbps=full.buf_height * full_layout.bursts_per_row * BURST_BYTES * maps_per_s / 1e6,
        seconds=seconds, line_clocks=line, missed=[d["missed"] for d in display], late=[d["late"] for d in display],
        slack_clocks=[_measured(d["least_slack"], 32) for d in display],
        lead_rows=[_measured(d["least_lead"], 8) for d in display],
        display_mbps=[d["rows"] * row_bytes / seconds / 1e6 for d in display[:cameras]],
        engine_mbps=[n * row_bytes / seconds / 1e6 for n in marks["engine_rows"]],
        camera_mbps=[n * BURST_BYTES / seconds / 1e6 for n in marks["camera_bursts"]],
        efficiency=(counts["read_words"] + counts["write_words"]) / counts["clocks"],
        refreshes=counts["refreshes"], clocks=counts["clocks"], map_frames=map_frames, **figures)
