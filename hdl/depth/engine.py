"""DepthEngine: a dense disparity map of the two frame buffers, a row at a time (docs/depth.md)."""

from typing import NamedTuple

from amaranth import Cat, Module, Mux, Signal, unsigned
from amaranth.hdl import Assert
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH, DIAGONAL_PATHS, THREE_PATHS, TWO_PATHS
from spec.sensor import SENSOR
from hdl.depth.census import CensusWindow, grey_range_layout
from hdl.depth.left_right_fill import LeftRightFill
from hdl.depth.left_winner import LeftWinner
from hdl.depth.matching_cost import MatchingCost
from hdl.depth.median import Median3x3
from hdl.depth.separable_median import separable_median
from hdl.depth.ports import ResultReadSignature, RowTagReadSignature, SharedReadSignature, token_layout
from hdl.depth.reverse_path import ReversePath
from hdl.depth.row_ring import RowRing
from hdl.depth.sgm_path import SgmPath
from hdl.depth.winner import Winner
from hdl.reset_tree import add_reset_subtree

__all__ = ["DepthEngine", "Schedule", "schedule", "tag_delay", "check_parameters", "median_block", "row_lag",
           "line_buffer_pieces"]

RING_ROWS = 8           # input ring slots per image: the 7 census rows and the one being fetched
CENSUS_SHIFT = 1        # clock of a step at which the ring column enters the census windows
SHIFT_CLOCK = 3         # clock at which the left census shift register takes the new signature
ISSUE_CLOCK = 4         # clock at which group 0 of the step's pixel enters the cost stage
VREAD_CLOCK = 4         # clock at which the vertical path's row minimum is read for the step's pixel
PATH_CLOCK = ISSUE_CLOCK + 1 + MatchingCost.LATENCY     # clock at which group 0 enters the paths
END_GAP = 2             # clocks between a row's last code and the median's end token
LINE_BLOCK_WORDS = 512  # words of a block RAM at the line buffer's width (512 x 72): its pieces' smallest depth


def median_block(config):
    """The median block of ``config.median``: :class:`Median3x3` (3) or the ``separable_median`` class of 5 or 7
    (``config.median_valid``: each median over the valid codes). Its ``ROW_LAG`` is the rows a pass's output
    trails its input: pass y writes row y - ROW_LAG, and a map is H + ROW_LAG passes."""
    return Median3x3 if config.median == 3 else separable_median(config.median, config.median_valid)


def row_lag(config):
    """The rows a pass's output trails its input: the median's ``ROW_LAG`` (:func:`median_block`), and one more
    with ``left_right`` (row y's checked codes go to the median at the start of pass y + 1). Pass y writes row
    y - lag; a map is H + lag passes."""
    return median_block(config).ROW_LAG + (1 if config.left_right else 0)


def line_buffer_pieces(width, groups, block_words=LINE_BLOCK_WORDS):
    """The vertical line buffer's pieces of columns, ``(first column, columns)``: the width rounded up to a
    multiple of the largest power of two of at most ``block_words`` / ``groups`` columns (a smaller piece would
    take a block of its own all the same), split by its binary digits, high to low: each piece a power of two
    of columns, ``columns`` x ``groups`` words (800 x 8 words: 4096, 2048 and 512)."""
    unit = 1 << max(0, (block_words // groups).bit_length() - 1)
    total = -(-width // unit) * unit
    pieces, base = [], 0
    for bit in reversed(range(total.bit_length())):
        if total >> bit & 1:
            pieces.append((base, 1 << bit))
            base += 1 << bit
    return pieces


class Schedule(NamedTuple):
    """The engine's timing (docs/depth.md): a pass is ``steps`` steps of ``step_clocks`` clocks, then
    ``drain_clocks``; ``pass_clocks`` is their total (starting a pass takes 3 clocks more). With three paths the
    forward steps are followed by ``back_steps`` backward steps, ``back_drain`` + 1 clocks for the row's last
    code and the replay of the row's codes into the median, 2 (W + 1) clocks: ``reverse_clocks`` (0 for two
    paths). With the left-right check the drain holds the row's backward scan (:class:`LeftRightFill`), started at
    drain clock ``fill_start``; its replay into the median runs at the start of the next pass."""
    step_clocks: int
    steps: int
    drain_clocks: int
    back_steps: int = 0
    back_drain: int = 0
    replay_clocks: int = 0
    fill_start: int = 0

    @property
    def reverse_clocks(self):
        if not self.back_steps:
            return 0
        return self.back_steps * self.step_clocks + self.back_drain + 1 + self.replay_clocks

    @property
    def pass_clocks(self):
        return self.steps * self.step_clocks + self.drain_clocks + self.reverse_clocks


def schedule(geometry=SENSOR, config=DEPTH):
    """The :class:`Schedule` of a :class:`DepthEngine` with these parameters (without building one)."""
    groups = config.disparities // config.lanes
    step_clocks = max(SgmPath.loop_clocks(config), ISSUE_CLOCK + groups)
    steps = geometry.buf_width + 2 * (config.census_width // 2) + config.disparities - 1
    code_clock = PATH_CLOCK + SgmPath.LATENCY + groups - 1 + Winner.latency(config)
    median = median_block(config)
    if config.left_right:
        # The scan starts when the two-path engine's end token would go to the median (the row's last code is in
        # its store) and ends within the drain; the next pass's start (3 clocks after it at least) replays the row
        # into the median.
        fill_start = code_clock + END_GAP - step_clocks
        return Schedule(step_clocks, steps, fill_start + LeftRightFill.scan_clocks(geometry.buf_width),
                        fill_start=fill_start)
    if config.paths != THREE_PATHS:
        return Schedule(step_clocks, steps, code_clock + END_GAP + median.LATENCY + 2 - step_clocks)
    # Backward steps: the census windows' lead only (left and right move together). The backward drain ends when
    # the row's last code (x = 0, written in the clock of the winner's ``valid``: step clock ``back_code_clock``
    # of the last step) is in the row of codes: the replay reads it in the next clock. The final drain: the
    # median's last output (``LATENCY`` clocks after the replay's end token, which is the clock before the drain)
    # is written in the drain's last clock, before the result ring moves on.
    back_code_clock = PATH_CLOCK + ReversePath.LATENCY + groups - 1 + Winner.latency(config)
    return Schedule(step_clocks, steps, median.LATENCY - 1,
                    back_steps=geometry.buf_width + 2 * (config.census_width // 2),
                    back_drain=back_code_clock - step_clocks, replay_clocks=2 * (geometry.buf_width + 1))


def tag_delay(config=DEPTH, tag_margin=8):
    """Clocks the row-tag samples add to a map with every read granted (docs/depth.md, "Row tags"): pass 0 waits
    for its census_height // 2 + 1 rows, each 3 clocks later for its start sample, and for the last one's end
    sample, ``tag_margin`` + 1 clocks after its last pixel would have counted."""
    return 3 * (config.census_height // 2 + 1) + tag_margin + 1


def check_parameters(geometry, config, out_rows=4, tag_margin=8):
    """``ValueError`` for what :class:`DepthEngine` rejects (see its Raises)."""
    if config.disparities % config.lanes:
        raise ValueError(f"lanes ({config.lanes}) must divide D ({config.disparities})")
    if not 2 <= config.disparities <= geometry.buf_width:
        raise ValueError(f"D = {config.disparities} must be 2..{geometry.buf_width} (the image width)")
    if (config.census_width % 2 == 0 or config.census_height % 2 == 0
            or config.census_height > RING_ROWS - 1):
        raise ValueError(f"the census window must be odd x odd and at most {RING_ROWS - 1} rows high")
    if config.paths not in (TWO_PATHS, THREE_PATHS, DIAGONAL_PATHS):
        raise ValueError(f"the RTL aggregates {', '.join(TWO_PATHS)} (and {THREE_PATHS[-1]}), or "
                         f"{', '.join(DIAGONAL_PATHS)} only, not {', '.join(config.paths)}")
    if config.left_right and config.paths == THREE_PATHS:
        raise ValueError("the RTL's left-right check takes two paths (TWO_PATHS or DIAGONAL_PATHS), not THREE_PATHS")
    if out_rows < 2:
        raise ValueError(f"out_rows must be at least 2, not {out_rows}")
    if tag_margin < 2:
        raise ValueError(f"tag_margin must be at least 2 clocks, not {tag_margin}")
    if config.ad_sampling != "pixel" and config.census_width < 3:
        raise ValueError(f"Birchfield and Tomasi's AD term ({config.ad_sampling!r}) takes its row neighbours from "
                         f"the census window: census_width must be at least 3, not {config.census_width}")
    if config.ad_clip and config.pixel_bits != geometry.grey_bits:
        raise ValueError(f"with the AD term pixel_bits ({config.pixel_bits}) must be the buffers' grey_bits "
                         f"({geometry.grey_bits})")


class DepthEngine(wiring.Component):
    """Census + semi-global matching on two paths (or three) + winner-take-all + median (``config.median``: 3 x 3,
    or the separable 5 x 5 or 7 x 7: :func:`median_block`) (docs/depth.md), computed row by row from the two frame
    buffers into a small ring of result rows.

    With ``config.paths`` = ``DIAGONAL_PATHS`` the second path is the diagonal from the top right (p' = (x + 1,
    y - 1)) instead of top to bottom: the same line buffer, read at column x + 1, and L' = 0, M' = 0 at x = W - 1
    (where p' leaves the image, as at a restart); the schedule is the two-path one.

    With ``config.paths`` = ``THREE_PATHS`` each pass runs the row forward (left to right and top to bottom, their
    sum kept per pixel and disparity in :class:`hdl.depth.reverse_path.ReversePath`'s row store), then backward
    (census and costs again from the input ring, right to left, the winner in descending x into a row of codes),
    then replays the codes into the median (docs/depth.md, "The third path in the RTL", scheme a'):
    ``schedule(...).reverse_clocks`` more per pass.

    With ``config.left_right`` (two paths) the back end also runs the left-right check and the background fill
    (docs/depth.md, "The left-right check in the RTL"): :class:`LeftWinner` on the winner's sums, the row's codes,
    d* and d_L into :class:`LeftRightFill`, whose scan runs in the pass's drain (``schedule(...).fill_start``;
    ``LeftRightFill.scan_clocks(W)`` clocks) and whose replay into the median runs at the start of the next pass:
    the output trails the input by one more row (:func:`row_lag`).

    Right image = reference: the code of right pixel (x, y) is its disparity d (match left(x + d, y)) in
    1 / 2**F pixel (F = ``fraction_bits``), or ``config.invalid`` = D 2**F. ``golden.depth.depth_map`` is the same
    map (with ``row_tags``: the tags the engine sampled).

    Parameters
    ----------
    geometry : SensorGeometry
        Buffer size and grey width (``SENSOR``: 400 x 300 x 5).
    config : DepthConfig
        D, census window, P1, P2, ``max_cost``, lanes, paths (``DEPTH``).
    out_rows : int
        Rows in the result ring (4).
    tag_margin : int
        Clocks from a row's last read to the request of its end tag sample (8; at least 2): at least the row-tag
        source's lag behind the capture's writes.

    Ports
    -----
    start : In(1)
        Start a map (one pulse per frame); a map in progress is abandoned.
    left_row_offset : In(range(-(height - 1), height))
        The map is of the left image moved up by this many rows, signed (row y is buffer row
        min(max(y + offset, 0), H - 1)): the rectification. Held from two clocks before ``start`` to the end of the map.
    left, right : Out(SharedReadSignature)
        The frame buffers' read ports, each shared through request/grant (see ``SharedReadSignature``);
        every pixel is read once per map, rows in order.
    result : In(ResultReadSignature)
        The reader's port into the result ring: address (r mod out_rows) * width + x, data one clock later;
        ``rows_ready`` = rows of this map complete (0 after ``start``); row r is written only once the
        reader's ``rows_released`` > r - out_rows.
    left_tags, right_tags : Out(RowTagReadSignature(height))
        The two buffers' row tags (``row`` from a register, ``tag`` and ``busy`` one clock later; tag 0, busy 0
        from a source that tracks nothing: then the map is the one without tags). Each fetched row is asked
        before its first read and again ``tag_margin`` clocks after its last read (the answer taken one clock
        later); it is torn if either answer is busy or the tags differ. Row y is invalid (raw codes forced to
        ``config.invalid`` before the median) iff, in either image, a row of its census window is torn or the
        window's tags differ, or a window row's left tag is not its right tag (the trackers' tags are paired,
        :class:`hdl.frame_pairing.FramePairing`); the vertical path restarts at row y iff y = 0, row y - 1 is
        invalid, or (either image) row y or y - 1 is torn or their tags differ:
        ``golden.depth.depth_map(..., row_tags=...)``. The
        left tags are those of the rows the engine reads (after ``left_row_offset``).
    busy : Out(1)
        A map is being computed.

    Other attributes (state, not ports: what the formal harness reads, sim/formal/harnesses/depth.py)
    row_invalid, restart : Signal
        The running pass's row is invalid; its vertical path restarts (both valid from the pass's first census
        column on).
    pass_row : Signal(range(height + lag + 1))
        The pass running or waiting to run (y): 0 .. height + lag - 1 while a map runs (pass y writes row y - lag,
        lag = :func:`row_lag`: the median's ``ROW_LAG``, 1 for the 3 x 3, 2 for the separable 5 x 5, 3 for the 7 x
        7, one more with ``left_right``), height + lag once it is done, 0 before the first.

    Elaborated for the platform ``"formal"`` (sim/formal/runner.py), the engine and its row rings also assert
    their invariants (pass control, fetch, tag samples: docs/formal.md), in ``sync``; never in simulation or
    Verilog otherwise.

    Clock domain: ``sync`` (the parent renames it to ``pix``).

    Latency and schedule: a pass per row, ``steps`` steps of ``step_clocks`` clocks plus ``drain_clocks``;
    the pipeline of one pixel within its step (clock 0 = the step's start, g = group):

    ========== ==============================================================
    0          ring read of column clamp(s - 3)
    1          column -> census windows
    2          census signatures registered
    3          three paths: left census shift register shifts
    4          vertical path's row minimum read (pixel x: word x; the diagonal: word x + 1)
    4 + g      group g: the lanes' left signatures, with the AD term their grey values (and Birchfield and
               Tomasi's ranges) (two paths: the candidates' chain advances; three: selected from the shift
               register)
    5 + g      cost: XOR, count 6-bit chunks, grey difference (3 clocks)
    6 + g      vertical line buffer read, group g (word (x, g); the diagonal: (x + 1, g)): the path's ``prev``
               at 7 + g
    8 + g      paths: select L'; 9 + g: partial minimums; 10 + g: L
    11 + g     line buffer write (vertical L), winner sum, path minimum trees
    G + 12 + t winner folded (t = minimum-tree clocks), then F + 6 clocks of ``Subpixel`` to the code,
    2 clocks to the median's end token, ``LATENCY`` in the median (12 for the 3 x 3, 14 for the separable
    5 x 5, 17 for the 7 x 7; 16 and 19 over the valid codes)
    ========== ==============================================================

    A row's first read is at the earliest 4 clocks after the previous row's last one; a pass waits for its rows'
    end tag samples, ``tag_margin`` + 3 clocks after their last reads (docs/depth.md, "Row tags").

    Raises
    ------
    ValueError
        If ``lanes`` does not divide D, D is more than the width, the census window is not odd, the paths are not
        ``spec.depth.TWO_PATHS``, ``THREE_PATHS`` or ``DIAGONAL_PATHS`` (the golden model's other path sets have no
        RTL), ``left_right`` is set with ``THREE_PATHS``, ``tag_margin`` is less than 2, ``ad_sampling`` is a
        Birchfield-Tomasi term with a census window narrower than 3, or the AD term is on (``ad_clip`` > 0) with
        ``pixel_bits`` other than the buffers' ``grey_bits``.
    """

    def __init__(self, geometry=SENSOR, config=DEPTH, *, out_rows=4, tag_margin=8):
        check_parameters(geometry, config, out_rows, tag_margin)
        self.tag_margin = tag_margin
        self.geometry = geometry
        self.config = config
        self.out_rows = out_rows
        self.groups = config.disparities // config.lanes
        w, h = geometry.buf_width, geometry.buf_height
        plan = schedule(geometry, config)
        self.step_clocks, self.steps, self.drain_clocks = plan.step_clocks, plan.steps, plan.drain_clocks
        self.fill_start = plan.fill_start
        self.lead = plan.steps - w
        self.three = config.paths == THREE_PATHS
        self.back_steps, self.back_drain = plan.back_steps, plan.back_drain
        self.backward = Signal()
        if self.three:
            self.phase_count = Signal(range(max(self.back_drain, w) + 1))
            self.replay_odd, self.replaying = Signal(), Signal()
        self.row_invalid, self.restart = Signal(), Signal()
        self.median = median_block(config)
        self.lag = row_lag(config)
        self.pass_row = Signal(range(h + self.lag + 1), name="y")
        super().__init__({
            "start": In(1),
            "left_row_offset": In(range(-(h - 1), h)),
            "left": Out(SharedReadSignature(geometry)),
            "right": Out(SharedReadSignature(geometry)),
            "result": In(ResultReadSignature((out_rows * w - 1).bit_length(), config.code_bits, h)),
            "left_tags": Out(RowTagReadSignature(h)),
            "right_tags": Out(RowTagReadSignature(h)),
            "busy": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        cfg, g = self.config, self.geometry
        w, h = g.buf_width, g.buf_height
        ry = cfg.census_height // 2

        left_ring = add_reset_subtree(m, "left_ring", RowRing(g, RING_ROWS, tag_margin=self.tag_margin))
        right_ring = add_reset_subtree(m, "right_ring", RowRing(g, RING_ROWS, tag_margin=self.tag_margin))
        wiring.connect(m, wiring.flipped(self.left), left_ring.buffer)
        wiring.connect(m, wiring.flipped(self.right), right_ring.buffer)
        wiring.connect(m, wiring.flipped(self.left_tags), left_ring.tags)
        wiring.connect(m, wiring.flipped(self.right_tags), right_ring.tags)

        # --- Pass control ---------------------------------------------------------------------------
        y = self.pass_row              # the pass running or waiting to run; h + lag once the map is done
        step = Signal(range(self.steps))
        clock = Signal(range(self.step_clocks))
        in_run = Signal()
        ring_row = [Signal(range(RING_ROWS), name=f"ring_row{j}") for j in range(cfg.census_height)]
        out_base = Signal(range(self.out_rows * w))

        # Registered in two stages (rows only ever arrive and are only ever released, so a late value is a
        # safe one): a pass waits two clocks in SETTLE for them to see its y.
        # ``before``: the pass's output row y - lag (none while ``no_row``).
        need, first, before = Signal.like(y), Signal(), Signal.like(y)
        room_limit = Signal(range(h + self.out_rows + 1))
        # need = min(y + ry + 1, H): y compared with a constant beside the sum, not the sum after it (pix timing).
        m.d.sync += [need.eq(Mux(y < h - ry - 1, y + ry + 1, h)), first.eq(y == 0), before.eq(y - self.lag),
                     room_limit.eq(self.result.rows_released + self.out_rows)]
        no_row = first
        if self.lag > 1:
            no_row = Signal()
            m.d.sync += no_row.eq(y < self.lag)
        can_start = Signal()
        m.d.sync += can_start.eq((left_ring.tagged >= need) & (right_ring.tagged >= need)
                                 & (no_row | (before < room_limit)))
        # The census rows' ring slots, in two registered stages (y + j - ry, then clamped): y changes only in
        # DRAIN and the slots are read only in RUN, at least three clocks later. ``inner[j]``: census rows j - 1
        # and j are different image rows (the edge into row j is inside the window).
        inner = [Signal(name=f"census_inner{j}") for j in range(cfg.census_height)]
        for j in range(cfg.census_height):
            row = Signal(range(-ry, h + self.lag + ry + 1), name=f"census_row{j}")     # y + j - ry, no wrap
            m.d.sync += row.eq(y + j - ry)
            clamped = Mux(row < 0, 0, Mux(row > h - 1, h - 1, row))
            m.d.sync += [ring_row[j].eq(clamped[:(RING_ROWS - 1).bit_length()]),
                         inner[j].eq((row >= 1) & (row <= h - 1))]
        row_invalid, restart = self._row_flags(m, (left_ring, right_ring), ring_row, inner, first, y)
        limit = Signal(range(h + 1))            # rows that may be fetched: none while idle; late is safe
        m.d.sync += limit.eq(Mux(~self.busy, 0, Mux(y + RING_ROWS - ry < h, y + RING_ROWS - ry, h)))
        m.d.comb += [left_ring.limit.eq(limit), right_ring.limit.eq(limit),
                     left_ring.row_offset.eq(self.left_row_offset),
                     left_ring.start.eq(self.start), right_ring.start.eq(self.start)]

        fsm, drain = self._passes(m, y, step, clock, can_start, in_run, out_base)
        self._drain = (fsm, drain, can_start)
        if platform == "formal":
            self._invariants(m, fsm, (left_ring, right_ring), y, (step, clock, drain), (need, first, before),
                             can_start, limit)

        left_sig, right_sig, pixels = self._census(m, left_ring, right_ring, ring_row, step, clock, in_run)
        issue = self._issue if self.three else self._issue_chain
        token, candidates = issue(m, left_sig, right_sig, pixels, step, clock, in_run)
        horizontal, vertical = self._paths(m, token, candidates, step, clock, in_run, restart)
        writes = self._back_end(m, horizontal, vertical, y, out_base, row_invalid)
        if platform == "formal" and self.three:
            self._reverse_invariants(m, fsm, step, *writes)
        return m

    def _row_flags(self, m, rings, ring_row, inner, first, y):
        """Row y's invalid and vertical-restart flags from the rings' slot bits (docs/depth.md, "Rows from
        different camera frames"), registered in two stages, recomputed every clock: a pass uses them from its
        step 0's clock 5 on, and its rows' bits are in the slots a clock before the pass starts. The two images'
        bits are merged per slot (a slot is bad if torn in either image or its two tags differ; an edge in either
        image) before each census row's slot is picked: one pick a row for both images."""
        ry = self.config.census_height // 2
        left_ring, right_ring = rings
        bad, edge = Signal(RING_ROWS, name="slot_bad"), Signal(RING_ROWS, name="slot_edge")
        m.d.comb += [bad.eq(left_ring.torn | right_ring.torn | Cat(*self._pair_bits(m, rings))),
                     edge.eq(left_ring.edge | right_ring.edge)]
        picked, edge_y = [], []
        for j in range(len(ring_row)):
            bit = Signal(name=f"window_bad{j}")
            m.d.sync += bit.eq(bad.bit_select(ring_row[j], 1))
            picked.append(bit)
            if j or ry == 0:
                bit = Signal(name=f"window_edge{j}")
                m.d.sync += bit.eq(edge.bit_select(ring_row[j], 1) & inner[j])
                if j:
                    picked.append(bit)
                if j == ry:                      # the edge into row y itself
                    edge_y.append(bit)
        row_invalid, prev_invalid, restart = self.row_invalid, Signal(), self.restart
        first_late = Signal()
        m.d.sync += [row_invalid.eq(Cat(*picked).any()), first_late.eq(first),
                     restart.eq(first_late | prev_invalid | Cat(*edge_y).any())]
        # The invalid flag of row y - 1, taken when y moves on (the flags of row y are in two clocks later).
        y_seen = Signal.like(y)
        m.d.sync += y_seen.eq(y)
        with m.If(y != y_seen):
            m.d.sync += prev_invalid.eq(row_invalid)
        return row_invalid, restart

    def _pair_bits(self, m, rings):
        """Per ring slot: its left and right slot tags differ (two camera frame pairs)."""
        left_ring, right_ring = rings
        return [left_ring.slot_tags[k] != right_ring.slot_tags[k] for k in range(RING_ROWS)]

    def _passes(self, m, y, step, clock, can_start, in_run, out_base):
        """The pass state machine: wait for rows and room, run the steps, drain, next pass."""
        w, h = self.geometry.buf_width, self.geometry.buf_height
        drain = Signal(range(self.drain_clocks + 1))
        with m.FSM(name="engine") as fsm:
            with m.State("IDLE"):
                with m.If(self.start):
                    m.next = "SETTLE"
            # Two clocks for can_start to see this pass; a start in them or in WAIT settles again (can_start may
            # still see the abandoned map's rows).
            with m.State("SETTLE"):
                m.d.comb += self.busy.eq(1)
                m.next = "SETTLE2"
                with m.If(self.start):
                    m.next = "SETTLE"
            with m.State("SETTLE2"):
                m.d.comb += self.busy.eq(1)
                m.next = "WAIT"
                with m.If(self.start):
                    m.next = "SETTLE"
            with m.State("WAIT"):
                m.d.comb += self.busy.eq(1)
                with m.If(self.start):
                    m.next = "SETTLE"
                with m.Elif(can_start):
                    m.d.sync += [step.eq(0), clock.eq(0)]
                    if self.three:
                        m.d.sync += self.backward.eq(0)
                    m.next = "RUN"
            with m.State("RUN"):
                m.d.comb += [self.busy.eq(1), in_run.eq(1)]
                m.d.sync += clock.eq(Mux(clock == self.step_clocks - 1, 0, clock + 1))
                with m.If(clock == self.step_clocks - 1):
                    m.d.sync += step.eq(step + 1)
                    if self.three:
                        self._next_phase(m, step)
                    else:
                        with m.If(step == self.steps - 1):
                            m.d.sync += drain.eq(0)
                            m.next = "DRAIN"
                with m.If(self.start):
                    m.next = "SETTLE"
            if self.three:
                self._reverse_states(m, drain)
            with m.State("DRAIN"):
                m.d.comb += self.busy.eq(1)
                m.d.sync += drain.eq(drain + 1)
                with m.If(drain == self.drain_clocks):
                    m.d.sync += y.eq(y + 1)
                    with m.If(self._has_row(y)):
                        m.d.sync += [self.result.rows_ready.eq(y if self.lag == 1 else y - (self.lag - 1)),
                                     out_base.eq(Mux(out_base == (self.out_rows - 1) * w, 0, out_base + w))]
                    with m.If(y == h + self.lag - 1):
                        m.next = "IDLE"
                    with m.Else():
                        m.next = "SETTLE"
                with m.If(self.start):
                    m.next = "SETTLE"
        with m.If(self.start):
            m.d.sync += [y.eq(0), self.result.rows_ready.eq(0), out_base.eq(0)]
        return fsm, drain

    def _has_row(self, y):
        """Pass ``y`` writes a row (y - lag): y >= lag."""
        return (y != 0) if self.lag == 1 else (y >= self.lag)

    def _next_phase(self, m, step):
        """Three paths, at a step's last clock: after the forward steps the backward ones (docs/depth.md, scheme
        a'), after those the backward drain."""
        with m.If(~self.backward & (step == self.steps - 1)):
            m.d.sync += [self.backward.eq(1), step.eq(0)]
        with m.If(self.backward & (step == self.back_steps - 1)):
            m.d.sync += self.phase_count.eq(0)
            m.next = "BACK_DRAIN"

    def _reverse_states(self, m, drain):
        """Three paths: wait for the row's last code (backward drain), then replay the row of codes into the
        median in ascending x, one every other clock, and its end token; then the common drain."""
        w = self.geometry.buf_width
        with m.State("BACK_DRAIN"):
            m.d.comb += self.busy.eq(1)
            m.d.sync += self.phase_count.eq(self.phase_count + 1)
            with m.If(self.phase_count == self.back_drain):
                m.d.sync += [self.phase_count.eq(0), self.replay_odd.eq(0)]
                m.next = "REPLAY"
            with m.If(self.start):
                m.next = "SETTLE"
        with m.State("REPLAY"):
            m.d.comb += [self.busy.eq(1), self.replaying.eq(1)]
            m.d.sync += self.replay_odd.eq(~self.replay_odd)
            with m.If(self.replay_odd):
                m.d.sync += self.phase_count.eq(self.phase_count + 1)
                with m.If(self.phase_count == w):
                    m.d.sync += drain.eq(0)
                    m.next = "DRAIN"
            with m.If(self.start):
                m.next = "SETTLE"

    def _invariants(self, m, fsm, rings, y, counters, registered, can_start, limit):
        """The pass control's invariants (elaborated for the formal platform only): what makes the safety
        properties of sim/formal/harnesses/depth.py inductive. Each is an ``Assert`` named by its message."""
        h, ry, w = self.geometry.buf_height, self.config.census_height // 2, self.geometry.buf_width
        step, clock, drain = counters
        need, first, before = registered
        running = fsm.ongoing("RUN") | fsm.ongoing("DRAIN")
        settled = fsm.ongoing("SETTLE2") | fsm.ongoing("WAIT") | running
        rows_needed = Mux(y + ry + 1 < h, y + ry + 1, h)            # rows up to min(y + ry, h - 1)
        rows_allowed = Mux(y + RING_ROWS - ry < h, y + RING_ROWS - ry, h)
        invariants = {
            # The pass counter: 0 .. h + lag - 1 while a map runs, h + lag once it is done; rows_ready trails it by
            # the median's row lag.
            "pass_in_map": Mux(fsm.ongoing("IDLE"), (y == 0) | (y == h + self.lag), y <= h + self.lag - 1),
            "rows_ready_trails_pass": self.result.rows_ready == Mux(self._has_row(y), y - self.lag, 0),
            "step_in_pass": ~fsm.ongoing("RUN") | ((step < self.steps) & (clock < self.step_clocks)),
            "drain_in_range": ~fsm.ongoing("DRAIN") | (drain <= self.drain_clocks),
            # SETTLE and SETTLE2 give the registers a clock each to see the pass's y.
            "admission_sees_pass": ~settled | ((need == rows_needed) & (first == (y == 0))
                                               & (before == (y - self.lag)[:len(before)])),
            # The fetch limit is registered from y: one clock late after a start, never ahead of the pass.
            "fetch_limit_of_pass": fsm.ongoing("SETTLE") | (limit <= rows_allowed),
        }
        for i, ring in enumerate(rings):
            side = ("left", "right")[i]
            # Rows only arrive while a map runs: what can_start saw is still there in WAIT, and in the pass.
            invariants[f"{side}_admitted_rows_tagged"] = ~(fsm.ongoing("WAIT") & can_start) | (ring.tagged >= need)
            invariants[f"{side}_running_pass_rows_tagged"] = ~running | (ring.tagged >= rows_needed)
            invariants[f"{side}_fetch_within_limit"] = fsm.ongoing("IDLE") | (ring.fetch_row <= rows_allowed)
        for name, test in invariants.items():
            m.d.sync += Assert(test, name)

    def _reverse_invariants(self, m, fsm, step, codes_write, results_write):
        """Three paths: the pass order and the phase counters (elaborated for the formal platform only; docs/formal.md,
        "Which property covers what"). Each is an ``Assert`` named by its message."""
        w = self.geometry.buf_width
        backward_run = fsm.ongoing("RUN") & self.backward
        after_backward = fsm.ongoing("BACK_DRAIN") | fsm.ongoing("REPLAY") | fsm.ongoing("DRAIN")
        invariants = {
            # The pass order: forward steps, backward steps, the backward drain, the replay, the drain.
            "backward_step_in_pass": ~backward_run | (step < self.back_steps),
            "backward_before_drains": ~after_backward | self.backward,
            "back_drain_in_range": ~fsm.ongoing("BACK_DRAIN") | (self.phase_count <= self.back_drain),
            "replay_in_row": ~fsm.ongoing("REPLAY") | (self.phase_count <= w),
            # The backward census columns: W - 1 + rx - step clamped, counted down from W - 1.
            "back_column_in_row": self._back_col < w,
            # The row of codes is whole when the replay reads it: the backward drain outlasts the winner.
            "codes_written_before_replay": ~(codes_write.en & fsm.ongoing("REPLAY")),
            # The result ring takes the replay's median outputs only, the last of them in the drain.
            "results_written_in_replay_or_drain": ~results_write.en | fsm.ongoing("REPLAY") | fsm.ongoing("DRAIN"),
        }
        for name, test in invariants.items():
            m.d.sync += Assert(test, name)

    def _census(self, m, left_ring, right_ring, ring_row, step, clock, in_run):
        """Step clocks 0-3: ring reads, census windows, the left census shift register (newest first). Returns
        the left signature (two paths) or shift register (three), the right signature and the centres' AD pixels
        (left, right: None without the AD term)."""
        cfg, w = self.config, self.geometry.buf_width
        rx = cfg.census_width // 2
        signatures, pixels = [], []
        for name, ring, lag in (("left", left_ring, 0), ("right", right_ring, cfg.disparities - 1)):
            # Column clamp(step - rx - lag), counted: the right window lags the left one by D - 1 columns.
            col = Signal(range(w), name=f"{name}_column")
            moving = Signal(name=f"{name}_moving")
            m.d.comb += ring.col.eq(Mux(self.backward, self._back_column(m, step, clock), col) if self.three else col)
            with m.If(~in_run):
                m.d.sync += [col.eq(0), moving.eq(rx + lag == 0)]
            with m.Elif(clock == self.step_clocks - 1):
                with m.If(step == rx + lag - 1):
                    m.d.sync += moving.eq(1)
                with m.If(moving & (col != w - 1)):
                    m.d.sync += col.eq(col + 1)
            census = CensusWindow(cfg, self.geometry.grey_bits)
            m.submodules[f"{name}_census"] = census
            for j in range(cfg.census_height):
                m.d.comb += census.column[j].eq(ring.column[ring_row[j]])
            m.d.comb += census.shift.eq(in_run & (clock == CENSUS_SHIFT))
            signatures.append(census.census)
            pixels.append(self._pixel(m, census, name) if cfg.ad_clip else None)
        if not self.three:                      # two paths: the candidates' chain is built at the issue
            return signatures[0], signatures[1], pixels
        entry = self._candidate_layout()
        shift_reg = [Signal(entry, name=f"left_census{j}", reset_less=True) for j in range(cfg.disparities)]
        # The shift register's enable (D entries wide: the largest clock-enable net) from a register, decoded a
        # clock early: RUN at clock SHIFT_CLOCK is always RUN at clock SHIFT_CLOCK - 1 the clock before without a
        # start (a step starts at clock 0 and is longer than ISSUE_CLOCK > SHIFT_CLOCK clocks).
        shift_now = Signal(name="census_shift_now")
        m.d.sync += shift_now.eq(in_run & (clock == SHIFT_CLOCK - 1) & ~self.start)
        with m.If(shift_now):
            inside = step < w + 2 * rx
            if self.three:                      # backward: the entering column is inside from step 2 rx on
                inside = Mux(self.backward, step >= 2 * rx, inside)
            m.d.sync += [shift_reg[0].census.eq(signatures[0]), shift_reg[0].inside.eq(inside)]
            if cfg.ad_clip:
                m.d.sync += shift_reg[0].pixel.eq(pixels[0])
            for j in range(1, cfg.disparities):
                m.d.sync += shift_reg[j].eq(shift_reg[j - 1])
        return shift_reg, signatures[1], pixels

    def _pixel_layout(self, ranges=True):
        """What the AD term takes of a pixel: its grey value and, for Birchfield and Tomasi's term (unless not
        ``ranges``), its range."""
        cfg = self.config
        fields = {"grey": cfg.pixel_bits}
        if cfg.ad_sampling != "pixel" and ranges:
            fields["range"] = grey_range_layout(cfg.pixel_bits)
        return data.StructLayout(fields)

    def _pixel(self, m, census, name):
        """The AD term's view of a census window's centre (:meth:`_pixel_layout`)."""
        pixel = Signal(self._pixel_layout(), name=f"{name}_pixel")
        m.d.comb += pixel.grey.eq(census.centre)
        if self.config.ad_sampling != "pixel":
            m.d.comb += pixel.range.eq(census.centre_range)
        return pixel

    def _candidate_layout(self, ranges=True):
        """A left candidate: its census signature, whether its column is inside the image, and (AD term) its
        pixel (:meth:`_pixel_layout`)."""
        cfg = self.config
        fields = {"census": cfg.census_bits, "inside": 1}
        if cfg.ad_clip:
            fields["pixel"] = self._pixel_layout(ranges)
        return data.StructLayout(fields)

    def _lanes(self, m, right_cen, right_pixel, left_sel, left_pixel, inside):
        """The issued group's candidates, the cost stage's inputs: the right pixel's census (and AD pixel), per
        lane the left one's census (and AD pixel) and inside bit."""
        cfg, P = self.config, self.config.lanes
        fields = {"right": cfg.census_bits, "left": data.ArrayLayout(cfg.census_bits, P), "inside": P}
        if cfg.ad_clip:
            pixel = self._pixel_layout()
            fields |= {"right_pixel": pixel, "left_pixel": data.ArrayLayout(pixel, P)}
        lanes = Signal(data.StructLayout(fields), name="candidates")
        m.d.comb += [lanes.right.eq(right_cen), lanes.left.eq(left_sel), lanes.inside.eq(inside)]
        if cfg.ad_clip:
            m.d.comb += [lanes.right_pixel.eq(right_pixel), lanes.left_pixel.eq(left_pixel)]
        return lanes

    def _back_column(self, m, step, clock):
        """Three paths, backward steps: the ring column clamp(W - 1 + rx - step) for both images, counted down
        (one counter, built on the first call)."""
        if not hasattr(self, "_back_col"):
            w, rx = self.geometry.buf_width, self.config.census_width // 2
            col, moving = Signal(range(w), name="back_column"), Signal(name="back_moving")
            with m.If(~self.backward):
                m.d.sync += [col.eq(w - 1), moving.eq(rx == 0)]
            with m.Elif(clock == self.step_clocks - 1):
                with m.If(step == rx - 1):
                    m.d.sync += moving.eq(1)
                with m.If(moving & (col != 0)):
                    m.d.sync += col.eq(col - 1)
            self._back_col = col
        return self._back_col

    def _issue_token(self, m, right_sig, right_pixel, step, clock, in_run):
        """Step clocks 4 .. 4 + G - 1: group g's token and the right signature (and grey), registered."""
        cfg, w = self.config, self.geometry.buf_width
        G = self.groups
        x = step - self.lead
        lead = self.lead
        if self.three:                          # backward: x = W - 1 + 2 rx - step, from step 2 rx on
            x = Mux(self.backward, w - 1 + (cfg.census_width // 2) * 2 - step, x)
            lead = Mux(self.backward, (cfg.census_width // 2) * 2, self.lead)
        group = clock - ISSUE_CLOCK
        token = Signal(token_layout(G, w))
        right_cen = Signal(cfg.census_bits, reset_less=True)
        issuing = in_run & (clock >= ISSUE_CLOCK) & (clock < ISSUE_CLOCK + G) & (step >= lead)
        m.d.sync += [
            token.go.eq(issuing),
            token.group.eq(group),
            token.last.eq(group == G - 1),
            token.first.eq(x == 0),
            token.x.eq(x),
            right_cen.eq(right_sig),
        ]
        if right_pixel is not None:
            right_pixel_reg = Signal(self._pixel_layout(), name="right_pixel", reset_less=True)
            m.d.sync += right_pixel_reg.eq(right_pixel)
            right_pixel = right_pixel_reg
        return token, right_cen, right_pixel, group

    def _issue_chain(self, m, left_sig, right_sig, pixels, step, clock, in_run):
        """Two paths: the lanes' left signatures from a chain of candidates (no select).

        Lane k of group g in step s takes census_L(x + gP + k) (x = s - lead). That is lane k + 1's candidate of
        group g one step earlier, and lane P - 1's of group g is lane 0's of group g + 1 one step earlier; lane
        P - 1's of the last group is the signature that entered in this step. So one register chain R advances
        at each of a step's G issue clocks: its input is the new signature (with its ``inside`` bit) at the last
        group, else R[D - 2] (the candidate D - 1 issue clocks old); lane k reads R[(P - 1 - k) G]. Every
        candidate of a pixel (steps >= lead) entered the chain in the same pass, so the chain needs no reset.
        The chain's stretches between taps are plain shift registers (SRLs), where a D-entry shift register
        and a G:1 select per lane and bit would be logic. With the AD term each candidate carries its grey value
        beside its signature. Birchfield and Tomasi's ranges go along a second chain of registers with a reset (to
        0, never read: every range read entered in the pass), so flip-flops: a register with a reset cannot be an
        SRL16E, and the build is short of LUTs, not of flip-flops (docs/depth.md, "Where the LUTs are")."""
        cfg = self.config
        G, P, D = self.groups, cfg.lanes, cfg.disparities
        rx, w = cfg.census_width // 2, self.geometry.buf_width
        token, right_cen, right_pixel, group = self._issue_token(m, right_sig, pixels[1], step, clock, in_run)
        entry = self._candidate_layout(ranges=False)
        length = max(D - 1, (P - 1) * G + 1)
        chain = [Signal(entry, name=f"left_candidate{i}", reset_less=True) for i in range(length)]
        fresh = Signal(entry)
        m.d.comb += [fresh.census.eq(left_sig), fresh.inside.eq(step < w + 2 * rx)]
        if cfg.ad_clip:
            m.d.comb += fresh.pixel.grey.eq(pixels[0].grey)
        ranges = []
        if cfg.ad_sampling != "pixel":
            ranges = [Signal(grey_range_layout(cfg.pixel_bits), name=f"left_range{i}") for i in range(length)]
        # The chain's enable (the largest clock-enable net) from a register, decoded a clock early: in RUN
        # without a start the next clock is clock + 1 in RUN, or clock 0 (not an issue clock) after a step's last.
        advance = Signal(name="candidates_advance")
        m.d.sync += advance.eq(in_run & (clock >= ISSUE_CLOCK - 1) & (clock < ISSUE_CLOCK + G - 1) & ~self.start)
        with m.If(advance):
            for links, new in ((chain, fresh), (ranges, pixels[0].range if ranges else None)):
                if links:
                    m.d.sync += links[0].eq(Mux(group == G - 1, new, links[D - 2]) if G > 1 else new)
                    for i in range(1, length):
                        m.d.sync += links[i].eq(links[i - 1])
        left_sel = Signal(data.ArrayLayout(cfg.census_bits, P))
        left_pixel = Signal(data.ArrayLayout(self._pixel_layout(), P)) if cfg.ad_clip else None
        inside = Signal(P)
        for k in range(P):
            tap = (P - 1 - k) * G
            m.d.comb += [left_sel[k].eq(chain[tap].census), inside[k].eq(chain[tap].inside)]
            if cfg.ad_clip:
                m.d.comb += left_pixel[k].grey.eq(chain[tap].pixel.grey)
            if ranges:
                m.d.comb += left_pixel[k].range.eq(ranges[tap])
        return token, self._lanes(m, right_cen, right_pixel, left_sel, left_pixel, inside)

    def _issue(self, m, shift_reg, right_sig, pixels, step, clock, in_run):
        """Three paths, step clocks 4 .. 4 + G - 1: group g's token and its lanes' left signatures (and pixels),
        selected from the left census shift register and registered."""
        cfg = self.config
        G, P, D = self.groups, cfg.lanes, cfg.disparities
        token, right_cen, right_pixel, group = self._issue_token(m, right_sig, pixels[1], step, clock, in_run)
        left_sel = Signal(data.ArrayLayout(cfg.census_bits, P), reset_less=True)
        left_pixel = Signal(data.ArrayLayout(self._pixel_layout(), P), reset_less=True) if cfg.ad_clip else None
        inside = Signal(P)
        with m.Switch(group):
            for gi in range(G):
                with m.Case(gi):
                    for k in range(P):
                        e = shift_reg[D - 1 - (gi * P + k)]          # candidate d = gi * P + k
                        b = shift_reg[gi * P + k]                   # backward: the newest entry is d = 0
                        pick = Mux(self.backward, b.as_value(), e.as_value())
                        chosen = data.View(self._candidate_layout(), pick)
                        m.d.sync += [left_sel[k].eq(chosen.census), inside[k].eq(chosen.inside)]
                        if cfg.ad_clip:
                            m.d.sync += left_pixel[k].eq(chosen.pixel)
        self.issue_backward = Signal()
        m.d.sync += self.issue_backward.eq(self.backward)
        return token, self._lanes(m, right_cen, right_pixel, left_sel, left_pixel, inside)

    def _paths(self, m, token, lanes, step, clock, in_run, restart):
        """Cost (3 clocks), then both paths; the vertical path's line buffer (a group a clock, from the cost
        stage's tokens) and row minimums (read at VREAD_CLOCK)."""
        cfg, w = self.config, self.geometry.buf_width
        G, P = self.groups, cfg.lanes
        cost = add_reset_subtree(m, "cost", MatchingCost(cfg))
        m.d.comb += [cost.right.eq(lanes.right), cost.left.eq(lanes.left), cost.inside.eq(lanes.inside)]
        if cfg.ad_clip:
            m.d.comb += cost.right_grey.eq(lanes.right_pixel.grey)
            for k in range(P):
                m.d.comb += cost.left_grey[k].eq(lanes.left_pixel[k].grey)
                if cfg.ad_sampling != "pixel":
                    m.d.comb += cost.left_range[k].eq(lanes.left_pixel[k].range)
            if cfg.ad_sampling == "bt":
                m.d.comb += cost.right_range.eq(lanes.right_pixel.range)
        tok = token
        cost_tokens = []
        back = self.issue_backward if self.three else None
        for s in range(MatchingCost.LATENCY):
            delayed = Signal(token_layout(G, w), name=f"cost_token{s}")
            m.d.sync += delayed.eq(tok)
            tok = delayed
            cost_tokens.append(tok)
            if self.three:
                back_delayed = Signal(name=f"cost_backward{s}")
                m.d.sync += back_delayed.eq(back)
                back = back_delayed
        horizontal = add_reset_subtree(m, "horizontal", SgmPath(cfg, recurrent=True, width=w))
        vertical = add_reset_subtree(m, "vertical", SgmPath(cfg, recurrent=False, width=w))
        forward_tok = tok
        if self.three:
            forward_tok, back_tok = Signal.like(tok, name="forward_token"), Signal.like(tok, name="backward_token")
            m.d.comb += [forward_tok.eq(tok), forward_tok.go.eq(tok.go & ~back),
                         back_tok.eq(tok), back_tok.go.eq(tok.go & back)]
            self.reverse = reverse = add_reset_subtree(m, "reverse", ReversePath(cfg, width=w))
            m.d.comb += [reverse.token.eq(back_tok), reverse.cost.eq(cost.cost),
                         reverse.store_token.eq(horizontal.l_token)]
            for k in range(P):
                m.d.comb += reverse.carry[k].eq(horizontal.l[k] + vertical.l[k])
        for path in (horizontal, vertical):
            m.d.comb += [path.token.eq(forward_tok), path.cost.eq(cost.cost)]

        self._line_buffer(m, vertical, cost_tokens, step, clock, restart)
        return horizontal, vertical

    def _line_buffer(self, m, vertical, cost_tokens, step, clock, restart):
        """The vertical path's previous row: L' a group a clock (from the cost stage's tokens) and M' (read at
        VREAD_CLOCK)."""
        cfg, w = self.config, self.geometry.buf_width
        G, P = self.groups, cfg.lanes
        pbits = cfg.path_bits
        # The line buffer: W x G words of P path costs, word (x, g) pixel x's group g, read a group a clock
        # (group g of pixel x at step clock 6 + g: in the vertical path's ``prev`` at 7 + g, the clock before
        # the group enters the path) and written a group a clock by the vertical path's ``l`` (11 + g). It is
        # built as simple dual-port block RAMs (docs/board.md), one per piece of columns
        # (:func:`line_buffer_pieces`), each a power of two deep, so that none needs a select between blocks:
        # the only select is the registered choice of piece (zero where the path starts), a LUT a bit.
        pieces = line_buffer_pieces(w, G, LINE_BLOCK_WORDS)
        reads, writes = [], []
        for i, (_, size) in enumerate(pieces):
            memory = Memory(shape=unsigned(pbits * P), depth=size * G, init=[])
            m.submodules[f"vertical_rows{i}"] = memory
            reads.append(memory.read_port())
            writes.append(memory.write_port())
        m.submodules.vertical_minimums = minimums = Memory(shape=unsigned(pbits), depth=w, init=[])
        min_read, min_write = minimums.read_port(), minimums.write_port()

        def word(x, group, size):      # the address in its piece: x's low bits and the group
            low = x[:(size - 1).bit_length()]
            return Cat(group, low) if G & (G - 1) == 0 else low * G + group

        # Read before write: pixel x of row y reads row y - 1's words (x, g) (the diagonal: (x + 1, g)) in its
        # own step at clocks 6 + g and writes its own words (x, g) at 11 + g; pixel x + 1 (a step later) writes
        # (x + 1, g). So every word of row y - 1 is read before row y overwrites it, for TWO_PATHS, THREE_PATHS
        # (the forward pass is TWO_PATHS'; the backward pass's tokens read words nobody uses and write none;
        # ReversePath's carry takes the vertical ``l`` of the forward pass, which this does not move) and
        # DIAGONAL_PATHS. Pass y + 1 reads only after pass y's last write (the drain).
        read_tok = cost_tokens[-3]              # a group at step clock 6 + g
        x = step - self.lead
        min_x_read = Mux((x >= 0) & (x < w), x, 0)
        read_x = read_tok.x
        fresh, read_fresh = restart, restart    # L' = 0, M' = 0: the path starts at this pixel
        if cfg.paths == DIAGONAL_PATHS:
            # p' = (x + 1, y - 1): row y - 1's word x + 1, read in pixel x's step (x + lead). Row y overwrites
            # that word with pixel x + 1's L and M only, from clock PATH_CLOCK + SgmPath.LATENCY of the next
            # step on (its groups issue in step x + 1 + lead): after this read. At x = W - 1 p' is outside the
            # image: the path starts there.
            min_x_read = Mux((x >= 0) & (x < w - 1), x + 1, 0)
            read_x = Mux(read_tok.x < w - 1, read_tok.x + 1, 0)
            fresh = restart | (x == w - 1)
            read_fresh = restart | (read_tok.x == w - 1)
        choice = Signal(range(len(pieces) + 1), name="vertical_piece")     # len(pieces): zero
        piece = len(pieces)
        for i, (base, size) in reversed(list(enumerate(pieces))):
            piece = Mux(read_x < base + size, i, piece) if i < len(pieces) - 1 else i
        with m.If(read_tok.go):
            m.d.sync += choice.eq(Mux(read_fresh, len(pieces), piece))
        for port, (_, size) in zip(reads, pieces):
            m.d.comb += [port.addr.eq(word(read_x, read_tok.group, size)), port.en.eq(read_tok.go)]
        with m.Switch(choice):
            for i, port in enumerate(reads):
                with m.Case(i):
                    m.d.comb += vertical.prev.eq(port.data)
        m.d.comb += [min_read.addr.eq(min_x_read), min_read.en.eq(clock == VREAD_CLOCK)]
        with m.If(clock == VREAD_CLOCK + 1):
            m.d.sync += vertical.prev_min.eq(Mux(fresh, 0, min_read.data))
        lt = vertical.l_token
        for port, (base, size) in zip(writes, pieces):
            inside = lt.go
            if base:
                inside &= lt.x >= base
            if base + size < w:
                inside &= lt.x < base + size
            m.d.comb += [port.addr.eq(word(lt.x, lt.group, size)), port.data.eq(vertical.l.as_value()),
                         port.en.eq(inside)]
        min_x = Signal(range(w))
        with m.If(lt.go & lt.last):
            m.d.sync += min_x.eq(lt.x)
        m.d.comb += [min_write.addr.eq(min_x), min_write.data.eq(vertical.m), min_write.en.eq(vertical.m_valid)]

    def _back_end(self, m, horizontal, vertical, y, out_base, row_invalid):
        """Winner, median, result ring."""
        cfg, g = self.config, self.geometry
        w = g.buf_width
        median = add_reset_subtree(m, "median", self.median(cfg, g))
        if not cfg.left_right:                  # with the check the median's pass is the previous one
            m.d.comb += median.y.eq(y)
        codes_write = None
        if self.three:
            codes_write = self._reverse_back_end(m, median, row_invalid)
        elif cfg.left_right:
            self._left_right_back_end(m, horizontal, vertical, median, row_invalid)
        else:
            winner = add_reset_subtree(m, "winner", Winner(cfg, w))
            m.d.comb += [winner.token.eq(horizontal.l_token), winner.horizontal.eq(horizontal.l),
                         winner.vertical.eq(vertical.l)]
            end = [Signal(name=f"row_end{i}") for i in range(END_GAP)]
            m.d.sync += end[0].eq(winner.valid & (winner.x == w - 1))
            for i in range(1, END_GAP):
                m.d.sync += end[i].eq(end[i - 1])
            m.d.comb += [
                median.valid.eq(winner.valid | end[-1]),
                median.x.eq(Mux(end[-1], w, winner.x)),
                median.code.eq(Mux(row_invalid, cfg.invalid, winner.code)),
            ]
        m.submodules.results = results = Memory(shape=unsigned(cfg.code_bits), depth=self.out_rows * w, init=[])
        write, read = results.write_port(), results.read_port()
        # Passes 0 .. lag - 1 have no output row: a median output then is the last of an abandoned map, still in
        # the pipeline after ``start``, and is dropped (sim/formal/harnesses/depth.py).
        m.d.comb += [
            write.addr.eq(out_base + median.out_x),
            write.data.eq(median.out_code),
            write.en.eq(median.out_valid & self._has_row(y)),
            read.addr.eq(self.result.addr),
            self.result.data.eq(read.data),
        ]
        return codes_write, write

    def _left_right_back_end(self, m, horizontal, vertical, median, row_invalid):
        """Two paths with the left-right check: the winner's codes and d* and :class:`LeftWinner`'s d_L (from the
        winner's sums) into :class:`LeftRightFill`'s row stores; in the drain the fill's scan checks the row, and
        the next pass's start replays it into the median, whose pass is then y - 1 (docs/depth.md, "left-right
        check")."""
        cfg, w = self.config, self.geometry.buf_width
        winner = add_reset_subtree(m, "winner", Winner(cfg, w))
        m.d.comb += [winner.token.eq(horizontal.l_token), winner.horizontal.eq(horizontal.l),
                     winner.vertical.eq(vertical.l)]
        left = add_reset_subtree(m, "left_winner", LeftWinner(cfg, w))
        m.d.comb += [left.token.eq(winner.sums_token), left.sums.eq(winner.sums)]
        fill = add_reset_subtree(m, "left_right", LeftRightFill(cfg, w))
        fsm, drain, can_start = self._drain
        y = self.pass_row
        m.d.comb += [
            fill.code_valid.eq(winner.valid), fill.code_x.eq(winner.x), fill.code_d.eq(winner.d),
            fill.code.eq(Mux(row_invalid, cfg.invalid, winner.code)),
            fill.left_valid.eq(left.valid), fill.left_x.eq(left.x), fill.left_d.eq(left.d),
            fill.start.eq(fsm.ongoing("DRAIN") & (drain == self.fill_start) & ~self.start),
            # The pass's start (WAIT -> RUN: room for its output row) replays the previous pass's row, y - 1.
            fill.replay.eq(fsm.ongoing("WAIT") & can_start & ~self.start),
            fill.stop.eq(self.start),
            median.y.eq(Mux(y == 0, 0, y - 1)),
            median.valid.eq(fill.valid), median.x.eq(fill.x), median.code.eq(fill.out_code),
        ]

    def _reverse_back_end(self, m, median, row_invalid):
        """Three paths: the winner over ReversePath's L_rl and carried S2 (codes in descending x) into a row of
        codes, replayed into the median in ascending x (docs/depth.md, scheme a')."""
        cfg, w = self.config, self.geometry.buf_width
        reverse = self.reverse
        winner = add_reset_subtree(m, "winner", Winner(cfg, w, vertical_bits=reverse.carry_bits))
        m.d.comb += [winner.token.eq(reverse.out_token), winner.horizontal.eq(reverse.l),
                     winner.vertical.eq(reverse.carry_out)]
        m.submodules.row_codes = codes = Memory(shape=unsigned(cfg.code_bits), depth=w, init=[])
        write, read = codes.write_port(), codes.read_port()
        index = self.phase_count
        m.d.comb += [
            write.addr.eq(winner.x),
            write.data.eq(Mux(row_invalid, cfg.invalid, winner.code)),
            write.en.eq(winner.valid),
            read.addr.eq(Mux(index < w, index, 0)),
            median.valid.eq(self.replaying & self.replay_odd),
            median.x.eq(index),
            median.code.eq(read.data),
        ]
        return write
