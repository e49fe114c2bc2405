"""InitSequencer: the real init tables played against the project's register-file models (Amaranth simulator),
fault behaviour, and the cocotb run on Verilator and Icarus against a third-party I2C peer (cocotbext-i2c).

Amaranth runs use a 1 MHz sync clock (every bus interval is derived from ``clk_hz``; the bus still runs at
100 kHz in real time, the table waits keep their real length) and short retry/timeout settings so a fault
ends quickly; the cocotb default run uses a 1 MHz clock as well; the board configuration (100 MHz clock, board
retry/timeout values) runs on both simulators in the ``slow`` test.
"""

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from golden.part_config import ch7301c_expected, mt9d112_expected
from hdl.i2c_init import ErrorCode, InitSequencer
from hdl.init_tables import CH7301C_TABLE, MT9D112_TABLE, InitTable, Poll, Wait, Write, CH7301C
from sim.runners.amaranth import simulate
from sim.runners.cocotb import run_cocotb
from sim.models.i2c.bus import I2CBench, amaranth_target_process, i2c_bench_waves
from sim.models.ch7301c.target import CH7301CModel
from sim.models.i2c.monitor import I2CBusMonitor
from sim.models.i2c.target import RegisterTarget
from sim.models.mt9d112.target import MT9D112Model
from sim.models.i2c.table import expected_prefix, expected_reads, expected_writes
from sim.models.mt9d112.config import expected_sensor_config

CLK = 1_000_000
FAST = dict(retries=2, retry_delay_us=50, timeout_us=500)


class Run:
    """Outcome of one sequencer simulation."""


def run_sequencer(table, targets, *, limit_s, quiet_s=0.002, clk=CLK, **kw):
    """Simulate ``InitSequencer(table)`` with ``targets`` on its bus until it reports done or error, then
    ``quiet_s`` longer (to see that nothing else happens). Fails if neither comes within ``limit_s``."""
    params = {**FAST, **kw}
    seq = InitSequencer(table, clk_hz=clk, **params)
    bench = I2CBench({"bus": seq})
    r = Run()
    r.monitor = I2CBusMonitor()
    r.retries = params["retries"]
    target = amaranth_target_process(bench.bus.bus, targets, clk, bench.cycles, r.monitor)
    status = bench.status.bus

    async def testbench(ctx):
        done = error = 0
        while not (done or error):
            done, error, cycles = await ctx.changed(status.done, status.error).sample(bench.cycles)
            assert not (done and error), "done and error together"
        r.t_settled = cycles / clk
        r.done, r.error = done, error
        r.code, r.entry = ctx.get(status.error_code), ctx.get(status.entry)
        r.mismatch = ctx.get(status.mismatch)
        # afterwards: the status must not change and the bus must stay quiet
        _, _, expired = await ctx.changed(status.done, status.error).delay(quiet_s)
        assert expired, "done/error changed after the sequencer had settled"
        assert ctx.get(bench.bus.bus.drive_high) == 0, "a line was driven high"

    simulate(bench, clocks={"sync": clk}, testbenches=[testbench], processes=[target], timeout_s=limit_s,
             timeout_message=f"the sequencer neither finished nor failed within {limit_s} s")
    last = r.monitor.last_edge
    r.quiet_after = last is None or last <= r.t_settled
    return r


def named(device, pairs):
    return [(device, reg, value) for reg, value in pairs]


# --- the real tables against the models ------------------------------------------------------------------

def test_mt9d112_table_configures_1600x1200_rgb565():
    cam = MT9D112Model()
    r = run_sequencer(MT9D112_TABLE, [cam], limit_s=0.05)
    assert (r.done, r.error, r.code, r.entry) == (1, 0, ErrorCode.NONE, len(MT9D112_TABLE))
    assert named("mt9d112", cam.writes) == expected_writes(MT9D112_TABLE)
    # ID check, then the sequencer-command poll: the model answers "busy" twice before 0
    assert [reg for reg, _ in cam.reads] == [0x3000] + [0x3390] * (cam.cmd_busy_reads + 1)
    assert [reg for _, reg in expected_reads(MT9D112_TABLE)] == [0x3000, 0x3390]
    assert cam.sensor_config() == expected_sensor_config()
    assert cam.problems() == []
    state = cam.state()
    assert {k: state[k] for k in mt9d112_expected()} == {k: e.value for k, e in mt9d112_expected().items()}
    assert cam.commands_done == [2]
    polls = [t for t in r.monitor.transactions if "Sr" in t]
    assert len(polls) == len(cam.reads)                      # every register read uses a repeated START
    assert len(r.monitor.transactions) == len(cam.writes) + len(cam.reads)   # no retry in a clean run
    assert r.monitor.violations() == [] and r.monitor.protocol_errors == []


def test_ch7301c_table_configures_dvi_for_1080p():
    dvi = CH7301CModel()
    r = run_sequencer(CH7301C_TABLE, [dvi], limit_s=0.02)
    assert (r.done, r.error, r.entry) == (1, 0, len(CH7301C_TABLE))
    assert named("ch7301c", dvi.writes) == expected_writes(CH7301C_TABLE)
    assert dvi.reads == [(0x4A, 0x95), (0x4B, 0x17)] and r.mismatch == 0
    assert dvi.state() == {k: e.value for k, e in ch7301c_expected().items()}
    assert len(r.monitor.transactions) == len(dvi.writes) + len(dvi.reads)
    assert r.monitor.violations() == []


def test_sensor_is_not_rgb565_before_configuration():
    cfg = MT9D112Model().sensor_config()
    assert not cfg.rgb565 and (cfg.width, cfg.height) == (800, 600)


# --- faults ----------------------------------------------------------------------------------------------

def test_absent_device_nacks_address_then_error():
    dvi = CH7301CModel(address=0x75)                          # the other AS strap: nobody answers at 0x76
    r = run_sequencer(CH7301C_TABLE, [dvi], limit_s=0.02)
    assert (r.done, r.error, r.code, r.entry) == (0, 1, ErrorCode.NACK_ADDR, 0)
    assert r.monitor.transactions == [[(0x76 << 1, False)]] * (r.retries + 1)   # bounded retries
    assert dvi.writes == [] and r.quiet_after


def test_transient_address_nack_is_retried():
    dvi = CH7301CModel(nack_address=True, nack_times=2)
    r = run_sequencer(CH7301C_TABLE, [dvi], limit_s=0.02)
    assert (r.done, r.error) == (1, 0) and dvi.nacks_given == 2
    assert named("ch7301c", dvi.writes) == expected_writes(CH7301C_TABLE)


def test_persistent_nack_mid_write_stops_at_that_entry():
    dvi = CH7301CModel(nack_write_byte=1, nack_write_reg=0x34)    # NACK the data byte of 0x34
    r = run_sequencer(CH7301C_TABLE, [dvi], limit_s=0.02)
    idx = next(i for i, e in enumerate(CH7301C_TABLE.entries) if isinstance(e, Write) and e.reg == 0x34)
    assert (r.done, r.error, r.code, r.entry) == (0, 1, ErrorCode.NACK_DATA, idx)
    assert named("ch7301c", dvi.writes) == expected_prefix(CH7301C_TABLE, idx)   # nothing written after it
    assert dvi.nacks_given == r.retries + 1 and r.quiet_after


def test_transient_nack_mid_write_is_retried():
    cam = MT9D112Model(nack_write_byte=3, nack_write_reg=0x3390, nack_times=1)   # 2nd data byte, once
    r = run_sequencer(MT9D112_TABLE, [cam], limit_s=0.05)
    assert (r.done, r.error) == (1, 0) and cam.nacks_given == 1
    assert named("mt9d112", cam.writes) == expected_writes(MT9D112_TABLE)
    assert cam.sensor_config() == expected_sensor_config()


def test_clock_stretching_target():
    dvi = CH7301CModel(stretch_s=30e-6)
    r = run_sequencer(CH7301C_TABLE, [dvi], limit_s=0.02)
    assert (r.done, r.error) == (1, 0) and dvi.stretches > 10
    assert named("ch7301c", dvi.writes) == expected_writes(CH7301C_TABLE)
    assert r.monitor.maximum["tLOW"] >= 30e-6 - 1e-9 and r.monitor.violations() == []


@pytest.mark.parametrize("line", ["sda", "scl"])
def test_bus_held_low_is_stuck(line):
    dvi = CH7301CModel(**{f"hold_{line}_low": True})
    r = run_sequencer(CH7301C_TABLE, [dvi], limit_s=0.02)
    assert (r.done, r.error, r.code, r.entry) == (0, 1, ErrorCode.STUCK, 0)
    assert dvi.writes == [] and dvi.transactions == 0 and r.quiet_after
    assert r.t_settled < FAST["timeout_us"] * 1e-6 + 0.5e-3   # timeout (+ the 9-pulse bus clear for SDA)


@pytest.mark.parametrize("ids", [dict(version_id=0x4A), dict(device_id=0x18)], ids=["version", "device"])
def test_unexpected_ch7301c_id_is_shown_and_the_bring_up_goes_on(ids):
    """The CH7301C's ID bytes are Checks: another value sets ``mismatch`` (an LED) and the table completes."""
    dvi = CH7301CModel(**ids)
    r = run_sequencer(CH7301C_TABLE, [dvi], limit_s=0.02)
    assert (r.done, r.error, r.mismatch) == (1, 0, 1)
    assert named("ch7301c", dvi.writes) == expected_writes(CH7301C_TABLE)


def test_wrong_chip_version_stops_the_sensor_table():
    """The MT9D112's chip version stays a one-shot Poll: another value stops its table at that entry."""
    cam = MT9D112Model()
    cam.chip.regs[0x3000] = 0x1581
    r = run_sequencer(MT9D112_TABLE, [cam], limit_s=0.02)
    idx = next(i for i, e in enumerate(MT9D112_TABLE.entries) if isinstance(e, Poll) and e.reg == 0x3000)
    assert (r.done, r.error, r.code, r.entry) == (0, 1, ErrorCode.POLL, idx)
    assert cam.writes == [] and r.quiet_after


def test_poll_gives_up_after_its_attempts():
    table = InitTable(CH7301C, (Write(0x49, 0x01, "x"), Poll(0x49, 0x00, mask=0xFF, attempts=4, interval_us=100),
                                Write(0x49, 0xC0, "never")))
    dvi = CH7301CModel()
    r = run_sequencer(table, [dvi], limit_s=0.02)
    assert (r.error, r.code, r.entry) == (1, ErrorCode.POLL, 1)
    assert dvi.reads == [(0x49, 0x01)] * 4 and dvi.writes == [(0x49, 0x01)]


def test_waits_last_their_time():
    table = InitTable(CH7301C, (Write(0x1F, 0x80, "a"), Wait(1500, "w"), Write(0x49, 0xC0, "b")))
    dvi = CH7301CModel()
    r = run_sequencer(table, [dvi], limit_s=0.02)
    assert r.done and len(r.monitor.transactions) == 2
    assert r.monitor.maximum["tBUF"] >= 1500e-6


# --- random tables ---------------------------------------------------------------------------------------

class ScratchTarget(RegisterTarget):
    """A plain 8-bit register file at the CH7301C's address: any register takes any value (the CH7301C model
    refuses registers it does not know; these tables test the sequencer, not the part)."""

    def __init__(self, address, **faults):
        super().__init__(address, reg_bytes=1, data_bytes=1, name="scratch", **faults)
        self.regs = {}

    def write_register(self, reg, value):
        self.regs[reg] = value

    def read_register(self, reg):
        return self.regs.get(reg, 0)


_entry = st.one_of(
    st.builds(lambda r, v: Write(r, v, "random"), st.integers(0, 0x48), st.integers(0, 0xFF)),
    st.builds(lambda us: Wait(us, "random"), st.integers(0, 300)),
)


@settings(max_examples=4, deadline=None, derandomize=True, suppress_health_check=list(HealthCheck))
@given(entries=st.lists(_entry, min_size=1, max_size=5), nacks=st.integers(0, FAST["retries"]),
       nack_byte=st.integers(0, 1))
def test_random_tables_with_transient_nacks(entries, nacks, nack_byte):
    """Any table, with up to ``retries`` NACKs of a register or data byte: every write lands, in order, once."""
    table = InitTable(CH7301C, tuple(entries))
    dvi = ScratchTarget(0x76, nack_write_byte=nack_byte, nack_times=nacks)
    r = run_sequencer(table, [dvi], limit_s=0.05)
    assert (r.done, r.error) == (1, 0)
    assert named("ch7301c", dvi.writes) == expected_writes(table)
    writes = sum(isinstance(e, Write) for e in entries)
    assert len(r.monitor.transactions) == writes + (nacks if writes else 0)   # one retry per NACK


# --- cocotb on Verilator and Icarus ----------------------------------------------------------------------

def cocotb_testbench(clk_hz, **kw):
    return I2CBench({"cam": InitSequencer(MT9D112_TABLE, clk_hz=clk_hz, **kw),
                     "dvi": InitSequencer(CH7301C_TABLE, clk_hz=clk_hz, **kw)})


def run_cocotb_i2c(simulator, clk_hz, testcase=None, waves=None, **kw):
    params = dict(clk_hz=clk_hz, **kw)
    return run_cocotb(cocotb_testbench(clk_hz, **kw), name="i2c_bench", test_module="cocotb_i2c", simulator=simulator,
                      params=params, testcase=testcase, waves=waves, run_waves=i2c_bench_waves(("cam", "dvi")))


def test_cocotb_i2c(simulator):
    run_cocotb_i2c(simulator, 1_000_000, retries=3, retry_delay_us=200, timeout_us=2000)


@pytest.mark.slow
def test_cocotb_i2c_board_clock(simulator):
    """The board configuration (100 MHz, board defaults): both full tables, third-party decode, UM10204 timing."""
    run_cocotb_i2c(simulator, 100_000_000, testcase="test_third_party_decode", retries=3,
                   retry_delay_us=1000, timeout_us=25_000)
