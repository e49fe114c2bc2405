# amaranth: UnusedElaboratable=no
"""BufferOwnership (the frame store's core): a writer never writes a buffer a reader holds, and what a reader holds
is a pair of frames their writers finished whole, for any pulses of the writers and readers in any clocks.

The block is elaborated with ``platform="formal"``, so its own invariants (docs in :mod:`hdl.frame_store.ownership`)
are asserted with the harness's properties. The reference, written from the rules, not from the block: per camera
and buffer, whether it holds a complete frame -- set when the writer finishes it complete, cleared while a writer
owns it -- and each camera's count of complete frames finished, to tell a pair's frames apart.
"""

from amaranth import Cat, Signal

from hdl.frame_store.ownership import BufferOwnership
from sim.formal.runner import FormalHarness

CAMERAS, READERS, BUFFERS = 2, 1, 3


class FrameStoreOwnershipHarness(FormalHarness):
    name = "frame_store_ownership"
    block = "BufferOwnership"

    cameras = CAMERAS

    def dut(self):
        return BufferOwnership(self.cameras, READERS, BUFFERS)

    def build(self, m):
        dut = self.dut()
        self.open(m, "dut", dut)
        cameras, buffers = dut.cameras, dut.buffers
        for c, w in enumerate(dut.writers):
            m.d.comb += [w.start.eq(self.free(f"start_{c}")), w.finish.eq(self.free(f"finish_{c}")),
                         w.complete.eq(self.free(f"complete_{c}"))]
        for r, reader in enumerate(dut.readers):
            m.d.comb += [reader.take.eq(self.free(f"take_{r}")), reader.release.eq(self.free(f"release_{r}"))]

        complete = [Signal(buffers, name=f"complete_{c}") for c in range(cameras)]
        for c, w in enumerate(dut.writers):
            for b in range(buffers):
                owned = w.writing & (w.buffer == b)
                with m.If(w.finish & owned):                    # the finish comes before a start
                    m.d.sync += complete[c][b].eq(w.complete)
                with m.Elif(owned):
                    m.d.sync += complete[c][b].eq(0)            # being written, or abandoned

        for r, reader in enumerate(dut.readers):
            for c, w in enumerate(dut.writers):
                held = reader.buffer[c]
                self.prove(m, f"writer_{c}_never_writes_reader_{r}_s_buffer",
                           ~(w.writing & reader.valid & (w.buffer == held)))
                self.prove(m, f"reader_{r}_holds_a_complete_frame_of_{c}", ~reader.valid | complete[c].bit_select(held, 1))
            past_valid = self.past_valid(m)
            was_take = self.past(m, reader.take, name=f"take_{r}")
            was_release = self.past(m, reader.release, name=f"release_{r}")
            was_valid = self.past(m, reader.valid, name=f"valid_{r}")
            was_held = self.past(m, Cat(*reader.buffer), name=f"held_{r}")
            self.prove(m, f"reader_{r}_s_pair_is_stable_while_held",
                       ~(past_valid & was_valid & reader.valid & ~was_take & ~was_release) | (Cat(*reader.buffer) == was_held))

        for c, w in enumerate(dut.writers):
            self.prove(m, f"writer_{c}_always_gets_a_buffer",
                       ~(self.past_valid(m) & self.past(m, w.start, name=f"start_{c}")) | w.writing)

        self.covers(m, dut)

    def covers(self, m, dut):
        """The cases the properties are about."""
        w0, w1 = dut.writers
        reader = dut.readers[0]
        self.cover(m, "writers_write_while_a_pair_is_held",
                   reader.valid & w0.writing & w1.writing & (reader.buffer[0] != 0) & (reader.buffer[1] != 0))
        self.cover(m, "a_second_pair_is_held", reader.valid & self.past(m, reader.valid, name="valid_again")
                   & (Cat(*reader.buffer) != self.past(m, Cat(*reader.buffer), name="held_again")))
