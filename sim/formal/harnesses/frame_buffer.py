# amaranth: UnusedElaboratable=no
"""FrameBuffer: a write at an address >= depth is dropped, and every word reads back its last in-range write.

The buffer is a deliberately awkward size (3 x 3 = 9 words behind a 4-bit address, so 7 addresses are out of
range). Both ports are free on every clock. The data property uses the arbitrary-address technique: the harness
follows one word, at an address ``watched`` that the solver picks and keeps, through a shadow register; a read
of that word must return the shadow. Since the address is arbitrary, the proof covers every word.
"""

from amaranth import Cat, Signal

from hdl.frame_buffer import FrameBuffer
from spec.sensor import SensorGeometry
from sim.formal.runner import FormalHarness

#: 12 x 12 sensor pixels at scale 4: a 3 x 3 buffer of 9 words, addresses 9..15 out of range.
GEOMETRY = SensorGeometry(width=12, height=12, scale=4)


class FrameBufferHarness(FormalHarness):
    name = "frame_buffer"
    block = "FrameBuffer"

    def __init__(self, geometry=GEOMETRY):
        super().__init__()
        self.geometry = geometry

    def dut(self):
        return FrameBuffer(self.geometry)

    def build(self, m):
        g = self.geometry
        depth = g.buf_depth
        w_addr, w_data, w_en = self.free("w_addr", g.addr_bits), self.free("w_data", g.grey_bits), self.free("w_en")
        r_addr = self.free("r_addr", g.addr_bits)
        watched = self.free("watched", g.addr_bits)

        dut = self.dut()
        module = self.open(m, "dut", dut)
        # The block's ports and its memories' write ports, one memory per bit of grey (the one place to adapt when
        # the signature changes).
        m.d.comb += [dut.write.addr.eq(w_addr), dut.write.data.eq(w_data), dut.write.en.eq(w_en),
                     dut.read.addr.eq(r_addr)]
        r_data = dut.read.data
        write_ports = [module.submodules[f"bit{i}"].write_ports[0] for i in range(g.grey_bits)]

        pv = self.past_valid(m)
        # Proof device, not a contract: the watched address is one fixed (but arbitrary) word of the buffer.
        self.assume(m, "watched_address_is_fixed", ~pv | (watched == self.past(m, watched, name="past_watched")))
        self.assume(m, "watched_address_in_buffer", watched < depth)

        self.prove(m, "memory_written_only_below_depth",
                   Cat(~port.en | (port.addr < depth) for port in write_ports).all())
        self.prove(m, "write_below_depth_reaches_memory", ~(w_en & (w_addr < depth)) |
                   Cat(port.en & (port.addr == w_addr) for port in write_ports).all())

        # The watched word: the last in-range write to it since reset (a reset clears the harness, not the RAM).
        shadow = Signal(g.grey_bits, name="shadow")
        known = Signal(name="shadow_known")
        with m.If(w_en & (w_addr == watched)):
            m.d.sync += [shadow.eq(w_data), known.eq(1)]
        read_watched = pv & self.past(m, known & (r_addr == watched), name="past_read_watched_known")
        self.prove(m, "read_returns_last_write", ~read_watched | (r_data == self.past(m, shadow, name="past_shadow")))

        self.cover(m, "read_back_written_word", read_watched & (r_data != 0))
        self.cover(m, "write_out_of_range", w_en & (w_addr >= depth))
        self.cover(m, "read_after_out_of_range_write_to_alias",
                   read_watched & self.past(m, w_en & (w_addr == watched + depth), 2, name="past_alias_write"))
