"""The depth maps' BufferOwnership (docs/frame_store.md, "Depth maps in the store"): one "camera" (the map writer),
one reader (the display), three buffers. The properties are the cameras' (:mod:`sim.formal.harnesses.frame_store`):
the writer never writes the map the display holds, the held map is one the writer finished whole, it does not change
until the next take, and the writer always gets a buffer -- for any starts, finishes (whole or abandoned) and takes
in any clocks."""

from amaranth import Cat

from sim.formal.harnesses.frame_store import FrameStoreOwnershipHarness

__all__ = ["MapOwnershipHarness"]


class MapOwnershipHarness(FrameStoreOwnershipHarness):
    name = "map_store_ownership"
    cameras = 1

    def covers(self, m, dut):
        """The writer writes a map while the display holds another; a second map is held."""
        (writer,), reader = dut.writers, dut.readers[0]
        self.cover(m, "writer_writes_while_a_map_is_held", reader.valid & writer.writing)
        self.cover(m, "a_second_map_is_held", reader.valid & self.past(m, reader.valid, name="valid_again")
                   & (Cat(*reader.buffer) != self.past(m, Cat(*reader.buffer), name="held_again")))
