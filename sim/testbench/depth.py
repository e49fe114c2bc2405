"""A test testbench around the depth engine: two frame buffers, an arbiter stand-in and a result reader.

:class:`DepthTestbench` is what the Amaranth-simulator and cocotb tests (and the benchmark) run: the two images are
written through ``load_*`` (one word of each per clock), ``start`` starts a map, and the testbench

* moves the left image up by ``row_offset`` rows for the engine (the rectification switch);
* grants the engine's read requests in the clocks a pseudo-random pattern leaves free (``grant_mask``: grant
  when ``lfsr & grant_mask == 0``, independently per buffer; 0 grants every request); in the other clocks the
  buffers read another address (a stand-in for the compositor), so data the engine did not ask for is wrong;
* copies every finished row from the engine's result ring into a full-size result memory, then releases it
  (not while ``hold`` is high: a reader that falls behind);
* counts the granted reads of each buffer (``reads_left``, ``reads_right``);
* raises ``done`` when all rows are copied and counts the clocks from ``start`` to ``done`` (``clocks``);
* answers the engine's row-tag ports from a table per buffer (``tag_load_*``: one row's tag, busy in bit
  ``ROW_TAG_BITS``; all 0 at reset), one clock after ``row``; the row ``flip_left`` / ``flip_right`` (``height``:
  none) has its tag's bit 0 flipped the first time the engine asks for it after ``start`` (after the answer), so
  that the row's start and end samples differ.

``read_addr`` / ``read_data`` read the result memory (y * width + x; data one clock later).
"""

from amaranth import Cat, Module, Mux, Signal, unsigned
from amaranth.lib import wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from hdl.depth import DepthEngine
from hdl.frame_buffer import FrameBuffer
from spec.depth import DEPTH
from spec.sensor import ROW_TAG_BITS, SENSOR

__all__ = ["DepthTestbench"]


class DepthTestbench(wiring.Component):
    def __init__(self, geometry=SENSOR, config=DEPTH, *, out_rows=4):
        self.geometry, self.config, self.out_rows = geometry, config, out_rows
        g = geometry
        super().__init__({
            "load_en": In(1),
            "load_addr": In(g.addr_bits),
            "load_left": In(g.grey_bits),
            "load_right": In(g.grey_bits),
            "grant_mask": In(8),
            "start": In(1),
            "row_offset": In(range(-(g.buf_height - 1), g.buf_height)),
            "hold": In(1),
            "done": Out(1),
            "clocks": Out(32),
            "rows_ready": Out(range(geometry.buf_height + 1)),
            "reads_left": Out(32),
            "reads_right": Out(32),
            "read_addr": In(g.addr_bits),
            "read_data": Out(config.code_bits),
            "tag_load_en": In(1),
            "tag_load_row": In(range(g.buf_height)),
            "tag_load_left": In(ROW_TAG_BITS + 1),
            "tag_load_right": In(ROW_TAG_BITS + 1),
            "flip_left": In(range(g.buf_height + 1), init=g.buf_height),
            "flip_right": In(range(g.buf_height + 1), init=g.buf_height),
        })

    def elaborate(self, platform):
        m = Module()
        g, cfg = self.geometry, self.config
        w, h = g.buf_width, g.buf_height
        m.submodules.engine = engine = DepthEngine(g, cfg, out_rows=self.out_rows)
        self.engine = engine
        lfsr = Signal(16, init=0xACE1)
        m.d.sync += lfsr.eq(Cat(lfsr[1:], lfsr[0] ^ lfsr[2] ^ lfsr[3] ^ lfsr[5]))
        other = Signal(g.addr_bits)                         # the other reader's address
        m.d.sync += other.eq(Mux(other == g.buf_depth - 1, 0, other + 1))
        for name, port, bits in (("left", engine.left, lfsr[:8]), ("right", engine.right, lfsr[8:])):
            buf = FrameBuffer(g)
            m.submodules[f"{name}_buffer"] = buf
            grant = (bits & self.grant_mask) == 0
            reads = getattr(self, f"reads_{name}")
            with m.If(self.start):
                m.d.sync += reads.eq(0)
            with m.Elif(port.request & grant):
                m.d.sync += reads.eq(reads + 1)
            m.d.comb += [
                buf.write.addr.eq(self.load_addr), buf.write.data.eq(getattr(self, f"load_{name}")),
                buf.write.en.eq(self.load_en),
                port.grant.eq(grant),
                buf.read.addr.eq(Mux(port.request & grant, port.port.addr, other)),
                port.port.data.eq(buf.read.data),
            ]

        self._tag_server(m, engine)
        m.submodules.maps = maps = Memory(shape=unsigned(cfg.code_bits), depth=g.buf_depth, init=[])
        store, fetch = maps.write_port(), maps.read_port()
        m.d.comb += [fetch.addr.eq(self.read_addr), self.read_data.eq(fetch.data)]
        row, x = Signal(range(h + 1)), Signal(range(w))
        ring_base = Signal(range(self.out_rows * w))
        map_addr = Signal(g.addr_bits)
        copying, copy_valid = Signal(), Signal()
        copy_addr = Signal.like(map_addr)
        m.d.comb += engine.result.addr.eq(ring_base + x)
        m.d.sync += [copy_valid.eq(copying), copy_addr.eq(map_addr)]
        m.d.comb += [store.addr.eq(copy_addr), store.data.eq(engine.result.data), store.en.eq(copy_valid)]
        m.d.comb += [engine.result.rows_released.eq(row), engine.start.eq(self.start), self.done.eq(row == h),
                     engine.left_row_offset.eq(self.row_offset)]
        m.d.comb += self.rows_ready.eq(engine.result.rows_ready)
        with m.If(~copying & ~self.hold & (row < engine.result.rows_ready)):
            m.d.sync += [copying.eq(1), x.eq(0)]
        with m.If(copying):
            m.d.sync += [x.eq(x + 1), map_addr.eq(map_addr + 1)]
            with m.If(x == w - 1):
                m.d.sync += [copying.eq(0), row.eq(row + 1),
                             ring_base.eq(Mux(ring_base == (self.out_rows - 1) * w, 0, ring_base + w))]
        with m.If(~self.done):
            m.d.sync += self.clocks.eq(self.clocks + 1)
        with m.If(self.start):
            m.d.sync += [row.eq(0), ring_base.eq(0), map_addr.eq(0), copying.eq(0), self.clocks.eq(0)]
        return m

    def _tag_server(self, m, engine):
        """One table of (busy, tag) per buffer, read at the engine's ``row``; the flip row changes after its first
        answer of the map."""
        h = self.geometry.buf_height
        start_seen = Signal()
        m.d.sync += start_seen.eq(self.start)
        for name in ("left", "right"):
            port, flip = getattr(engine, f"{name}_tags"), getattr(self, f"flip_{name}")
            table = Memory(shape=unsigned(ROW_TAG_BITS + 1), depth=h, init=[])
            m.submodules[f"{name}_tag_table"] = table
            read, write = table.read_port(), table.write_port()
            armed, flipping = Signal(name=f"{name}_flip_armed"), Signal(name=f"{name}_flipping")
            asked = armed & (port.row == flip)
            m.d.sync += [flipping.eq(asked), armed.eq(armed & ~asked)]
            with m.If(self.start):
                m.d.sync += [armed.eq(0), flipping.eq(0)]
            with m.Elif(start_seen):
                m.d.sync += armed.eq(1)      # the engine shows its first row of the map from the clock after
            m.d.comb += [
                read.addr.eq(port.row),
                port.tag.eq(read.data[:ROW_TAG_BITS]),
                port.busy.eq(read.data[ROW_TAG_BITS]),
                write.addr.eq(Mux(self.tag_load_en, self.tag_load_row, flip)),
                write.data.eq(Mux(self.tag_load_en, getattr(self, f"tag_load_{name}"), read.data ^ 1)),
                write.en.eq(self.tag_load_en | flipping),
            ]
