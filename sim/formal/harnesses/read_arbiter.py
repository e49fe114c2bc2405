# amaranth: UnusedElaboratable=no
"""ReadArbiter: the buffer's one read port serves one reader per clock, the display (priority) is never refused.

Every input is free on every clock: both readers' requests and addresses, and the buffer's read data. The
properties are the contract of :class:`hdl.depth.SharedReadSignature` and of the arbiter's docstring: the display
is granted whenever it requests, the engine exactly in the clocks the display leaves free, the buffer's address is
the granted reader's, and its data reaches both readers.
"""

from spec.sensor import SMALL_SENSOR
from hdl.read_arbiter import ReadArbiter
from sim.formal.runner import FormalHarness


class ReadArbiterHarness(FormalHarness):
    name = "read_arbiter"
    block = "ReadArbiter"

    def __init__(self, geometry=SMALL_SENSOR):
        super().__init__()
        self.geometry = geometry

    def dut(self):
        return ReadArbiter(self.geometry)

    def build(self, m):
        g = self.geometry
        request = {r: self.free(f"{r}_request") for r in ("display", "engine")}
        addr = {r: self.free(f"{r}_addr", g.addr_bits) for r in ("display", "engine")}
        data = self.free("buffer_data", g.grey_bits)
        m.submodules.dut = dut = self.dut()
        # The block's ports (the one place to adapt when the signature changes).
        readers = {"display": dut.display, "engine": dut.engine}
        for r, port in readers.items():
            m.d.comb += [port.request.eq(request[r]), port.port.addr.eq(addr[r])]
        m.d.comb += dut.buffer.data.eq(data)
        grant = {r: port.grant for r, port in readers.items()}
        served = {r: request[r] & grant[r] for r in readers}        # a read the buffer performs for r

        self.prove(m, "one_reader_per_clock", ~(served["display"] & served["engine"]))
        self.prove(m, "display_never_refused", ~request["display"] | grant["display"])
        self.prove(m, "engine_granted_exactly_when_display_idle", grant["engine"] == ~request["display"])
        self.prove(m, "buffer_address_is_display_read", ~served["display"] | (dut.buffer.addr == addr["display"]))
        self.prove(m, "buffer_address_is_engine_read", ~served["engine"] | (dut.buffer.addr == addr["engine"]))
        self.prove(m, "read_data_reaches_both_readers",
                   (readers["display"].port.data == data) & (readers["engine"].port.data == data))
        self.cover(m, "engine_read_granted", served["engine"] & (addr["engine"] != addr["display"]))
        self.cover(m, "engine_request_refused", request["engine"] & ~grant["engine"] &
                   (addr["engine"] != addr["display"]))
