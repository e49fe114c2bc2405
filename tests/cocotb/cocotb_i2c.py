"""cocotb tests of the I2C init sequencers (Verilator and Icarus), one design: an ``I2CBench`` with the MT9D112
sequencer on bus ``cam`` and the CH7301C sequencer on bus ``dvi``, bus at 100 kHz, sync clock ``clk_hz``.

* ``test_third_party_decode``: a cocotbext-i2c device on each bus (bit/byte/START/STOP/ACK decoding and address
  matching by the third-party library) records the bus; the decoded writes must equal the expected list, the
  polls must read the expected registers, and a timing monitor on each bus must see every UM10204
  standard-mode interval met.
* ``test_faults_nack``: the project's models with faults: the MT9D112 NACKs the data of one register for ever
  (error NACK_DATA at that entry, nothing written after it); the CH7301C bus has no device (NACK_ADDR).
* ``test_stretch_and_stuck``: the CH7301C model stretches SCL after every byte (table completes, writes equal
  the expected list, stretched low times on the bus); the MT9D112 bus has SDA held low (STUCK after the
  timeout and the nine-pulse bus clear, no write).

Parameters (``sim.runners.cocotb.test_params()``): ``clk_hz`` (the clock the design was built for) and its
``timeout_us`` and ``retries``, for the checks.
"""

import cocotb
from cocotb.clock import Clock
from cocotb.simtime import get_sim_time
from cocotb.triggers import ClockCycles, Timer
from cocotbext.i2c import I2cDevice

from sim.models.i2c.table import expected_prefix, expected_writes
from hdl.i2c_init import ErrorCode
from hdl.init_tables import CH7301C_TABLE, MT9D112_TABLE, Wait, Write
from sim.runners.cocotb import TopPorts, test_params
from sim.models.i2c.bus import start_cocotb_monitor, start_cocotb_targets
from sim.models.ch7301c.target import CH7301CModel
from sim.models.i2c.monitor import I2CBusMonitor
from sim.models.mt9d112.target import MT9D112Model

PARAMS = test_params()
CLK_PERIOD_NS = 1e9 / PARAMS.get("clk_hz", 100_000_000)
TABLES = {"cam": MT9D112_TABLE, "dvi": CH7301C_TABLE}


class RecordingDevice(I2cDevice):
    """A cocotbext-i2c device that records what it decodes: a transaction is the list of its segments (one per
    START / repeated START), each ``["w" or "r", [bytes]]``. Reads are answered by ``responder(reg, n)`` (n =
    how many times that register was read before)."""

    def __init__(self, dut, bus, device, responder):
        self.addr = device.address                    # I2cDevice matches against self.addr
        self.device = device
        self.responder = responder
        self.segments = []
        self.transactions = []
        self.read_count = {}
        lines = getattr(TopPorts(dut).bus, bus)
        super().__init__(sda=lines.sda, sda_o=lines.peer_sda_o, scl=lines.scl, scl_o=lines.peer_scl_o)

    def handle_start(self):
        self.segments.append(["?", []])

    async def handle_write(self, data):
        self.segments[-1][0] = "w"
        self.segments[-1][1].append(data)

    async def handle_read(self):
        seg = self.segments[-1]
        if seg[0] != "r":
            seg[0] = "r"
            prev = [s for s in self.segments[:-1] if s[1]]
            reg = int.from_bytes(bytes(prev[-1][1]), "big") if prev else None
            n = self.read_count.get(reg, 0)
            self.read_count[reg] = n + 1
            seg.append(self.responder(reg, n).to_bytes(self.device.data_bytes, "big"))
        data = seg[2][len(seg[1])] if len(seg[1]) < len(seg[2]) else 0xFF
        seg[1].append(data)
        return data

    def handle_stop(self):
        segs = [s[:2] for s in self.segments if s[1]]
        if segs:
            self.transactions.append(segs)
        self.segments = []

    def decoded(self):
        """``(writes, reads, malformed)``: writes ``[(device, reg, value)]``, reads ``[(device, reg, value)]``."""
        rb, db = self.device.reg_bytes, self.device.data_bytes
        writes, reads, bad = [], [], []
        for segs in self.transactions:
            kinds = [k for k, _ in segs]
            if kinds == ["w"] and len(segs[0][1]) == rb + db:
                b = bytes(segs[0][1])
                writes.append((self.device.name, int.from_bytes(b[:rb], "big"), int.from_bytes(b[rb:], "big")))
            elif kinds == ["w", "r"] and len(segs[0][1]) == rb and len(segs[1][1]) == db:
                reads.append((self.device.name, int.from_bytes(bytes(segs[0][1]), "big"),
                              int.from_bytes(bytes(segs[1][1]), "big")))
            else:
                bad.append(segs)
        return writes, reads, bad


def cam_responder(reg, n):
    # chip version; the sequencer-command variable reads "busy" (2) once, then 0 (command done)
    return {0x3000: 0x1580, 0x3390: 0x0002 if n == 0 else 0x0000}.get(reg, 0)


def dvi_responder(reg, n):
    return {0x4A: 0x95, 0x4B: 0x17}.get(reg, 0)


async def reset(dut):
    for bus in TABLES:
        lines = getattr(TopPorts(dut).bus, bus)
        lines.peer_scl_o.value = 1
        lines.peer_sda_o.value = 1
        lines.ext_scl_low.value = 0
        lines.ext_sda_low.value = 0
    dut.rst.value = 1
    await ClockCycles(dut.clk, 10)
    dut.rst.value = 0
    return get_sim_time("ns") * 1e-9


async def run_until_settled(dut, limit_ms):
    """Wait until every bus reports done or error; fail the test if it takes longer than ``limit_ms``. Checks on
    every 20 us step that done and error are never both high and that done, once seen, never falls."""
    seen_done = {}
    for _ in range(int(limit_ms * 50)):
        await Timer(20, unit="us")
        settled = True
        for bus in TABLES:
            state = getattr(TopPorts(dut).status, bus)
            done, err = int(state.done.value), int(state.error.value)
            assert not (done and err), f"{bus}: done and error together"
            if seen_done.get(bus) and not done:
                raise AssertionError(f"{bus}: done fell")
            if done and bus not in seen_done:
                seen_done[bus] = get_sim_time("ns") * 1e-9
            settled &= bool(done or err)
        if settled:
            return seen_done
    raise AssertionError(f"sequencers still busy after {limit_ms} ms")


def status(dut, bus):
    s = getattr(TopPorts(dut).status, bus)
    return int(s.done.value), int(s.error.value), ErrorCode(int(s.error_code.value)), int(s.entry.value)


def entry_index(table, reg):
    return next(i for i, e in enumerate(table.entries) if isinstance(e, Write) and e.reg == reg)


@cocotb.test()
async def test_third_party_decode(dut):
    Clock(dut.clk, CLK_PERIOD_NS, unit="ns").start()
    devices = {"cam": RecordingDevice(dut, "cam", MT9D112_TABLE.device, cam_responder),
               "dvi": RecordingDevice(dut, "dvi", CH7301C_TABLE.device, dvi_responder)}
    monitors = {bus: I2CBusMonitor() for bus in TABLES}
    for bus, mon in monitors.items():
        start_cocotb_monitor(getattr(TopPorts(dut).bus, bus), mon)
    t0 = await reset(dut)
    done_at = await run_until_settled(dut, limit_ms=60)

    for bus, table in TABLES.items():
        dut._log.info("%s: init done %.2f ms after reset", bus, 1e3 * (done_at[bus] - t0))
        assert status(dut, bus) == (1, 0, ErrorCode.NONE, len(table)), f"{bus}: {status(dut, bus)}"
        writes, reads, bad = devices[bus].decoded()
        assert not bad, f"{bus}: transactions that are neither a write nor a register read: {bad[:3]}"
        assert writes == expected_writes(table), f"{bus}: decoded writes differ from the expected list"
        assert len(monitors[bus].transactions) == len(writes) + len(reads), f"{bus}: retries in a clean run"
        dut._log.info("%s: %d writes decoded by cocotbext-i2c equal the expected list", bus, len(writes))
        assert int(getattr(TopPorts(dut).bus, bus).drive_high.value) == 0, f"{bus}: a line was driven high"
        viol = monitors[bus].violations()
        assert not viol, f"{bus}: UM10204 standard-mode violations: {viol}"
        assert not monitors[bus].protocol_errors, monitors[bus].protocol_errors[:3]
        dut._log.info("%s minimum intervals (us): %s; largest SDA change after SCL fell %.2f us", bus,
                      {k: round(v * 1e6, 2) for k, v in monitors[bus].minimum.items()},
                      monitors[bus].max_hold * 1e6)

    _, cam_reads, _ = devices["cam"].decoded()
    assert [r[1] for r in cam_reads] == [0x3000, 0x3390, 0x3390]     # ID check; poll busy once, then done
    _, dvi_reads, _ = devices["dvi"].decoded()
    assert [(r[1], r[2]) for r in dvi_reads] == [(0x4A, 0x95), (0x4B, 0x17)]


@cocotb.test()
async def test_faults_nack(dut):
    Clock(dut.clk, CLK_PERIOD_NS, unit="ns").start()
    reg = 0x3214                                                  # slew-rate register: the 3rd write
    cam = MT9D112Model(nack_write_byte=2, nack_write_reg=reg)    # NACK its first data byte, for ever
    cam_mon, dvi_mon = I2CBusMonitor(), I2CBusMonitor()
    start_cocotb_targets(TopPorts(dut).bus.cam, [cam], cam_mon)
    start_cocotb_monitor(TopPorts(dut).bus.dvi, dvi_mon)          # no device on the DVI bus
    await reset(dut)
    done_at = await run_until_settled(dut, limit_ms=30)
    assert not done_at, f"done reported despite faults: {done_at}"

    idx = entry_index(MT9D112_TABLE, reg)
    assert status(dut, "cam") == (0, 1, ErrorCode.NACK_DATA, idx)
    assert [("mt9d112", r, v) for r, v in cam.writes] == expected_prefix(MT9D112_TABLE, idx)
    assert cam.nacks_given == PARAMS["retries"] + 1
    assert status(dut, "dvi") == (0, 1, ErrorCode.NACK_ADDR, 0)
    assert len(dvi_mon.transactions) == PARAMS["retries"] + 1
    assert all(t[0] == ((0x76 << 1), False) for t in dvi_mon.transactions)

    # nothing moves on either bus after the error
    t_err = get_sim_time("ns") * 1e-9
    await Timer(2, unit="ms")
    for mon in (cam_mon, dvi_mon):
        assert mon.last_edge is not None and mon.last_edge < t_err


@cocotb.test()
async def test_stretch_and_stuck(dut):
    Clock(dut.clk, CLK_PERIOD_NS, unit="ns").start()
    cam = MT9D112Model(hold_sda_low=True)
    dvi = CH7301CModel(stretch_s=20e-6)
    cam_mon, dvi_mon = I2CBusMonitor(), I2CBusMonitor()
    start_cocotb_targets(TopPorts(dut).bus.cam, [cam], cam_mon)
    start_cocotb_targets(TopPorts(dut).bus.dvi, [dvi], dvi_mon)
    t0 = await reset(dut)
    done_at = await run_until_settled(dut, limit_ms=20)

    assert status(dut, "dvi") == (1, 0, ErrorCode.NONE, len(CH7301C_TABLE))
    assert [("ch7301c", r, v) for r, v in dvi.writes] == expected_writes(CH7301C_TABLE)
    assert dvi.stretches > 10
    assert not dvi_mon.violations(), dvi_mon.violations()
    assert dvi_mon.maximum["tLOW"] >= 20e-6 - 1e-9, "the stretch did not show on the bus"

    assert "cam" not in done_at
    first_access = next(i for i, e in enumerate(MT9D112_TABLE.entries) if not isinstance(e, Wait))
    assert status(dut, "cam") == (0, 1, ErrorCode.STUCK, first_access)
    assert cam.writes == [] and cam.transactions == 0
    # SDA low for ever: the master waited its timeout, tried the nine-pulse bus clear, then gave up
    assert cam_mon.scl_rises == 9
    waited = (sum(e.us for e in MT9D112_TABLE.entries[:first_access]) + PARAMS["timeout_us"]) * 1e-6
    assert waited < cam_mon.last_edge - t0 < waited + 0.5e-3
