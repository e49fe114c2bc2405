# amaranth: UnusedElaboratable=no
"""BurstWriter with the BufferOwnership (one camera's writer, one reader): for any entries a camera's FIFO could
hold -- any kinds, rows, burst numbers, verdicts, in any order, at any time -- every write granted lands inside the
buffer the writer owns, burst-aligned, never in the buffer the reader holds; and a frame is finished complete only
when the bursts granted since its START were exactly the frame's, in raster order, each made of its own words.

The reference counts the bursts granted since the last START (n) and notes whether the k-th was other than row
k // bursts_per_row, burst k mod bursts_per_row, or was not made of the words taken since the last grant: words
0, 1, .. of that burst in order, the fourth the FIFO's head at the grant (taken in the next clock, which the
reference then skips), or (a row's last burst, short of four words) the row's last words, the rest made by the
writer. It is written from docs/frame_store.md, not from the block's
expected-word counters. The rows are 48 pixels: a row's second burst has two words of the packer's and two made.
"""

from amaranth import Mux, Signal

from hdl.frame_store.burst_packer import ENTRY_KINDS, WORD_BYTES
from hdl.frame_store.burst_writer import BurstWriter
from hdl.frame_store.layout import FrameStoreLayout
from hdl.frame_store.ownership import BufferOwnership
from sim.formal.runner import FormalHarness

LAYOUT = FrameStoreLayout(width=48, height=3, cameras=2, buffers=3, base=64)
CAMERA = 1
assert LAYOUT.bursts_per_row == 2, "the reference's row and burst of the k-th burst are k >> 1 and k & 1"
ROW_WORDS = LAYOUT.row_bytes // WORD_BYTES         # the words the packer sends a row (6: the last burst two short)


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
            entry.row.eq(self.free("row", len(entry.row))), entry.word.eq(self.free("word", len(entry.word))),
            dut.entries.rdy.eq(self.free("rdy")),
            dut.mem.grant.eq(self.free("grant") & dut.mem.request),
            own.writers[0].start.eq(dut.own.start), own.writers[0].finish.eq(dut.own.finish),
            own.writers[0].complete.eq(dut.own.complete),
            dut.own.buffer.eq(own.writers[0].buffer), dut.own.writing.eq(own.writers[0].writing),
            own.readers[0].take.eq(self.free("take")), own.readers[0].release.eq(self.free("release")),
        ]
        # A FIFO keeps its head until it is taken: an entry offered and not taken is offered again, unchanged.
        offered, held_fields = Signal(name="offered_not_taken"), Signal(len(entry.as_value()), name="held_head")
        m.d.sync += [offered.eq(dut.entries.rdy & ~dut.entries.en), held_fields.eq(entry.as_value())]
        self.assume(m, "fifo_head_kept_until_taken", ~offered | (dut.entries.rdy & (entry.as_value() == held_fields)))
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
        # The words taken since the last grant (or START): how many, whether they were words 0, 1, .. of one
        # burst in order, its row and the next word such a run would take.
        taken = dut.entries.en & dut.entries.rdy & (entry.kind == ENTRY_KINDS["BURST"])
        run = Signal(range(5), name="run_words")
        run_ok, run_row, run_next = Signal(name="run_ok"), Signal.like(entry.row, name="run_row"), \
            Signal(len(entry.word) + 1, name="run_next")
        continues = Mux(run == 0, entry.word[:2] == 0, run_ok & (entry.row == run_row) & (entry.word == run_next))
        head = dut.entries.rdy & (entry.kind == ENTRY_KINDS["BURST"])
        # The burst granted: the FIFO's head, its fourth word (taken in the next clock), or the run's, a row's last
        # words (the writer makes the rest).
        fourth = head & (run == 3) & continues & (entry.word[:2] == 3)
        short = ~fourth & (run >= 1) & (run <= 3) & run_ok & (run_next == ROW_WORDS)
        skip = Signal(name="skip_granted_fourth")     # the next entry taken is the granted fourth word
        with m.If(starts | granted):
            m.d.sync += [run.eq(0), skip.eq(granted & fourth)]
        with m.Elif(taken & skip):
            m.d.sync += skip.eq(0)
        with m.Elif(taken):
            m.d.sync += [run.eq(Mux(run == 4, 4, run + 1)), run_ok.eq(continues), run_row.eq(entry.row),
                         run_next.eq(entry.word + 1)]
        row = Mux(fourth, entry.row, run_row)
        burst = Mux(fourth, entry.word[2:], (run_next - 1)[2:])
        with m.If(starts):
            m.d.sync += [n.eq(0), out_of_order.eq(0)]
        with m.Elif(granted):
            m.d.sync += n.eq(Mux(n == total + 1, n, n + 1))
            with m.If((n >= total) | ~(fourth | short) | (row != n[1:]) | (burst != n[0])):   # 2 bursts a row
                m.d.sync += out_of_order.eq(1)
        started = Signal(name="started")          # a START since reset
        with m.If(starts):
            m.d.sync += started.eq(1)
        self.prove(m, "complete_only_after_exactly_the_frame_s_bursts",
                   ~(dut.own.finish & dut.own.complete) | (started & (n == total) & ~out_of_order & ok))
        self.cover(m, "a_frame_finished_complete", dut.own.finish & dut.own.complete & dut.own.writing)
        self.cover(m, "a_write_while_a_frame_is_held", granted & reader.valid)
