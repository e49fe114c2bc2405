"""RowRing: fetches a frame buffer's rows, in order, into a ring of line buffers (docs/depth.md, "Input rows")."""

from amaranth import C, Cat, Module, Mux, Signal, unsigned
from amaranth.hdl import Assert
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from spec.sensor import ROW_TAG_BITS, SENSOR
from hdl.depth.ports import RowTagReadSignature, SharedReadSignature
from hdl.shift_add import times

__all__ = ["RowRing"]


class RowRing(wiring.Component):
    """Row fetcher and ring of ``rows`` line buffers for one frame buffer.

    Rows 0, 1, 2, ... are read through ``buffer`` (a shared read port: one read in each clock with
    ``request`` and ``grant`` high, data one clock later), every pixel once, and row r is written into ring
    slot ``r mod rows``. Ring row r holds buffer row min(max(r + ``row_offset``, 0), height - 1) (the signed
    rectification moving the left image up or down: above the image the first row is read again, below it the
    last one; ``row_offset`` is sampled at ``start``). One memory word per column holds that column's pixel of
    every slot, so one read gives a whole column of the ring. A fetched pixel is merged into its column's word
    (read, replace one slot, write back) from an identical copy of the ring, so both copies are plain simple
    dual-port memories -- one whole-word write port, one synchronous read port, one clock, no lane write
    enables (docs/board.md): the census reads one, the merge reads the other.

    Row tags (docs/depth.md, "Rows from different camera frames"): once a row may be fetched (``limit``) the ring
    asks ``tags`` for its buffer row (the *start sample*; no read of the row is requested before it is in), and again
    ``tag_margin`` clocks after the row's last granted read (the *end sample*: ``tags.row`` is the row in the clock
    ``tag_margin`` clocks after that read, the answer is taken one clock later). The row is *torn* iff either
    sample is busy or their tags differ; its *edge* bit is set iff it is torn, the ring row before it is torn, or
    the two rows' tags differ (ring row 0: iff it is torn). Both bits and the end sample's tag go into the row's
    slot; ``tagged`` counts the rows whose data, bits and tag are in. While an end sample is pending the ring does
    not make the next row's last read (it never binds for width >= ``tag_margin``).

    Parameters
    ----------
    geometry : SensorGeometry
        Buffer size and grey width.
    rows : int
        Ring slots, a power of two.
    tag_margin : int
        Clocks from a row's last read to its end sample's request (at least 2): the row-tag source's lag.

    Ports
    -----
    start : In(1)
        Restart at row 0 (a fetch in flight is dropped).
    row_offset : In(range(-(height - 1), height))
        Signed: buffer rows to skip (positive) or ring rows that repeat buffer row 0 before row 1 (negative),
        held from two clocks before ``start``.
    limit : In(range(height + 1))
        Rows below ``limit`` may be fetched; the reader raises it as slots become free.
    fetched : Out(range(height + 1))
        Rows whose pixels are all in the ring.
    tagged : Out(range(height + 1))
        Rows whose pixels and tag bits are in (``tagged`` <= ``fetched`` <= ``tagged`` + 1).
    torn, edge : Out(rows)
        One bit per slot (slot ``r mod rows`` for ring row r): torn, and inconsistent with the row before.
    slot_tags : Out(ArrayLayout(tag bits, rows))
        The end sample's tag of each slot's row (compared with the other image's by the engine).
    tags : Out(RowTagReadSignature(height))
        The buffer's row tags: ``row`` from a register; ``tag``, ``busy`` of that row one clock later.
    col : In(range(width))
        Ring read address; ``column`` holds that column of every slot one clock later.

    Other attributes (state, not ports: what the formal harness's invariant reads, sim/formal/harnesses/depth.py)
    fetch_row, fetch_col : Signal
        The ring row and column the next read requests (``buffer.port.addr`` = min(max(fetch_row +
        row_offset, 0), height - 1) * width + fetch_col, counted).
    write_en : Signal(rows)
        One bit per slot: the slot whose memory is written this clock (at most one bit is set).

    Elaborated for the platform ``"formal"``, the ring asserts its fetch and tag-sample invariants (docs/formal.md).

    The ring and its copy are the submodules ``ring`` and ``ring_shadow``: one word per column, ``grey_bits`` per
    slot (slot ``k`` in bits ``k * grey_bits`` up).

    Clock domain: ``sync`` (the parent renames it to ``pix``).

    Latency: a row's first read at the earliest 3 clocks after ``limit`` allows it (0 without tags) and 5 clocks
    after the previous row's last read (2 without tags);
    ``tagged`` counts it ``tag_margin`` + 3 clocks after its last read (``fetched``: 2).

    Raises
    ------
    ValueError
        If ``rows`` is not a power of two of at least 2, or ``tag_margin`` is less than 2.
    """

    def __init__(self, geometry=SENSOR, rows=8, *, tag_margin=8):
        if rows < 2 or rows & (rows - 1):
            raise ValueError(f"ring rows must be a power of two >= 2, not {rows}")
        if tag_margin < 2:
            raise ValueError(f"tag_margin must be at least 2 clocks, not {tag_margin}")
        self.geometry = geometry
        self.rows = rows
        self.tag_margin = tag_margin
        super().__init__({
            "buffer": Out(SharedReadSignature(geometry)),
            "start": In(1),
            "row_offset": In(range(-(geometry.buf_height - 1), geometry.buf_height)),
            "limit": In(range(geometry.buf_height + 1)),
            "fetched": Out(range(geometry.buf_height + 1)),
            "col": In(range(geometry.buf_width)),
            "column": Out(data.ArrayLayout(geometry.grey_bits, rows)),
            "tagged": Out(range(geometry.buf_height + 1)),
            "torn": Out(rows),
            "edge": Out(rows),
            "slot_tags": Out(data.ArrayLayout(ROW_TAG_BITS, rows)),
            "tags": Out(RowTagReadSignature(geometry.buf_height)),
        })
        self.fetch_row = Signal(range(geometry.buf_height + 1))
        self.fetch_col = Signal(range(geometry.buf_width))
        self.write_en = Signal(rows)

    def _memories(self, m):
        """The ring and its copy (submodules ``ring``, ``ring_shadow``): ``(write ports, read port, copy's read
        port)``."""
        word = unsigned(self.geometry.grey_bits * self.rows)
        m.submodules.ring = memory = Memory(shape=word, depth=self.geometry.buf_width, init=[])
        m.submodules.ring_shadow = shadow = Memory(shape=word, depth=self.geometry.buf_width, init=[])
        writes = [memory.write_port(), shadow.write_port()]
        return writes, memory.read_port(), shadow.read_port()

    def elaborate(self, platform):
        m = Module()
        g, rows = self.geometry, self.rows
        gb = g.grey_bits
        writes, read, merge_read = self._memories(m)
        m.d.comb += read.addr.eq(self.col)
        for k in range(rows):
            m.d.comb += self.column[k].eq(read.data[k * gb:(k + 1) * gb])

        issued = self.fetch_row                      # row being requested
        slot = Signal(range(rows))                   # issued mod rows
        col = self.fetch_col
        addr = Signal(g.addr_bits)                   # source row * width + col, counted
        source = Signal(range(g.buf_height))         # the buffer row being fetched: clamp(issued + offset, 0, h - 1)
        row_start = Signal(g.addr_bits)              # source * width
        above = Signal(range(g.buf_height))          # rows still to fetch again at the top: -(issued + offset)
        first_source = Signal(range(g.buf_height))   # max(row_offset, 0), registered (a quasi-static input)
        first_above = Signal(range(g.buf_height))    # max(-row_offset, 0), registered
        offset_addr = Signal(g.addr_bits)            # first_source * width, registered
        below = Mux(self.row_offset > 0, self.row_offset, 0)
        m.d.sync += [first_source.eq(below), first_above.eq(Mux(self.row_offset < 0, -self.row_offset, 0)),
                     offset_addr.eq(times(below, g.buf_width))]
        pending = Signal()                           # a granted read's data arrives this clock
        pending_col = Signal.like(col)
        pending_slot = Signal.like(slot)
        pending_last = Signal()

        # The request comes from registers: ``allowed`` lags ``issued`` by a clock, so the clock after a row's
        # last column is granted never requests (the next row may not be allowed yet). ``sampled``: the row's start
        # sample is in; ``ending & col_last``: the previous row's end sample is pending and this is the last read.
        # ``col_last`` (col == width - 1, set with the grant that moves ``col`` there) is all the grant meets of the
        # column: no comparison of ``col`` lies after the grant. ``ready`` = allowed & ~row_done & sampled &
        # ~(ending & col_last), set a clock ahead from those registers' next values (:meth:`_ready`), so the
        # request is one register and ``start``.
        allowed, row_done, sampled, ending, col_last = Signal(), Signal(), Signal(), Signal(), Signal()
        ready, allowed_next = Signal(), Signal()
        m.d.comb += allowed_next.eq((issued < self.limit) & (issued < g.buf_height))
        m.d.sync += allowed.eq(allowed_next)
        m.d.comb += [
            self.buffer.port.addr.eq(addr),
            self.buffer.request.eq(ready & ~self.start),
        ]
        granted = self.buffer.request & self.buffer.grant
        last_read = granted & col_last
        m.d.sync += [pending.eq(granted), row_done.eq(last_read)]
        with m.If(granted):
            m.d.sync += col_last.eq(col == g.buf_width - 2)
        samples, shown = self._tag_samples(m, source, slot, allowed, row_done, sampled, ending, last_read)
        self._ready(m, ready, (allowed_next, sampled, ending, col_last), (granted, last_read, shown, samples[2]), col)
        with m.If(granted):
            m.d.sync += [
                pending_col.eq(col),
                pending_slot.eq(slot),
                pending_last.eq(col_last),
                addr.eq(addr + 1),
            ]
            with m.If(col_last):
                m.d.sync += [col.eq(0), issued.eq(issued + 1), slot.eq(slot + 1)]
                with m.If(above != 0):                          # above the image: the first row again
                    m.d.sync += [addr.eq(row_start), above.eq(above - 1)]
                with m.Elif(source == g.buf_height - 1):        # below the image: the last row again
                    m.d.sync += addr.eq(row_start)
                with m.Else():
                    m.d.sync += [source.eq(source + 1), row_start.eq(addr + 1)]
            with m.Else():
                m.d.sync += col.eq(col + 1)

        self._merge(m, writes, merge_read, col, (pending, pending_col, pending_slot))
        with m.If(pending & pending_last):
            m.d.sync += self.fetched.eq(self.fetched + 1)

        with m.If(self.start):
            m.d.sync += [issued.eq(0), slot.eq(0), col.eq(0), addr.eq(offset_addr), row_start.eq(offset_addr),
                         source.eq(first_source), above.eq(first_above), pending.eq(0), self.fetched.eq(0),
                         allowed.eq(0), col_last.eq(0), ready.eq(0)]
        if platform == "formal":
            self._invariants(m, (slot, addr, source, row_start), (pending, pending_slot, pending_last),
                             (allowed, row_done, sampled, ending, col_last, ready), samples)
        return m

    def _merge(self, m, writes, merge_read, col, arriving):
        """The merge: the copy is read at the granted column (``col``, before it advances), so its word is there
        when the pixel arrives (``arriving``: pending, its column and slot); the pixel replaces its slot's value
        in the word written to both memories. Consecutive writes go to different columns (width >= 2)."""
        rows, gb = self.rows, self.geometry.grey_bits
        pending, pending_col, pending_slot = arriving
        m.d.comb += [merge_read.addr.eq(col), self.write_en.eq(Mux(pending, C(1, rows) << pending_slot, 0))]
        old = merge_read.data
        merged = Cat(*(Mux(self.write_en[k], self.buffer.port.data, old[k * gb:(k + 1) * gb]) for k in range(rows)))
        for write in writes:
            m.d.comb += [write.addr.eq(pending_col), write.data.eq(merged), write.en.eq(pending)]

    def _ready(self, m, ready, state, events, col):
        """``ready`` in the next clock: allowed & ~row_done & sampled & ~(ending & col_last) of the next values
        (``start`` clears it in :meth:`elaborate`). A last read clears ``sampled`` and sets ``row_done``; otherwise
        ``sampled`` is set by ``shown``, ``ending`` cleared by ``write``, ``col_last`` moved by a grant and
        ``allowed`` is ``allowed_next`` (:meth:`_tag_samples`, :meth:`elaborate`)."""
        allowed_next, sampled, ending, col_last = state
        granted, last_read, shown, write = events
        col_last_next = Mux(granted, col == self.geometry.buf_width - 2, col_last)
        m.d.sync += ready.eq(~last_read & allowed_next & (sampled | shown) & ~(ending & ~write & col_last_next))

    def _invariants(self, m, fetch, in_flight, gates, samples):
        """The fetch's and the tag samples' invariants (elaborated for the formal platform only), each an
        ``Assert`` named by its message: a row is counted in ``fetched`` the clock after its last pixel is written,
        in ``tagged`` when its end sample's bits go in."""
        g, bits = self.geometry, (self.rows - 1).bit_length()
        slot, addr, source, row_start = fetch
        pending, pending_slot, pending_last = in_flight
        allowed, row_done, sampled, ending, col_last, ready = gates
        count, take, write, end_row, end_slot = samples
        last_in_flight = pending & pending_last
        invariants = {
            "row_in_flight_is_fetched": self.fetch_row == self.fetched + last_in_flight,
            "fetched_row_is_tagged": self.fetched + last_in_flight == self.tagged + ending,
            "fetched_in_image": self.fetch_row <= g.buf_height,
            "allowed_row_in_image": ~allowed | row_done | (self.fetch_row < g.buf_height),
            "slot_of_fetch_row": slot == self.fetch_row[:bits],
            "slot_of_pending_pixel": ~pending | (pending_slot == self.fetched[:bits]),
            "column_in_row": self.fetch_col < g.buf_width,
            "last_column_flag": col_last == (self.fetch_col == g.buf_width - 1),
            "request_ready": ready == (allowed & ~row_done & sampled & ~(ending & col_last)),
            "address_counts_columns": (addr == row_start + self.fetch_col) & (row_start == source * g.buf_width)
                                      & (source < g.buf_height),
            "end_sample_pending": ending == ((count != 0) | take | write),
            "end_sample_count": count <= self.tag_margin,
            # The pending end sample is row ``tagged``'s: its bits go into that row's slot.
            "end_sample_of_next_tagged_row": ~ending | ((end_slot == self.tagged[:bits]) & (end_row < g.buf_height)),
            "tag_row_in_image": self.tags.row < g.buf_height,
        }
        for name, test in invariants.items():
            m.d.sync += Assert(test, name)

    def _tag_samples(self, m, source, slot, allowed, row_done, sampled, ending, last_read):
        """The start and end samples of each row's tag through the one ``tags`` port, and the slot bits."""
        g, margin = self.geometry, self.tag_margin
        bits = len(self.tags.tag)
        port = self.tags
        # The port asks for the row to be fetched once it may be fetched (``want``: allowed, start sample not in;
        # ``allowed`` is a clock late after a row's last read, hence ``row_done``), and for a pending end sample's
        # row in the clock of its request; otherwise it keeps the row it asked for last.
        count = Signal(range(margin + 1))           # clocks to the end request (1: this clock); 0: none pending
        end_row, end_slot = Signal.like(source), Signal.like(slot)
        end_ask = count == 2
        want = Signal()
        m.d.comb += want.eq(allowed & ~sampled & ~row_done)
        with m.If(end_ask):
            m.d.sync += port.row.eq(end_row)
        with m.Elif(want):
            m.d.sync += port.row.eq(source)
        # ``shown``: this clock's answer is for ``source`` (asked in the clock before, unchanged since).
        asked, shown = Signal(), Signal()
        m.d.sync += [asked.eq(want & ~end_ask & ~last_read & ~self.start),
                     shown.eq(asked & ~last_read & ~self.start)]
        start_tag, start_busy = Signal(bits), Signal()
        with m.If(shown & ~sampled):
            m.d.sync += [start_tag.eq(port.tag), start_busy.eq(port.busy), sampled.eq(1)]
        held_tag, held_busy = Signal(bits), Signal()  # the start sample of the row whose end sample is pending
        with m.If(last_read):
            m.d.sync += [count.eq(margin), end_row.eq(source), end_slot.eq(slot), ending.eq(1), sampled.eq(0),
                         held_tag.eq(start_tag), held_busy.eq(start_busy)]
        with m.Elif(count != 0):
            m.d.sync += count.eq(count - 1)
        take, write = Signal(), Signal()            # this clock's answer is the end sample; the slot bits go in
        end_tag, end_busy = Signal(bits), Signal()
        m.d.sync += [take.eq(count == 1), write.eq(take)]
        with m.If(take):
            m.d.sync += [end_tag.eq(port.tag), end_busy.eq(port.busy)]
        prev_tag, prev_torn, first = Signal(bits), Signal(), Signal(init=1)
        torn = end_busy | held_busy | (end_tag != held_tag)
        edge = torn | prev_torn | (~first & (end_tag != prev_tag))
        with m.If(write):
            for k in range(self.rows):
                with m.If(end_slot == k):
                    m.d.sync += [self.torn[k].eq(torn), self.edge[k].eq(edge), self.slot_tags[k].eq(end_tag)]
            m.d.sync += [prev_tag.eq(end_tag), prev_torn.eq(torn), first.eq(0), ending.eq(0),
                         self.tagged.eq(self.tagged + 1)]
        with m.If(self.start):
            m.d.sync += [count.eq(0), sampled.eq(0), ending.eq(0), take.eq(0), write.eq(0), prev_torn.eq(0),
                         first.eq(1), self.tagged.eq(0)]
        return (count, take, write, end_row, end_slot), shown
