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
"""

from dataclasses import dataclass

from amaranth import Array, Cat, ClockDomain, DomainRenamer, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out
from amaranth.sim import Simulator

from hdl.depth.ports import SharedReadSignature
from hdl.frame_store.frame_store import CameraFeedSignature, FrameStore
from hdl.frame_store.layout import BURST_BYTES, FrameStoreLayout
from hdl.frame_store.row_reader import RowStreamSignature
from hdl.frame_store.row_window import RowWindow
from sim.models.mig import READ_LATENCY_RANGE, MIGModel, layout_window, watch_violations
from spec.board import CLOCKS
from spec.memory import MIG
from spec.sensor import SENSOR, SensorGeometry
from spec.video import CEA_1080P60

__all__ = ["WorstCase", "WorstCaseResult", "run_worst_case", "CameraSource", "camera_frame_clocks",
           "DisplayReads", "GreedyRows", "PortCounters", "CAMERA_GAP", "PEAK_MBPS"]

#: Pix clocks from both cameras' ``frame_done`` to the take: their last bursts and ends written, the pair formed.
PAIR_CLOCKS = 300
#: Bytes in a DRAM row (a column address's 1024 words of 8 bytes).
DRAM_ROW_BYTES = (1 << MIG.COL_BITS) * 8
#: PCLK clocks per kept pixel: two bytes a pixel, every 4th pixel kept.
CAMERA_GAP = 2 * 4
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


class DisplayReads(wiring.Component):
    """A 1x panel's reads on a ``RowWindow``: lines of ``line_clocks``, frames of ``blank_lines`` + ``height``
    lines; buffer row ``y`` read on line ``blank_lines + y``, pixel ``x`` at clock ``x0 + x``; the window restarted
    at row 0 in the frame's first clock. Starts at a frame's start on ``run``.

    Measured from ``landed`` (the stream's): ``missed`` counts refused reads, ``rows`` the rows landed; at each row's first pixel, ``late``
    counts rows not landed yet, ``least_slack`` is the fewest clocks a row landed before it, ``least_lead`` the
    fewest rows landed beyond it (the stream's ring holds ``slots`` rows, so a row's landing time is kept until
    it is shown)."""

    def __init__(self, geometry, x0, slots, line_clocks=CEA_1080P60.h_total, blank_lines=2):
        if x0 + geometry.buf_width > line_clocks:
            raise ValueError(f"a panel at column {x0} does not fit a line of {line_clocks} clocks")
        self.geometry, self.x0, self.slots = geometry, x0, slots
        self.line_clocks, self.blank_lines = line_clocks, blank_lines
        super().__init__({"window": Out(SharedReadSignature(geometry)), "restart": Out(1), "run": In(1),
                          "missed_in": In(1), "landed": In(1), "missed": Out(32), "late": Out(32), "rows": Out(32),
                          "least_slack": Out(32, init=2**32 - 1), "least_lead": Out(8, init=255)})

    @property
    def frame_lines(self):
        return self.blank_lines + self.geometry.buf_height

    def elaborate(self, platform):
        m = Module()
        g = self.geometry
        h = Signal(range(self.line_clocks))
        line = Signal(range(self.frame_lines))
        running = Signal()
        with m.If(self.run | running):
            m.d.sync += [running.eq(1), h.eq(h + 1)]
            with m.If(h == self.line_clocks - 1):
                m.d.sync += [h.eq(0), line.eq(Mux(line == self.frame_lines - 1, 0, line + 1))]
        y = Signal(range(g.buf_height + self.blank_lines))
        m.d.comb += y.eq(line - self.blank_lines)
        shown = running & (line >= self.blank_lines)
        active = shown & (h >= self.x0) & (h < self.x0 + g.buf_width)
        m.d.comb += [
            self.restart.eq((self.run | running) & (line == 0) & (h == 0)),
            self.window.request.eq(active),
            self.window.port.addr.eq(Mux(active, y * g.buf_width + h - self.x0, 0)),
        ]
        m.d.sync += [self.missed.eq(self.missed + (running & self.missed_in)),
                     self.rows.eq(self.rows + (running & self.landed))]
        self._measure(m, y, shown & (h == self.x0))
        return m

    def _measure(self, m, y, first_pixel):
        n = self.slots
        now = Signal(32)
        m.d.sync += now.eq(now + 1)
        times = Array(Signal(32, name=f"landed_at_{k}") for k in range(n))
        count = Signal(range(self.geometry.buf_height + n + 1))     # rows of this frame landed
        write, read = Signal(range(n)), Signal(range(n))
        with m.If(self.restart):
            m.d.sync += [count.eq(0), write.eq(0), read.eq(0)]
        with m.Else():
            with m.If(self.landed):
                m.d.sync += [count.eq(count + 1), times[write].eq(now), write.eq(Mux(write == n - 1, 0, write + 1))]
            with m.If(first_pixel):
                m.d.sync += read.eq(Mux(read == n - 1, 0, read + 1))
                with m.If(count > y):
                    slack, lead = now - times[read], count - y - 1
                    with m.If(slack < self.least_slack):
                        m.d.sync += self.least_slack.eq(slack)
                    with m.If(lead < self.least_lead):
                        m.d.sync += self.least_lead.eq(lead)
                with m.Else():
                    m.d.sync += self.late.eq(self.late + 1)


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


class PortCounters(wiring.Component):
    """Counts at MIG's user interface while ``run``: clocks, read words (``read_valid``), written words
    (``write_wren``), write commands per camera (by address: camera ``c``'s buffers), refreshes started."""

    def __init__(self, layout):
        self.layout = layout
        super().__init__({"read_valid": In(1), "write_wren": In(1), "cmd_wren": In(1), "cmd": In(MIG.CMD_WIDTH),
                          "addr": In(MIG.ADDR_WIDTH), "refreshing": In(1), "run": In(1),
                          "clocks": Out(32), "read_words": Out(32), "write_words": Out(32),
                          "refreshes": Out(32), "camera_bursts": Out(32).array(layout.cameras)})

    def elaborate(self, platform):
        m = Module()
        lay = self.layout
        was_refreshing = Signal()
        m.d.sync += was_refreshing.eq(self.refreshing)
        with m.If(self.run):
            m.d.sync += [self.clocks.eq(self.clocks + 1),
                         self.read_words.eq(self.read_words + self.read_valid),
                         self.write_words.eq(self.write_words + self.write_wren),
                         self.refreshes.eq(self.refreshes + (self.refreshing & ~was_refreshing))]
            write = self.cmd_wren & (self.cmd == MIG.CMD_WRITE)
            for c in range(lay.cameras):
                bases = [lay.buffer_base(c, b) for b in range(lay.buffers)]
                mine = write & Cat((self.addr >= lo) & (self.addr < lo + lay.buffer_words) for lo in bases).any()
                m.d.sync += self.camera_bursts[c].eq(self.camera_bursts[c] + mine)
        return m


@dataclass(frozen=True)
class WorstCase:
    """The scenario. ``rows``: buffer rows (the layout's height; the full 400-pixel width, so a row is 13 bursts as
    in the design); ``frames``: display frames measured (``blank_lines`` + ``rows`` lines each); ``latency``: the
    MIG model's read latency (clk0) within ``latency_range``; ``display_urgent``: the display's streams served
    before the writers (the design) or after them; ``display_columns``: one display stream per entry, its panel's
    first column, cameras alternating; ``engine_streams``: greedy readers, cameras alternating, listed first (so
    they come before non-urgent display streams); ``mig_fifo_depth``: the model's address FIFO's depth (MIG's
    1024; the write-data FIFO's is at most MIG's 512); ``stride``: bytes from a buffer row to the next, by default
    a DRAM row (8 KB), so every buffer row lies in its own DRAM row: two streams of one bank never share an open
    row (at full size, a 416-byte stride, rows up to 19 apart may); ``banks``: the banks the layout spreads the
    buffers over (1: all in bank 0)."""
    rows: int = 6
    frames: int = 3
    blank_lines: int = 2
    latency: int = READ_LATENCY_RANGE[1]
    latency_range: tuple = READ_LATENCY_RANGE
    display_urgent: bool = True
    display_columns: tuple = (540, 980, 100, 940)
    engine_streams: int = 2
    slots: int = 2
    camera_gap: int = CAMERA_GAP
    mig_fifo_depth: int = MIG.AF_DEPTH
    stride: int = DRAM_ROW_BYTES
    banks: int = MIG.BANKS

    @property
    def geometry(self):
        return SensorGeometry(width=1600, height=4 * self.rows)

    @property
    def layout(self):
        return FrameStoreLayout(width=self.geometry.buf_width, height=self.rows, stride=self.stride,
                                banks=self.banks)

    @property
    def streams(self):
        engine = [(i % 2, False) for i in range(self.engine_streams)]
        return tuple(engine + [(i % 2, self.display_urgent) for i in range(len(self.display_columns))])


@dataclass
class WorstCaseResult:
    """What a run measured. Times in seconds; rates in MB/s (10**6 bytes a second) of bursts moved (32 bytes each,
    a row's padding included)."""
    seconds: float
    line_clocks: int
    missed: list                # refused display reads, per display stream
    late: list                  # per display stream: rows not landed at their first pixel
    slack_clocks: list          # per display stream: the least pix clocks a row landed before its first pixel
    lead_rows: list             # per display stream: the fewest rows landed beyond the one starting to show
                                # (both None for a stream whose rows all came late)
    display_mbps: list
    engine_mbps: list
    camera_mbps: list
    efficiency: float           # (read words + written words) / clk0 clocks at MIG's user interface
    refreshes: int
    clocks: int = 0
    display_need_mbps: float = 0.0      # what each display stream needs: its rows over the frame's lines
    display_peak_mbps: float = 0.0      # ... on a line that shows a row: a row a line
    camera_need_mbps: float = 0.0       # what each camera writes at its rate
    engine_need_mbps: float = 0.0       # the design's engine: every row once per map, a map per display frame

    @property
    def least_slack(self):
        """The least slack of all display streams in pix clocks (0 when a stream had no row land in time)."""
        return min(0 if c is None else c for c in self.slack_clocks)

    def report(self):
        pix = CLOCKS.PIXEL_HZ
        lines = [
            f"simulated {self.seconds * 1e6:.1f} us ({self.clocks} clk0, {self.refreshes} refreshes)",
            f"display streams: refused reads {self.missed}, rows late {self.late}; least slack "
            f"{[None if c is None else round(c / pix * 1e6, 2) for c in self.slack_clocks]} us "
            f"({self.least_slack / self.line_clocks:.0%} of a line); fewest rows landed ahead {self.lead_rows}",
            "DDR2 bandwidth per stream, MB/s needed -> delivered:",
            f"  display (read) {self.display_need_mbps:.1f} ({self.display_peak_mbps:.1f} on a line showing a row) "
            f"-> {_rounded(self.display_mbps)}",
            f"  cameras (write) {self.camera_need_mbps:.1f} -> {_rounded(self.camera_mbps)}",
            f"  engine (read) {self.engine_need_mbps:.1f} (a full-size map per display frame; here as fast as "
            f"granted) -> {_rounded(self.engine_mbps)}",
            f"all streams {self.efficiency * PEAK_MBPS:.0f} MB/s of the interface's {PEAK_MBPS:.0f}: efficiency "
            f"(data clocks / clocks) {self.efficiency:.1%}; MIG violations: none",
        ]
        return "\n".join(lines)


def _rounded(rates):
    return [round(x, 1) for x in rates]


def _design(case):
    m = Module()
    m.domains += [ClockDomain(d) for d in ("pix", "mem", "cam_a", "cam_b")]
    lay, g = case.layout, case.geometry
    m.submodules.store = store = FrameStore(lay, g, streams=case.streams, slots=case.slots)
    depth = case.mig_fifo_depth
    mig = MIGModel(af_depth=depth, wdf_depth=min(depth, MIG.WDF_DEPTH), **layout_window(lay),
                   init_clocks=40, latency_range=case.latency_range)
    m.submodules.mig = DomainRenamer("mem")(mig)
    wiring.connect(m, store.mig, mig.user)
    parts = {"store": store, "mig": mig, "cameras": [], "displays": [], "engines": []}
    for c, domain in enumerate(("cam_a", "cam_b")):
        src = CameraSource(g, case.camera_gap)
        m.submodules[f"camera_{c}"] = DomainRenamer(domain)(src)
        wiring.connect(m, src.feed, store.cameras[c])
        parts["cameras"].append(src)
    for i in range(case.engine_streams):
        greedy = GreedyRows(lay.height, lay.width, case.slots)
        m.submodules[f"engine_{i}"] = DomainRenamer("pix")(greedy)
        wiring.connect(m, greedy.stream, store.streams[i])
        parts["engines"].append(greedy)
    for k, x0 in enumerate(case.display_columns):
        i = case.engine_streams + k
        window, reads = RowWindow(g, slots=case.slots), DisplayReads(g, x0, case.slots, blank_lines=case.blank_lines)
        m.submodules[f"window_{k}"] = DomainRenamer("pix")(window)
        m.submodules[f"display_{k}"] = DomainRenamer("pix")(reads)
        wiring.connect(m, window.stream, store.streams[i])
        wiring.connect(m, reads.window, window.consumer)
        m.d.comb += [window.restart.eq(reads.restart), window.first_row.eq(0), reads.missed_in.eq(window.missed),
                     reads.landed.eq(store.streams[i].landed)]
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
    """Simulate ``case``: the cameras' first frames (fast), the pair taken, then ``case.frames`` display frames
    measured. Returns a :class:`WorstCaseResult`; raises :class:`sim.models.mig.MIGProtocolViolation` on the MIG
    model's first violation."""
    m, p = _design(case)
    store, mig, counters = p["store"], p["mig"], p["counters"]
    marks = {}

    async def scenario(ctx):
        ctx.set(mig.latency, case.latency)
        for cam in p["cameras"]:
            ctx.set(cam.fast, 1)
            ctx.set(cam.run, 1)
        await ctx.tick("pix").until((p["cameras"][0].frames >= 1) & (p["cameras"][1].frames >= 1))
        for cam in p["cameras"]:
            ctx.set(cam.fast, 0)
        await ctx.tick("pix").repeat(PAIR_CLOCKS)      # the frames' ends through the FIFOs, the pair formed
        ctx.set(store.take, 1)
        await ctx.tick("pix")
        ctx.set(store.take, 0)
        await ctx.tick("pix").until(store.taken)
        marks["start"] = ctx.get(p["now"])
        for part in p["displays"] + p["engines"] + [counters]:
            ctx.set(part.run, 1)
        line = p["displays"][0].line_clocks
        await ctx.tick("pix").repeat(case.frames * (case.blank_lines + case.rows) * line)
        marks["counts"] = {name: ctx.get(getattr(counters, name)) for name in
                           ("clocks", "read_words", "write_words", "refreshes")}
        marks["camera_bursts"] = [ctx.get(counters.camera_bursts[c]) for c in range(2)]
        marks["engine_rows"] = [ctx.get(e.landed) for e in p["engines"]]
        marks["display"] = [{name: ctx.get(getattr(d, name)) for name in ("missed", "late", "least_slack",
                                                                          "least_lead", "rows")}
                            for d in p["displays"]]

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
    row_bytes = case.layout.bursts_per_row * BURST_BYTES
    line_s = line / CLOCKS.PIXEL_HZ
    camera_s = camera_frame_clocks(case.geometry, case.camera_gap) / CLOCKS.CAM_PCLK_HZ
    full_row_bytes = FrameStoreLayout(width=SENSOR.buf_width, height=SENSOR.buf_height).bursts_per_row * BURST_BYTES
    return WorstCaseResult(
        display_need_mbps=case.rows * row_bytes / ((case.blank_lines + case.rows) * line_s) / 1e6,
        display_peak_mbps=row_bytes / line_s / 1e6,
        camera_need_mbps=case.rows * row_bytes / camera_s / 1e6,
        engine_need_mbps=SENSOR.buf_height * full_row_bytes * CEA_1080P60.frame_hz / 1e6,
        seconds=seconds, line_clocks=line, missed=[d["missed"] for d in display], late=[d["late"] for d in display],
        slack_clocks=[_measured(d["least_slack"], 32) for d in display],
        lead_rows=[_measured(d["least_lead"], 8) for d in display],
        display_mbps=[d["rows"] * row_bytes / seconds / 1e6 for d in display],
        engine_mbps=[n * row_bytes / seconds / 1e6 for n in marks["engine_rows"]],
        camera_mbps=[n * BURST_BYTES / seconds / 1e6 for n in marks["camera_bursts"]],
        efficiency=(counts["read_words"] + counts["write_words"]) / counts["clocks"],
        refreshes=counts["refreshes"], clocks=counts["clocks"])
