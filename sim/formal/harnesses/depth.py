# amaranth: UnusedElaboratable=no
"""DepthEngine: every frame-buffer read and result-ring write in range, the row rings never overwrite a row a pass
still reads, a pass reads only complete rows and starts only when the result ring has room for its row.

The environment is free except for the reader's contract: ``start`` may come on any clock (a map in progress is
abandoned), the arbiters grant or refuse any request on any clock, the frame buffers return any data and the
row-tag sources any tag and busy bit, the reader reads any address. Only ``result.rows_released`` is constrained, by the contract of
:class:`~hdl.depth.ports.ResultReadSignature` (each assumption below says which part).

The engine is a tiny configuration of the same RTL (D = 2, 7 x 7 census) on a 3 x 9 buffer with a 3-row result
ring: not a power of two wide, deep or long, so no address bound holds by its width alone (27 words behind 5
address bits, a 9-word result ring behind 4), and taller than the 8-row input rings, so ring slots are reused.
A whole map there is about 980 clocks, too deep for a cover search in minutes: :class:`DepthMapHarness` completes
one on a smaller engine (2 x 3 buffer, 3 x 3 census, 2-row result ring: about 300 clocks) and proves the result
ring's properties and the invalid row's codes there (the codes' cone is the whole datapath, so they are not in
the larger harness's proof).

The three-path engine (``THREE_PATHS``: a backward pass and a replay after each forward pass) has the same two
configurations: :class:`DepthThreeHarness` proves the input rows' properties through the backward pass on the
3 x 9 engine, :class:`DepthThreeMapHarness` the result ring's and the replay's on the 2 x 3 one.
"""

import dataclasses

from amaranth import Mux, Signal

from hdl.depth.engine import RING_ROWS, DepthEngine, median_block
from spec.depth import THREE_PATHS, DepthConfig
from spec.sensor import SensorGeometry
from sim.formal.runner import FormalHarness

#: 12 x 36 sensor pixels at scale 4: a 3 x 9 buffer.
GEOMETRY = SensorGeometry(width=12, height=36)
CONFIG = DepthConfig(disparities=2, lanes=2)
OUT_ROWS = 3


#: The cover of the default run on this configuration: pass 0 taking a ring column (its rows fetched and tagged),
#: about 100 clocks in, found by BMC. A whole map here is about 980 clocks: beyond PDR and BMC in minutes, so the
#: map is completed on a smaller configuration (:class:`DepthMapHarness`); the slow variant ``depth_all_covers``
#: searches each ring's slot reuse, a read at the last address and the result ring's wrap with PDR.
DEFAULT_COVERS = ("pass_takes_a_column",)
#: BMC's bound for the pass cover (clocks; the shortest trace is about 100).
PASS_COVER_BOUND = 200

class DepthEngineHarness(FormalHarness):
    """The engine with the property families named in ``parts``: "reads" (the input rows' reads and ring writes),
    "tags" (row tags and frame pairs), "results" (the result ring's writes and the pass admission) and "codes" (an
    invalid row's codes: its cone is the whole datapath, so :class:`DepthMapHarness` proves it on a smaller
    engine)."""
    name = "depth"
    block = "DepthEngine"
    all_covers = False
    default_covers = DEFAULT_COVERS
    parts = ("reads", "tags", "results")
    map_cover_bound = None          # map_completes by PDR (the slow variant)

    def __init__(self, geometry=GEOMETRY, config=CONFIG, out_rows=OUT_ROWS):
        super().__init__()
        self.geometry, self.config, self.out_rows = geometry, config, out_rows

    def dut(self):
        return DepthEngine(self.geometry, self.config, out_rows=self.out_rows)

    def cover(self, m, name, test, *, bound=None):
        if self.all_covers or name in self.default_covers:
            super().cover(m, name, test, bound=bound)

    def prove(self, m, name, test, *, bound=None, group=None):
        if self._part in self.parts:
            return super().prove(m, name, test, bound=bound, group=group or self._part)

    def build(self, m):
        g, cfg = self.geometry, self.config
        h = g.buf_height
        self._start = start = self.free("start")
        rows_released = self.free("rows_released", range(h + 1))
        dut = self.dut()
        module = self.open(m, "dut", dut)
        # The block's ports and its submodules' (the one place to adapt when the signature changes): the pass
        # counter is the engine's ``pass_row``, the rings' writes and the result ring's write are their memories'
        # ports.
        m.d.comb += [dut.start.eq(start), dut.result.rows_released.eq(rows_released), dut.left_row_offset.eq(0),
                     dut.result.addr.eq(self.free("result_addr", len(dut.result.addr)))]
        reads = {}
        for side in ("left", "right"):
            port = getattr(dut, side)
            tags = getattr(dut, f"{side}_tags")
            m.d.comb += [port.grant.eq(self.free(f"{side}_grant")),
                         port.port.data.eq(self.free(f"{side}_data", g.grey_bits)),
                         tags.tag.eq(self.free(f"{side}_tag", len(tags.tag))),
                         tags.busy.eq(self.free(f"{side}_tag_busy"))]
            ring = module.submodules[f"{side}_ring"]
            reads[side] = (port, ring, ring.write_en,
                           module.submodules[f"{side}_census"].shift)
        y = dut.pass_row
        median = module.submodules.median
        result_write = module.submodules.results.write_ports[0]
        rows_ready, busy = dut.result.rows_ready, dut.busy

        self._reader_contract(m, start, rows_released, rows_ready)
        self._part = "reads"
        for side, (port, ring, ring_write, census_shift) in reads.items():
            self._input_rows(m, side, port, ring, ring_write, census_shift, y, busy)
        self._part = "tags"
        for side, (port, ring, ring_write, census_shift) in reads.items():
            self._row_tags(m, side, ring, census_shift, y, dut)
        self._pairs(m, reads["left"][1], reads["right"][1], reads["left"][3], y, dut)
        self.cover(m, "pass_takes_a_column", reads["left"][3] & (y == 0), bound=PASS_COVER_BOUND)
        self._part = "codes"
        self.prove(m, "invalid_row_gives_only_invalid_codes",
                   ~(median.valid & (median.x < g.buf_width) & dut.row_invalid) | (median.code == cfg.invalid))
        self._part = "results"
        self._results(m, y, median, result_write, reads["left"][3], rows_released, rows_ready)

    def _row_tags(self, m, side, ring, census_shift, y, dut):
        h, ry = self.geometry.buf_height, self.config.census_height // 2
        self.prove(m, f"{side}_tag_row_in_image", ring.tags.row < h)
        self.prove(m, f"{side}_tagged_rows_are_fetched", (ring.tagged <= ring.fetched) &
                   (ring.fetched <= ring.tagged + 1))
        self.prove(m, f"{side}_pass_reads_rows_with_their_tags",
                   ~census_shift | (ring.tagged >= Mux(y + ry + 1 < h, y + ry + 1, h)))
        # A torn row in the pass's census window makes the row invalid.
        torn_in_window = 0
        for slot in self._window_slots(y):
            torn_in_window = torn_in_window | ring.torn.bit_select(slot, 1)
        self.prove(m, f"{side}_torn_window_row_makes_the_row_invalid",
                   ~census_shift | ~torn_in_window | dut.row_invalid, group="window")

    def _window_slots(self, y):
        """The ring slots of the pass's census window: rows clamp(y - 3 .. y + 3), slot = row mod 8."""
        h, ry = self.geometry.buf_height, self.config.census_height // 2
        for j in range(-ry, ry + 1):
            row = Mux(y + j < 0, 0, Mux(y + j > h - 1, h - 1, y + j))
            yield row[:(RING_ROWS - 1).bit_length()]

    def _pairs(self, m, left_ring, right_ring, census_shift, y, dut):
        """A row of the pass's census window whose left and right slot tags differ (two camera frame pairs) makes
        the row invalid."""
        mismatch = 0
        for slot in self._window_slots(y):
            mismatch = mismatch | (left_ring.slot_tags[slot] != right_ring.slot_tags[slot])
        self.prove(m, "pair_mismatch_in_window_makes_the_row_invalid", ~census_shift | ~mismatch | dut.row_invalid,
                   group="window")

    def _reader_contract(self, m, start, rows_released, rows_ready):
        pv = self.past_valid(m)
        # ResultReadSignature: rows_released counts rows of this map the reader no longer needs, so it never
        # exceeds rows_ready; the reader restarts with the engine, so in the clock of ``start`` it may still
        # hold the last map's count (and drop to 0 after it); otherwise it only grows.
        self.assume(m, "reader_releases_only_ready_rows", start | (rows_released <= rows_ready))
        self.assume(m, "reader_never_takes_a_release_back",
                    ~pv | start | self.past(m, start, name="past_start") |
                    (rows_released >= self.past(m, rows_released, name="past_rows_released")))

    def _input_rows(self, m, side, port, ring, ring_write, census_shift, y, busy):
        g, cfg = self.geometry, self.config
        w, h, ry = g.buf_width, g.buf_height, cfg.census_height // 2
        fetched = ring.fetched
        # Helper invariant: the counted address is the row and column the ring is fetching (PDR alone does not
        # find this product in minutes); past the last row the ring re-reads row h - 1 (the harness holds the
        # left rows' rectification offset at 0: the source row is the ring row).
        source_row = Mux(ring.fetch_row < h, ring.fetch_row, h - 1)
        self.prove(m, f"{side}_read_address_is_row_and_column",
                   (port.port.addr == source_row * w + ring.fetch_col) & (ring.fetch_col < w))
        self.prove(m, f"{side}_requests_only_rows_of_the_image", ~port.request | (ring.fetch_row < h))
        self.prove(m, f"{side}_read_address_in_buffer", ~port.request | (port.port.addr < g.buf_depth))
        # The request comes from registers fed by ``busy`` through the fetch limit: two clocks.
        busy_before = self.past_valid(m, 2) & self.past(m, busy, 2, name=f"{side}_busy_before")
        self.prove(m, f"{side}_reads_only_for_a_map", ~port.request | busy_before)
        writing = ring_write != 0
        slot = fetched[:(RING_ROWS - 1).bit_length()]
        # Row ``fetched`` is the one in flight: its words go to slot fetched mod 8, which held row fetched - 8;
        # pass y reads rows y - 3 .. y + 3 (clamped), so that row must be below y - 3.
        self.prove(m, f"{side}_ring_writes_the_slot_of_the_row_in_flight",
                   ~writing | (ring_write == (1 << slot)))
        self.prove(m, f"{side}_ring_write_spares_rows_in_use", ~writing | (fetched < y + RING_ROWS - ry))
        self.prove(m, f"{side}_pass_reads_complete_rows",
                   ~census_shift | (fetched >= Mux(y + ry + 1 < h, y + ry + 1, h)))
        self.cover(m, f"{side}_ring_slot_reused", writing & (fetched >= RING_ROWS))
        self.cover(m, f"{side}_read_at_last_address",
                   port.request & port.grant & (port.port.addr == g.buf_depth - 1))

    def _results(self, m, y, median, write, census_shift, rows_released, rows_ready):
        g, cfg, n = self.geometry, self.config, self.out_rows
        w, h = g.buf_width, g.buf_height
        lag = median_block(cfg).ROW_LAG
        row = y - lag                                   # the median's output row in pass y
        self.prove(m, "rows_ready_counts_finished_passes", rows_ready == Mux(y < lag, 0, row))
        self.prove(m, "result_written_only_in_output_passes",
                   ~write.en | ((y >= lag) & (y <= h + lag - 1)))
        self.prove(m, "result_write_in_ring", ~write.en | (write.addr < n * w))
        self.prove(m, "result_write_at_row_and_column",
                   ~write.en | (write.addr == (row % n) * w + median.out_x) & (median.out_x < w))
        # A pass starts only when the result ring has room for its output row (the reader has released the row
        # n rows before it); its census reads mark the pass running.
        self.prove(m, "pass_runs_only_with_room_for_its_row",
                   ~census_shift | self._start | (y < lag) | (row < rows_released + n))
        self.cover(m, "result_ring_wraps", write.en & (row == n) & (median.out_x == w - 1))
        self.cover(m, "map_completes", rows_ready == h, bound=self.map_cover_bound)


#: The map harness's engine: D = 2 and a 3 x 3 census on a 2 x 3 buffer, a 2-row result ring. A whole map
#: (4 passes) is about 300 clocks, within BMC's reach in a minute. H + 1 = 4 is a power of two: the pass counter
#: counts to H + 1 once the map is done, and ``rows_ready_counts_finished_passes`` fails there if it wraps (PDR
#: finds that 303-clock counterexample in seconds).
MAP_GEOMETRY = SensorGeometry(width=8, height=12)
MAP_CONFIG = DepthConfig(disparities=2, lanes=2, census_width=3, census_height=3)
MAP_OUT_ROWS = 2
#: BMC's bound for ``map_completes`` on the map harness (clocks; the shortest trace is about 300).
MAP_COVER_BOUND = 340


class DepthMapHarness(DepthEngineHarness):
    """A smaller engine that completes a whole map (``map_completes``, by BMC) with the result ring's properties
    and the invalid row's codes: 3 rows through a 2-row result ring (so it wraps, and a pass waits for the reader's
    release), the census window clamped at both edges of every row and column, D = 2 = the width."""
    name = "depth_map"
    parts = ("results", "codes")
    default_covers = ("map_completes",)
    map_cover_bound = MAP_COVER_BOUND

    def __init__(self, geometry=MAP_GEOMETRY, config=MAP_CONFIG, out_rows=MAP_OUT_ROWS):
        super().__init__(geometry, config, out_rows)


#: The map harness's engine with the separable 5 x 5 median (``median=5``: pass y writes row y - 2) on a 2 x 2
#: buffer: H + 2 = 4 passes (a power of two, as the 3 x 3 map harness's H + 1: the pass counter must not wrap once
#: the map is done), both finishing passes clamping at the top and the bottom.
MEDIAN5_MAP_GEOMETRY = SensorGeometry(width=8, height=8)
MEDIAN5_MAP_CONFIG = dataclasses.replace(MAP_CONFIG, median=5)


class DepthMedian5MapHarness(DepthMapHarness):
    """:class:`DepthMapHarness` on the engine with the separable 5 x 5 median: the result ring's properties with
    the median's row lag of 2 (two passes without an output row, two finishing passes) and the invalid row's
    codes."""
    name = "depth_median5_map"

    def __init__(self, geometry=MEDIAN5_MAP_GEOMETRY, config=MEDIAN5_MAP_CONFIG, out_rows=MAP_OUT_ROWS):
        super().__init__(geometry, config, out_rows)


#: The map harness's engine with the separable 7 x 7 median over the valid codes (``median=7, median_valid=True``:
#: pass y writes row y - 3) on the 2 x 2 buffer: three passes without an output row, three finishing passes, the
#: window clamped at the top and the bottom in every one.
MEDIAN7_MAP_CONFIG = dataclasses.replace(MAP_CONFIG, median=7, median_valid=True)
#: BMC's bound for its ``map_completes`` (clocks): 5 passes of 71 + 3 clocks, about 400 with the start.
MEDIAN7_MAP_COVER_BOUND = 440


class DepthMedian7MapHarness(DepthMapHarness):
    """:class:`DepthMapHarness` on the engine with the separable 7 x 7 median over the valid codes: the result
    ring's properties with the median's row lag of 3 and the invalid row's codes."""
    name = "depth_median7_map"
    map_cover_bound = MEDIAN7_MAP_COVER_BOUND

    def __init__(self, geometry=MEDIAN5_MAP_GEOMETRY, config=MEDIAN7_MAP_CONFIG, out_rows=MAP_OUT_ROWS):
        super().__init__(geometry, config, out_rows)


#: The three-path engines (docs/depth.md, "The third path in the RTL"): those of :class:`DepthEngineHarness` and
#: :class:`DepthMapHarness` with ``THREE_PATHS``. A pass adds the backward steps, the backward drain and the replay
#: (139 clocks against 89 on the 3 x 9 engine, 87 against 64 on the 2 x 3 one).
THREE_CONFIG = dataclasses.replace(CONFIG, paths=THREE_PATHS, max_cost=CONFIG.max_cost * 3 // 2)
THREE_MAP_CONFIG = dataclasses.replace(MAP_CONFIG, paths=THREE_PATHS, max_cost=MAP_CONFIG.max_cost * 3 // 2)
#: BMC's bound for the backward pass's cover on the 3 x 9 engine (clocks; the shortest trace is about 110).
BACKWARD_COVER_BOUND = 150
#: BMC's bound for the replay cover on the 2 x 3 engine (clocks; the shortest trace is about 100).
REPLAY_COVER_BOUND = 140


class DepthThreeHarness(DepthEngineHarness):
    """The three-path engine's input rows: their properties hold through the backward pass too (its census reads
    are ``census_shift`` like the forward pass's), so the rings keep a pass's census rows until its backward pass
    is done; the engine's own invariants add the pass order (forward, backward, backward drain, replay, drain)
    and the phase counters (``DepthEngine._reverse_invariants``); the engine keeps ReversePath's contract on its
    tokens' columns. On the 3 x 9 engine with the 7 x 7 census, where the 8-slot rings are reused."""
    name = "depth_three"
    parts = ("reads",)
    default_covers = ("backward_pass_takes_a_column",)

    def __init__(self, geometry=GEOMETRY, config=THREE_CONFIG, out_rows=OUT_ROWS):
        super().__init__(geometry, config, out_rows)

    def open(self, m, name, dut):
        self._engine = dut          # the engine (a mutant's too): its ``backward`` and ``reverse``
        return super().open(m, name, dut)

    def _input_rows(self, m, side, port, ring, ring_write, census_shift, y, busy):
        super()._input_rows(m, side, port, ring, ring_write, census_shift, y, busy)
        if side == "left":
            self.cover(m, "backward_pass_takes_a_column", census_shift & self._engine.backward & (y == 0),
                       bound=BACKWARD_COVER_BOUND)
            # ReversePath's contract on its tokens' columns (sim/formal/harnesses/reverse_path.py assumes it): the
            # engine keeps it, so the row store's addresses are inside it in the engine too.
            reverse, w = self._engine.reverse, self.geometry.buf_width
            for name, token in (("reverse_token", reverse.token), ("reverse_store_token", reverse.store_token)):
                self.prove(m, f"{name}_in_row", ~token.go | (token.x < w))


class DepthThreeMapHarness(DepthMapHarness):
    """The three-path engine's result ring, on the 2 x 3 engine: the result ring's properties with the replay's
    writes, the ring written only where the reader has released the row, and the replay sending the codes of the
    backward pass just run (proof ``replay``); the cover: a replayed code reaches the median (the backward pass and
    its drain done)."""
    name = "depth_three_map"
    parts = ("results",)
    default_covers = ("replay_reaches_the_median", "replay_sends_a_watched_column_not_0")

    def __init__(self, geometry=MAP_GEOMETRY, config=THREE_MAP_CONFIG, out_rows=MAP_OUT_ROWS):
        super().__init__(geometry, config, out_rows)

    def _results(self, m, y, median, write, census_shift, rows_released, rows_ready):
        super()._results(m, y, median, write, census_shift, rows_released, rows_ready)
        n = self.out_rows
        # ResultReadSignature: row r is written only once the reader's rows_released > r - n (a start abandons
        # the map: the reader's count may still be the last map's in its clock).
        lag = median_block(self.config).ROW_LAG
        self.prove(m, "result_written_only_where_released", ~write.en | self._start | (y - lag < rows_released + n))
        self.cover(m, "replay_reaches_the_median", median.valid & (y == 0), bound=REPLAY_COVER_BOUND)
        self._replay(m, median)

    def open(self, m, name, dut):
        self._engine = dut          # the engine (a mutant's too): its ``backward``
        self._module = super().open(m, name, dut)
        return self._module

    def _replay(self, m, median):
        """The replay sends each column's code of the backward pass just run: one fixed, arbitrary column, marked
        when the backward pass writes its code (writes while ``backward`` is low, the forward pass's and those of an
        abandoned pass still in the pipeline, do not count; the mark is cleared in the forward pass)."""
        w = self.geometry.buf_width
        column = self.free("watched_column", range(w))
        self.hold(m, "watched_column_fixed", column)
        codes = self._module.submodules.row_codes.write_ports[0]
        backward = self._engine.backward
        written = Signal(name="watched_code_written")
        with m.If(~backward):
            m.d.sync += written.eq(0)
        with m.Elif(codes.en & (codes.addr == column)):
            m.d.sync += written.eq(1)
        # The median takes the code read a clock before: the write must be in before that read.
        self.prove(m, "replay_sends_codes_of_the_backward_pass",
                   ~(median.valid & (median.x == column)) | self.past(m, written, name="watched_code_was_written"),
                   group="replay")
        self.cover(m, "replay_sends_a_watched_column_not_0", median.valid & (median.x == column) & (column != 0),
                   bound=REPLAY_COVER_BOUND)
