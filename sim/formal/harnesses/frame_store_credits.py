# amaranth: UnusedElaboratable=no
"""RowFetcher (the frame store's reads): MIG cannot be held back, so no word MIG returns ever finds the receiving FIFO
full -- for any requests, holds, grants, any read latency and any draining of the FIFO.

The environment: MIG returns a word only for a read it was given (two words a granted burst, in order, any number
of clocks later); the FIFO's reader pops whenever it holds a word; the level the fetcher sees is at least the
FIFO's true occupancy and at most its depth (an asynchronous FIFO's write-side level counts a pop only once it has
crossed). The reference counts the words MIG owes and the FIFO's occupancy; the properties: every word written
finds room, the fetcher's outstanding count is what MIG owes, zero words (no pair held) never interleave with words
MIG owes.
"""

from amaranth import Mux, Signal

from hdl.frame_store.layout import FrameStoreLayout
from hdl.frame_store.row_fetcher import RowFetcher
from sim.formal.runner import FormalHarness

LAYOUT = FrameStoreLayout(width=64, height=3, cameras=1, buffers=3)
DEPTH = 4


class FrameStoreCreditsHarness(FormalHarness):
    name = "frame_store_credits"
    block = "RowFetcher"

    def dut(self):
        return RowFetcher(LAYOUT, 0, depth=DEPTH)

    def build(self, m):
        m.submodules.dut = dut = self.dut()
        owed = Signal(range(2 * DEPTH + 3), name="owed")            # words MIG still owes
        occupancy = Signal(range(DEPTH + 2), name="occupancy")      # words in the FIFO
        seen = self.free("seen_level", range(DEPTH + 1))
        pop = self.free("pop")
        valid = self.free("mig_valid")
        grant = self.free("grant")
        m.d.comb += [
            dut.requests.row.eq(self.free("row", range(LAYOUT.height))),
            dut.requests.rdy.eq(self.free("request_ready")),
            dut.hold.valid.eq(self.free("hold_valid")),
            dut.hold.buffer.eq(self.free("hold_buffer", 2)),
            dut.mem.grant.eq(grant & dut.mem.request),
            dut.mem.valid.eq(valid),
            dut.mem.data.eq(self.free("mig_data", 128)),
            dut.words.level.eq(seen),
        ]
        self.assume(m, "mig_returns_only_what_it_owes", ~valid | (owed != 0))
        self.assume(m, "level_seen_counts_every_word_in", (seen >= occupancy) & (seen <= DEPTH))
        self.assume(m, "hold_buffer_exists", dut.hold.buffer < LAYOUT.buffers)
        popped = pop & (occupancy != 0)
        granted = dut.mem.request & dut.mem.grant
        m.d.sync += [
            owed.eq(owed + Mux(granted, 2, 0) - valid),
            occupancy.eq(occupancy + dut.words.en - popped),
        ]
        self.prove(m, "a_word_always_finds_room", ~dut.words.en | (occupancy < DEPTH))
        self.prove(m, "outstanding_is_what_mig_owes", dut.outstanding == owed)
        self.prove(m, "zero_words_only_when_nothing_is_owed",
                   ~(dut.words.en & ~valid) | (owed == 0))
        self.prove(m, "never_more_owed_than_room", occupancy + owed <= DEPTH)
        self.cover(m, "fifo_full_with_words_owed", (occupancy == DEPTH - 2) & (owed == 2))
        self.cover(m, "full_fifo", occupancy == DEPTH)
