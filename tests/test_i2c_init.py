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
from hdl.i2c_init import ErrorCode, InitSequencer, Phase
from hdl.init_tables import CH7301C_TABLE, MT9D112_TABLE, InitTable, Poll, Wait, Write, CH7301C, MT9D112
from sim.runners.amaranth import simulate
from sim.runners.cocotb import run_cocotb
from sim.models.i2c.bus import I2CBench, amaranth_target_process, bench_buses, i2c_bench_waves
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


class TimedMonitor(I2CBusMonitor):
    """An :class:`I2CBusMonitor` that also keeps the times of the STARTs (SDA falling while SCL is high) and of
    the SCL falling edges (both made by the master alone)."""

    def __init__(self):
        super().__init__()
        self.starts, self.scl_falls, self._was = [], [], (1, 1)

    def observe(self, t, scl, sda):
        if scl and self._was[0] and self._was[1] and not sda:
            self.starts.append(t)
        if self._was[0] and not scl:
            self.scl_falls.append(t)
        self._was = (scl, sda)
        super().observe(t, scl, sda)


def run_sequencer(table, targets, *, limit_s, quiet_s=0.002, clk=CLK, shared=None, **kw):
    """Simulate ``InitSequencer(table)`` with ``targets`` on its bus until it reports done or error, then
    ``quiet_s`` longer (to see that nothing else happens). Fails if neither comes within ``limit_s``. With
    ``shared`` (a list of target lists, one per bus) the sequencer plays the table on all those buses at once:
    ``r.monitors`` holds each bus's monitor (``r.monitor`` the first), ``r.nacked`` the sequencer's ``nacked``. With
    ``table`` a sequence of ``Phase``, the run ends when the last phase ends and ``r.phases`` holds each phase's
    ``(done, error, error_code, entry, mismatch)``."""
    params = {**FAST, **kw}
    per_bus = [targets] if shared is None else shared
    seq = InitSequencer(table, clk_hz=clk, buses=len(per_bus), **params) if shared else \
        InitSequencer(table, clk_hz=clk, **params)
    bench = I2CBench({"bus": seq})
    r = Run()
    r.monitors = [TimedMonitor() for _ in per_bus]
    r.monitor = r.monitors[0]
    r.retries = params["retries"]
    names = bench_buses("bus", seq)
    processes = [amaranth_target_process(getattr(bench.bus, b), ts, clk, bench.cycles, mon)
                 for b, ts, mon in zip(names, per_bus, r.monitors)]
    phases = () if isinstance(table, InitTable) else table
    status = getattr(bench.status.bus, phases[-1].name) if phases else bench.status.bus

    async def testbench(ctx):
        done = error = 0
        while not (done or error):
            done, error, cycles = await ctx.changed(status.done, status.error).sample(bench.cycles)
            assert not (done and error), "done and error together"
        r.t_settled = cycles / clk
        r.done, r.error = done, error
        r.code, r.entry = ctx.get(status.error_code), ctx.get(status.entry)
        r.mismatch = ctx.get(status.mismatch)
        r.nacked = ctx.get(seq.nacked) if shared else None
        r.phases = {}
        for p in phases:
            ps = getattr(bench.status.bus, p.name)
            r.phases[p.name] = tuple(ctx.get(getattr(ps, k)) for k in ("done", "error", "error_code", "entry",
                                                                         "mismatch"))
        # afterwards: the status must not change and the bus must stay quiet
        _, _, expired = await ctx.changed(status.done, status.error).delay(quiet_s)
        assert expired, "done/error changed after the sequencer had settled"
        for b in names:
            assert ctx.get(getattr(bench.bus, b).drive_high) == 0, "a line was driven high"

    simulate(bench, clocks={"sync": clk}, testbenches=[testbench], processes=processes, timeout_s=limit_s,
             timeout_message=f"the sequencer neither finished nor failed within {limit_s} s")
    lasts = [mon.last_edge for mon in r.monitors]
    r.quiet_after = all(last is None or last <= r.t_settled for last in lasts)
    return r


def named(device, pairs):
    return [(device, reg, value) for reg, value in pairs]


# --- the real tables against the models ------------------------------------------------------------------

def test_mt9d112_table_configures_both_cameras_in_step():
    """One sequencer plays the MT9D112 table on both camera buses (as the system does): both sensors end up at
    1600 x 1200 RGB565, the two buses carry the master's bytes at the same clocks (so the start-of-streaming write
    reaches both at once), and a sensor that answers the sequencer-command poll "busy" longer holds the poll
    until both read 0."""
    cams = [MT9D112Model(), MT9D112Model(cmd_busy_reads=4)]
    r = run_sequencer(MT9D112_TABLE, None, shared=[[cams[0]], [cams[1]]], limit_s=0.05)
    assert (r.done, r.error, r.code, r.entry, r.mismatch) == (1, 0, ErrorCode.NONE, len(MT9D112_TABLE), 0)
    assert [reg for _, reg in expected_reads(MT9D112_TABLE)] == [0x3000, 0x3390]
    for cam, mon in zip(cams, r.monitors):
        assert named("mt9d112", cam.writes) == expected_writes(MT9D112_TABLE)
        # ID check, then the sequencer-command poll until both sensors answer 0 (B says "busy" the longer)
        assert [reg for reg, _ in cam.reads] == [0x3000] + [0x3390] * (cams[1].cmd_busy_reads + 1)
        assert cam.sensor_config() == expected_sensor_config()
        assert cam.problems() == []
        state = cam.state()
        assert {k: state[k] for k in mt9d112_expected()} == {k: e.value for k, e in mt9d112_expected().items()}
        assert cam.commands_done == [2]
        polls = [t for t in mon.transactions if "Sr" in t]
        assert len(polls) == len(cam.reads)                      # every register read uses a repeated START
        assert len(mon.transactions) == len(cam.writes) + len(cam.reads)   # no retry in a clean run
        assert mon.violations() == [] and mon.protocol_errors == []
    a, b = r.monitors
    sent = lambda mon: [t[:t.index("Sr") + 2] if "Sr" in t else t for t in mon.transactions]   # noqa: E731
    assert sent(a) == sent(b)                                    # the master's bytes (the answers differ)
    assert a.starts == b.starts and a.scl_falls == b.scl_falls and len(a.starts) > 40


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


# --- one sequencer for both camera buses (broadcast) -------------------------------------------------------

#: The MT9D112 table's start: the boot wait, the chip-version check and the first writes (short runs).
MT9D112_START = InitTable(MT9D112, MT9D112_TABLE.entries[:6])


def test_shared_nack_from_one_camera_is_retried_then_an_error():
    """Camera B alone does not answer (another address): every attempt is a NACK on both buses, the transaction is
    repeated on both, then the shared init stops with a NACK error naming bus B."""
    cams = [MT9D112Model(), MT9D112Model(address=0x3D)]
    r = run_sequencer(MT9D112_TABLE, None, shared=[[cams[0]], [cams[1]]], limit_s=0.05)
    idx = next(i for i, e in enumerate(MT9D112_TABLE.entries) if isinstance(e, Poll))
    assert (r.done, r.error, r.code, r.entry, r.nacked) == (0, 1, ErrorCode.NACK_ADDR, idx, 0b10)
    address = MT9D112_TABLE.device.address << 1
    assert r.monitors[0].transactions == [[(address, True)]] * (r.retries + 1)    # A acknowledged each attempt
    assert r.monitors[1].transactions == [[(address, False)]] * (r.retries + 1)
    assert cams[0].reads == [] and cams[0].writes == [] and r.quiet_after


def test_shared_transient_nack_on_one_bus_is_retried_on_both():
    cams = [MT9D112Model(), MT9D112Model(nack_write_byte=3, nack_write_reg=0x3214, nack_times=1)]
    r = run_sequencer(MT9D112_START, None, shared=[[cams[0]], [cams[1]]], limit_s=0.05)
    assert (r.done, r.error, r.nacked) == (1, 0, 0b10) and cams[1].nacks_given == 1
    # B's NACKed write is repeated, on both buses: A takes that write twice (harmless), B once.
    assert named("mt9d112", cams[1].writes) == expected_writes(MT9D112_START)
    once = [w for i, w in enumerate(cams[0].writes) if i == 0 or w != cams[0].writes[i - 1]]
    assert named("mt9d112", once) == expected_writes(MT9D112_START) and len(cams[0].writes) == len(once) + 1
    assert len(r.monitors[0].transactions) == len(cams[0].writes) + len(cams[0].reads)


def test_shared_clock_stretch_on_one_bus_holds_both():
    cams = [MT9D112Model(), MT9D112Model(stretch_s=30e-6)]
    r = run_sequencer(MT9D112_START, None, shared=[[cams[0]], [cams[1]]], limit_s=0.05)
    assert (r.done, r.error) == (1, 0) and cams[1].stretches > 10 and cams[0].stretches == 0
    a, b = r.monitors
    # B holds its SCL low; the master waits for it before it counts the high time, so bus A's high phase lasts
    # the stretch too, and the master pulls both SCLs low again at the same clock.
    assert b.maximum["tLOW"] >= 30e-6 - 1e-9 and a.maximum["tHIGH"] >= 30e-6 - 1e-9
    assert a.scl_falls == b.scl_falls and a.starts == b.starts
    assert a.violations() == [] and b.violations() == []


def test_shared_read_must_match_on_both_buses():
    """The chip-version check passes only when both sensors have the version: B's other version stops the
    shared table there (the AND and the OR of the two reads both have to match)."""
    cams = [MT9D112Model(), MT9D112Model()]
    cams[1].chip.regs[0x3000] = 0x1581
    r = run_sequencer(MT9D112_TABLE, None, shared=[[cams[0]], [cams[1]]], limit_s=0.02)
    idx = next(i for i, e in enumerate(MT9D112_TABLE.entries) if isinstance(e, Poll) and e.reg == 0x3000)
    assert (r.done, r.error, r.code, r.entry) == (0, 1, ErrorCode.POLL, idx)
    assert cams[0].writes == [] and cams[1].writes == []


# --- one sequencer for several tables, each on its own buses (phases) --------------------------------------

#: As the system plays them: the CH7301C's table on bus 2, then the MT9D112 table's start on buses 0 and 1.
PHASES = (Phase("dvi", CH7301C_TABLE, (2,)), Phase("cams", MT9D112_START, (0, 1)))


def test_phases_play_each_table_on_its_buses():
    cams, dvi = [MT9D112Model(), MT9D112Model()], CH7301CModel()
    r = run_sequencer(PHASES, None, shared=[[cams[0]], [cams[1]], [dvi]], limit_s=0.05)
    assert r.phases == {"dvi": (1, 0, ErrorCode.NONE, len(CH7301C_TABLE), 0),
                        "cams": (1, 0, ErrorCode.NONE, len(MT9D112_START), 0)}
    assert named("ch7301c", dvi.writes) == expected_writes(CH7301C_TABLE)
    assert dvi.state() == {k: e.value for k, e in ch7301c_expected().items()}
    for cam in cams:
        assert named("mt9d112", cam.writes) == expected_writes(MT9D112_START)
    a, b, d = r.monitors
    # each bus carries its own table only, the DVI's first
    assert len(d.transactions) == len(dvi.writes) + len(dvi.reads)
    assert len(a.transactions) == len(cams[0].writes) + len(cams[0].reads) and a.starts == b.starts
    assert d.last_edge < a.starts[0]
    assert all(mon.violations() == [] for mon in r.monitors)


def test_phase_error_ends_that_phase_only():
    """An absent CH7301C (another address strap) stops its table with NACK_ADDR at entry 0; the cameras' table
    still runs to the end."""
    cams, dvi = [MT9D112Model(), MT9D112Model()], CH7301CModel(address=0x75)
    r = run_sequencer(PHASES, None, shared=[[cams[0]], [cams[1]], [dvi]], limit_s=0.05)
    assert r.phases == {"dvi": (0, 1, ErrorCode.NACK_ADDR, 0, 0),
                        "cams": (1, 0, ErrorCode.NONE, len(MT9D112_START), 0)}
    assert r.monitors[2].transactions == [[(0x76 << 1, False)]] * (r.retries + 1)
    for cam in cams:
        assert named("mt9d112", cam.writes) == expected_writes(MT9D112_START)


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
