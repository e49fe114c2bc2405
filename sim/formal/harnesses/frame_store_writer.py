# amaranth: UnusedElaboratable=no
"""BurstWriter with the BufferOwnership (one camera's writer, one reader): for any entries a camera's FIFO could
hold -- any kinds, rows, burst numbers, verdicts, in any order, at any time -- every write granted lands inside the
buffer the writer owns, burst-aligned, never in the buffer the reader holds; and a frame is finished complete only
when the bursts granted since its START were exactly the frame's, in raster order.

An entry offered and not taken is offered again, unchanged (the FIFO's read side the writer reads).
The reference counts the bursts granted since the last START (n) and notes whether the k-th was other than row
k // bursts_per_row, burst k mod bursts_per_row; it is written from docs/frame_store.md, not from the block's
expected-burst counters.
"""

from amaranth import Mux, Signal

from hdl.frame_store.burst_writer import BurstWriter
from hdl.frame_store.layout import FrameStoreLayout
from hdl.frame_store.ownership import BufferOwnership
from sim.formal.runner import FormalHarness

LAYOUT = FrameStoreLayout(width=64, height=3, cameras=2, buffers=3, base=64)
CAMERA = 1
assert LAYOUT.bursts_per_row == 2, "the reference's row and burst of the k-th burst are k >> 1 and k & 1"


class FrameStoreWriterHarness(FormalHarness):
    name = "frame_store_writer"
    block = "BurstWriter"

    def dut(self):
        return BurstWriter(LAYOUT, CAMERA)

    def connect_verdict(self, m, dut, ok):
        """The entry's verdict (the one place a bite rewires)."""
        m.d.comb += dut.entries.data.ok.eq(ok)

    def build(self, m):
        lay = LAYOUT
        m.submodules.dut = dut = self.dut()
        m.submodules.own = own = BufferOwnership(cameras=1, readers=1, buffers=lay.buffers)
        entry = dut.entries.data
        ok = self.free("ok")
        self.connect_verdict(m, dut, ok)
        m.d.comb += [
            entry.kind.eq(self.free("kind", 2)),
            entry.row.eq(self.free("row", len(entry.row))), entry.burst.eq(self.free("burst", len(entry.burst))),
            dut.entries.rdy.eq(self.free("rdy")),
            dut.mem.grant.eq(self.free("grant") & dut.mem.request),
            own.writers[0].start.eq(dut.own.start), own.writers[0].finish.eq(dut.own.finish),
            own.writers[0].complete.eq(dut.own.complete),
            dut.own.buffer.eq(own.writers[0].buffer), dut.own.writing.eq(own.writers[0].writing),
            own.readers[0].take.eq(self.free("take")), own.readers[0].release.eq(self.free("release")),
        ]
        # A FIFO's read side: an entry offered and not taken is offered again, unchanged.
        held = self.past(m, dut.entries.rdy & ~dut.entries.en, name="held") & self.past_valid(m)
        for name, value in (("rdy", dut.entries.rdy), ("kind", entry.kind), ("row", entry.row),
                            ("burst", entry.burst), ("ok", ok)):
            was = self.past(m, value, name=f"was_{name}")
            self.assume(m, f"offered_{name}_held_until_taken", ~held | (value == was))
        granted = dut.mem.request & dut.mem.grant
        addr = dut.mem.addr
        low = Mux(dut.own.buffer == 0, lay.buffer_base(CAMERA, 0),
                  Mux(dut.own.buffer == 1, lay.buffer_base(CAMERA, 1), lay.buffer_base(CAMERA, 2)))
        self.prove(m, "write_inside_the_owned_buffer",
                   ~granted | (dut.own.writing & (addr >= low) & (addr + 3 < low + lay.buffer_words)))
        self.prove(m, "write_burst_aligned", ~granted | (addr[:2] == 0))
        reader = own.readers[0]
        self.prove(m, "write_never_in_the_held_buffer",
                   ~(granted & reader.valid & (reader.buffer[0] == dut.own.buffer)))

        total = lay.height * lay.bursts_per_row
        n = Signal(range(total + 2), name="granted_since_start")
        out_of_order = Signal(name="out_of_order")
        starts = dut.own.start
        with m.If(starts):
            m.d.sync += [n.eq(0), out_of_order.eq(0)]
        with m.Elif(granted):
            m.d.sync += n.eq(Mux(n == total + 1, n, n + 1))
            with m.If((n >= total) | (entry.row != n[1:]) | (entry.burst != n[0])):   # 2 bursts a row
                m.d.sync += out_of_order.eq(1)
        started = Signal(name="started")          # a START since reset
        with m.If(starts):
            m.d.sync += started.eq(1)
        self.prove(m, "complete_only_after_exactly_the_frame_s_bursts",
                   ~(dut.own.finish & dut.own.complete) | (started & (n == total) & ~out_of_order & ok))
        self.cover(m, "a_frame_finished_complete", dut.own.finish & dut.own.complete & dut.own.writing)
        self.cover(m, "a_write_while_a_frame_is_held", granted & reader.valid)
