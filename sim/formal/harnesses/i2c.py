# amaranth: UnusedElaboratable=no
"""I2CMaster and InitSequencer: open-drain pins, START/STOP the only SDA changes while SCL is high, a stuck bus
ends in the stuck-bus error in time, the init ROM index stays in range, ``done`` and ``error`` never together.

The bus is modelled as wired-AND lines: SCL = the master's release AND any other device's (free on every
clock), the same for SDA, so targets may stretch the clock, NACK, hold SDA or drive anything at all. The small
clock ratio (400 kHz system clock for a 100 kHz bus: 2-clock SCL phases) keeps the traces short; every
interval of :class:`~hdl.i2c_master.I2CTiming` is still derived from it.
"""

from amaranth import Cat, Signal

from hdl.i2c_init import ErrorCode, InitSequencer
from hdl.i2c_master import Cmd, I2CMaster
from hdl.init_tables import I2CDeviceSpec, InitTable, Wait, Write
from sim.formal.runner import FormalHarness

CLK_HZ, BUS_HZ, TIMEOUT_US = 400_000, 100_000, 50          # timeout: 20 clocks


def bus(harness, m, pins):
    """Wired-AND SCL and SDA between the master's open-drain ``pins`` and the rest of the bus (free inputs);
    ``{"scl": line, "sda": line, "scl_other": ..., "sda_other": ...}``."""
    scl_other, sda_other = harness.free("scl_other"), harness.free("sda_other")
    scl = Signal(name="scl_line")
    sda = Signal(name="sda_line")
    m.d.comb += [scl.eq(~pins["scl_oe"] & scl_other), sda.eq(~pins["sda_oe"] & sda_other),
                 pins["scl_i"].eq(scl), pins["sda_i"].eq(sda)]
    harness.prove(m, "scl_open_drain", pins["scl_o"] == 0)
    harness.prove(m, "sda_open_drain", pins["sda_o"] == 0)
    return {"scl": scl, "sda": sda, "scl_other": scl_other, "sda_other": sda_other}


def master_pins(master):
    """The master's pins (the one place to adapt when the signature changes)."""
    return {f"{line}_{pin}": getattr(getattr(master.i2c, line), pin)
            for line in ("scl", "sda") for pin in ("o", "oe", "i")}


class I2CMasterHarness(FormalHarness):
    name = "i2c_master"
    block = "I2CMaster"

    def dut(self):
        return I2CMaster(clk_hz=CLK_HZ, bus_hz=BUS_HZ, timeout_us=TIMEOUT_US)

    def build(self, m):
        m.submodules.dut = dut = self.dut()
        t = dut.timing
        cmd, cmd_valid = self.free("cmd", Cmd), self.free("cmd_valid")
        # The block's ports (the one place to adapt when the signature changes).
        m.d.comb += [dut.cmd.eq(cmd), dut.cmd_valid.eq(cmd_valid), dut.wdata.eq(self.free("wdata", 8)),
                     dut.rd_ack.eq(self.free("rd_ack"))]
        pins = master_pins(dut)
        ready, done, timed_out, bus_active = dut.ready, dut.done, dut.timed_out, dut.bus_active
        lines = bus(self, m, pins)

        accepted, current, busy = self._commands(m, dut, cmd, cmd_valid)
        self.prove(m, "done_ends_an_accepted_command", ~done | busy)
        self.prove(m, "ready_only_between_commands", ~ready | ~busy)
        self.prove(m, "scl_held_low_between_commands_of_a_transfer", ~(ready & bus_active) | pins["scl_oe"])

        # SDA moves while SCL is high only as a START (pull) or a STOP (release) -- or when a timed-out command
        # lets go of both lines.
        pv = self.past_valid(m)
        sda_was = self.past(m, pins["sda_oe"], name="past_sda_oe")
        scl_high = lines["scl"] | self.past(m, lines["scl"], name="past_scl_line")
        pulled, released = pv & scl_high & ~sda_was & pins["sda_oe"], pv & scl_high & sda_was & ~pins["sda_oe"]
        starting, stopping = busy & (current == Cmd.START), busy & (current == Cmd.STOP)
        self.prove(m, "sda_falls_under_scl_high_only_as_start", ~pulled | starting)
        self.prove(m, "sda_rises_under_scl_high_only_as_stop", ~released | starting | stopping | (done & timed_out))

        self._stuck_scl(m, t, dut, accepted, busy, done, timed_out, lines)
        self.cover(m, "start_condition", pulled)
        self.cover(m, "stop_condition", released & stopping)
        self.cover(m, "write_nacked", done & dut.nack)
        stretched = busy & (current == Cmd.WRITE) & ~pins["scl_oe"] & ~lines["scl"]
        self.cover(m, "write_clock_stretched_then_released",
                   busy & ~pins["scl_oe"] & lines["scl"] & self.past(m, stretched, name="past_stretched"))
        self.cover(m, "arbitration_lost", done & dut.arb_lost)

    def _commands(self, m, dut, cmd, cmd_valid):
        """The command contract (docstring: WRITE and READ only inside a transfer, after a START) and the command
        in progress: (accepted this clock, the current command, busy until its ``done``)."""
        accepted = dut.ready & cmd_valid
        self.assume(m, "data_commands_only_in_a_transfer",
                    ~(accepted & ((cmd == Cmd.WRITE) | (cmd == Cmd.READ))) | dut.bus_active)
        current = Signal(Cmd, name="current_cmd")
        busy = Signal(name="busy")
        with m.If(accepted):
            m.d.sync += [current.eq(cmd), busy.eq(1)]
        with m.Elif(dut.done):
            m.d.sync += busy.eq(0)
        return accepted, current, busy

    def _stuck_scl(self, m, t, dut, accepted, busy, done, timed_out, lines):
        """A command that finds SCL held low by another device all along ends with ``timed_out`` within the
        documented bound: the time-out plus, for a byte, the SCL low phase before the master lets SCL go."""
        timeout = -(-TIMEOUT_US * CLK_HZ // 1_000_000)       # the configured time-out, in clocks
        bound = timeout + t.hold + t.low + t.su_dat + 4
        stuck = Signal(name="scl_stuck_since_command")
        clocks = Signal(range(bound + 2), name="stuck_clocks")
        uses_bus = ~((dut.cmd == Cmd.STOP) & ~dut.bus_active)
        with m.If(accepted):
            m.d.sync += [stuck.eq(~lines["scl_other"] & uses_bus), clocks.eq(0)]
        with m.Elif(busy):
            m.d.sync += stuck.eq(stuck & ~lines["scl_other"])
            with m.If(clocks <= bound):
                m.d.sync += clocks.eq(clocks + 1)
        self.prove(m, "stuck_scl_command_still_within_bound", ~(busy & stuck) | (clocks <= bound))
        self.prove(m, "stuck_scl_command_ends_timed_out", ~(done & stuck) | timed_out)
        self.cover(m, "stuck_scl_timed_out", done & stuck & timed_out)


#: A three-entry table on a 1-byte-register device: one write (S addr reg data P) and two waits; three entries
#: so that the ROM's 2-bit address could point past the table.
TABLE = InitTable(I2CDeviceSpec("formal", 0x3C, reg_bytes=1, data_bytes=1),
                  (Write(0x12, 0x5A, "one register write"), Wait(5, "a pause"), Wait(5, "another pause")))


class InitSequencerHarness(FormalHarness):
    name = "i2c_init"
    block = "InitSequencer"

    def __init__(self, table=TABLE, retries=1):
        super().__init__()
        self.table, self.retries = table, retries

    def dut(self):
        return InitSequencer(self.table, clk_hz=CLK_HZ, bus_hz=BUS_HZ, retries=self.retries, retry_delay_us=10,
                             timeout_us=TIMEOUT_US)

    def build(self, m):
        n = len(self.table)
        dut = self.dut()
        module = self.open(m, "dut", dut)
        # The block's ports, its master's command interface and its ROM's read port (the one place to adapt).
        pins = master_pins(dut)
        status = dut.status
        done, error, error_code, entry = status.done, status.error, status.error_code, status.entry
        master = module.submodules.master
        rom_addr = module.submodules.rom.read_ports[0].addr
        bus(self, m, pins)

        pv = self.past_valid(m)
        self.prove(m, "rom_index_within_table", entry <= n)
        self.prove(m, "rom_read_inside_table", rom_addr < n)
        self.prove(m, "done_and_error_never_together", ~(done & error))
        self.prove(m, "done_sticky", ~(pv & self.past(m, done, name="past_done")) | done)
        self.prove(m, "error_sticky", ~(pv & self.past(m, error, name="past_error")) | error)
        self.prove(m, "done_only_after_whole_table", ~done | (entry == n))
        self.prove(m, "error_has_a_code", ~error | (error_code != ErrorCode.NONE))
        self.prove(m, "bus_released_after_error", ~error | (~pins["scl_oe"] & ~pins["sda_oe"]))

        # A NACKed address byte, then the same entry's transaction again from its START.
        address_nacked = Signal(name="address_nacked")
        with m.If(master.done & master.nack):
            m.d.sync += address_nacked.eq(1)
        self.cover(m, "nack_then_retry", address_nacked & master.ready & master.cmd_valid &
                   (master.cmd == Cmd.START) & (entry == 0))
        self.cover(m, "table_done", done)
        self.cover(m, "stuck_bus_error", error & (error_code == ErrorCode.STUCK))


class I2CBroadcastMasterHarness(I2CMasterHarness):
    """The master broadcasting on two buses (``buses=2``), each a wired-AND bus with its own free other side, and
    ``enable`` free between transfers: a bus left out is never pulled low, the enabled buses are driven alike,
    on each bus SDA moves under a high SCL only as a START or a STOP, and SCL held low on an enabled bus ends a
    command timed out within the same bound as on one bus."""
    name = "i2c_master_buses"
    block = "I2CMaster"
    buses = 2

    def dut(self):
        return I2CMaster(clk_hz=CLK_HZ, bus_hz=BUS_HZ, timeout_us=TIMEOUT_US, buses=self.buses)

    def build(self, m):
        m.submodules.dut = dut = self.dut()
        t, n = dut.timing, self.buses
        cmd, cmd_valid = self.free("cmd", Cmd), self.free("cmd_valid")
        enable = self.free("enable", n)
        m.d.comb += [dut.cmd.eq(cmd), dut.cmd_valid.eq(cmd_valid), dut.wdata.eq(self.free("wdata", 8)),
                     dut.rd_ack.eq(self.free("rd_ack")), dut.enable.eq(enable)]
        ready, done, timed_out, bus_active = dut.ready, dut.done, dut.timed_out, dut.bus_active
        accepted, current, busy = self._commands(m, dut, cmd, cmd_valid)
        pv = self.past_valid(m)
        # enable's contract (docstring): it changes only between transfers, and some bus is in use.
        self.assume(m, "enable_changes_only_between_transfers",
                    ~pv | (enable == self.past(m, enable, name="past_enable")) | (ready & ~bus_active))
        self.assume(m, "some_bus_enabled", enable != 0)
        starting, stopping = busy & (current == Cmd.START), busy & (current == Cmd.STOP)
        lines = []
        for k in range(n):
            pins = {f"{line}_{pin}": getattr(getattr(dut.i2c[k], line), pin)
                    for line in ("scl", "sda") for pin in ("o", "oe", "i")}
            scl_other, sda_other = self.free(f"scl_other_{k}"), self.free(f"sda_other_{k}")
            scl, sda = Signal(name=f"scl_line_{k}"), Signal(name=f"sda_line_{k}")
            m.d.comb += [scl.eq(~pins["scl_oe"] & scl_other), sda.eq(~pins["sda_oe"] & sda_other),
                         pins["scl_i"].eq(scl), pins["sda_i"].eq(sda)]
            lines.append((pins, scl, scl_other))
            self.prove(m, f"bus_{k}_open_drain", (pins["scl_o"] == 0) & (pins["sda_o"] == 0))
            self.prove(m, f"bus_{k}_not_pulled_unless_enabled", enable[k] | (~pins["scl_oe"] & ~pins["sda_oe"]))
            sda_was = self.past(m, pins["sda_oe"], name=f"past_sda_oe_{k}")
            scl_high = scl | self.past(m, scl, name=f"past_scl_line_{k}")
            pulled = pv & scl_high & ~sda_was & pins["sda_oe"]
            released = pv & scl_high & sda_was & ~pins["sda_oe"]
            self.prove(m, f"bus_{k}_sda_falls_under_scl_high_only_as_start", ~pulled | starting)
            self.prove(m, f"bus_{k}_sda_rises_under_scl_high_only_as_stop",
                       ~released | starting | stopping | (done & timed_out))
        (p0, scl0, _), (p1, scl1, _) = lines[0], lines[1]
        self.prove(m, "enabled_buses_driven_alike", ~(enable[0] & enable[1]) |
                   ((p0["scl_oe"] == p1["scl_oe"]) & (p0["sda_oe"] == p1["sda_oe"])))
        # SCL as the master reads it: low when an enabled bus's other side holds it.
        held = Signal(name="scl_other_all")
        m.d.comb += held.eq(Cat(*((other | ~enable[k]) for k, (_, _, other) in enumerate(lines))).all())
        self._stuck_scl(m, t, dut, accepted, busy, done, timed_out, {"scl_other": held})
        self.cover(m, "write_nacked_by_bus_1_only", done & dut.nack & (dut.nack_buses == 0b10))
        self.cover(m, "bus_0_high_while_bus_1_stretched",
                   busy & enable[0] & enable[1] & ~p0["scl_oe"] & scl0 & ~scl1)
        self.cover(m, "read_differs_between_buses", done & (current == Cmd.READ) & (dut.rdata != dut.rdata_any))
