"""RowRing: fetches a frame buffer's rows, in order, into a ring of line buffers (docs/depth.md, "Input rows")."""

from amaranth import C, Cat, Module, Mux, Signal, unsigned
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from spec.sensor import SENSOR
from hdl.depth.ports import SharedReadSignature
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

    Parameters
    ----------
    geometry : SensorGeometry
        Buffer size and grey width.
    rows : int
        Ring slots, a power of two.

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
        Rows completely in the ring.
    col : In(range(width))
        Ring read address; ``column`` holds that column of every slot one clock later.

    Other attributes (state, not ports: what the formal harness's invariant reads, sim/formal/harnesses/depth.py)
    fetch_row, fetch_col : Signal
        The ring row and column the next read requests (``buffer.port.addr`` = min(max(fetch_row +
        row_offset, 0), height - 1) * width + fetch_col, counted).
    memory, shadow : amaranth.lib.memory.Memory
        The ring and its copy: one word per column, ``grey_bits`` per slot (slot ``k`` in bits
        ``k * grey_bits`` up).
    write_en : Signal(rows)
        One bit per slot: the slot whose memory is written this clock (at most one bit is set).

    Clock domain: ``sync`` (the parent renames it to ``pix``).

    Raises
    ------
    ValueError
        If ``rows`` is not a power of two of at least 2.
    """

    def __init__(self, geometry=SENSOR, rows=8):
        if rows < 2 or rows & (rows - 1):
            raise ValueError(f"ring rows must be a power of two >= 2, not {rows}")
        self.geometry = geometry
        self.rows = rows
        super().__init__({
            "buffer": Out(SharedReadSignature(geometry)),
            "start": In(1),
            "row_offset": In(range(-(geometry.buf_height - 1), geometry.buf_height)),
            "limit": In(range(geometry.buf_height + 1)),
            "fetched": Out(range(geometry.buf_height + 1)),
            "col": In(range(geometry.buf_width)),
            "column": Out(data.ArrayLayout(geometry.grey_bits, rows)),
        })
        self.fetch_row = Signal(range(geometry.buf_height + 1))
        self.fetch_col = Signal(range(geometry.buf_width))
        word = unsigned(geometry.grey_bits * rows)
        self.memory = Memory(shape=word, depth=geometry.buf_width, init=[])
        self.shadow = Memory(shape=word, depth=geometry.buf_width, init=[])
        self.write_en = Signal(rows)
        self._writes = [self.memory.write_port(), self.shadow.write_port()]
        self._read, self._merge_read = self.memory.read_port(), self.shadow.read_port()

    def elaborate(self, platform):
        m = Module()
        g, rows = self.geometry, self.rows
        gb = g.grey_bits
        m.submodules.ring = self.memory
        m.submodules.ring_shadow = self.shadow
        m.d.comb += self._read.addr.eq(self.col)
        for k in range(rows):
            m.d.comb += self.column[k].eq(self._read.data[k * gb:(k + 1) * gb])

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
        # last column is granted never requests (the next row may not be allowed yet).
        allowed, row_done = Signal(), Signal()
        m.d.sync += allowed.eq((issued < self.limit) & (issued < g.buf_height))
        m.d.comb += [
            self.buffer.port.addr.eq(addr),
            self.buffer.request.eq(allowed & ~row_done & ~self.start),
        ]
        granted = self.buffer.request & self.buffer.grant
        m.d.sync += [pending.eq(granted), row_done.eq(granted & (col == g.buf_width - 1))]
        with m.If(granted):
            m.d.sync += [
                pending_col.eq(col),
                pending_slot.eq(slot),
                pending_last.eq(col == g.buf_width - 1),
                addr.eq(addr + 1),
            ]
            with m.If(col == g.buf_width - 1):
                m.d.sync += [col.eq(0), issued.eq(issued + 1), slot.eq(slot + 1)]
                with m.If(above != 0):                          # above the image: the first row again
                    m.d.sync += [addr.eq(row_start), above.eq(above - 1)]
                with m.Elif(source == g.buf_height - 1):        # below the image: the last row again
                    m.d.sync += addr.eq(row_start)
                with m.Else():
                    m.d.sync += [source.eq(source + 1), row_start.eq(addr + 1)]
            with m.Else():
                m.d.sync += col.eq(col + 1)

        # The merge: the copy is read at the granted column (``col``, before it advances), so its word is
        # there when the pixel arrives; consecutive writes go to different columns (width >= 2).
        m.d.comb += [self._merge_read.addr.eq(col), self.write_en.eq(Mux(pending, C(1, rows) << pending_slot, 0))]
        old = self._merge_read.data
        merged = Cat(*(Mux(self.write_en[k], self.buffer.port.data, old[k * gb:(k + 1) * gb]) for k in range(rows)))
        for write in self._writes:
            m.d.comb += [write.addr.eq(pending_col), write.data.eq(merged), write.en.eq(pending)]
        with m.If(pending & pending_last):
            m.d.sync += self.fetched.eq(self.fetched + 1)

        with m.If(self.start):
            m.d.sync += [issued.eq(0), slot.eq(0), col.eq(0), addr.eq(offset_addr), row_start.eq(offset_addr),
                         source.eq(first_source), above.eq(first_above), pending.eq(0), self.fetched.eq(0),
                         allowed.eq(0)]
        return m
