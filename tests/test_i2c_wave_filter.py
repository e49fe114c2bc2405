"""The I2C transaction filter GTKWave runs (sim/waves/i2c_filter.py) decodes a recorded bus as two independent
references do: the project's bus monitor (sim.models.i2c.monitor.I2CBusMonitor, fed by the simulation itself, not by
the VCD) transaction by transaction, and the table's write list (sim/models/i2c/table.py) write by write.

Buses: the MT9D112 table (writes, and polls that read back after a repeated START) against the register-file
model; the CH7301C table against a target that NACKs its address (the sequencer retries, then gives up). The
recording is the VCD of Amaranth's simulator; the filter is fed from it directly, and once through GTKWave itself
(headless), which runs the program named in the save file.
"""

import pytest

from hdl.i2c_init import InitSequencer
from hdl.init_tables import CH7301C_TABLE
from sim.waves import gtkwave_check
from sim.runners.amaranth import simulate
from sim.waves.gtkw import I2CBus, Waves, changes, read_vars
from sim.models.i2c.bus import I2CBench, amaranth_target_process
from sim.models.i2c.monitor import I2CBusMonitor
from sim.models.i2c.target import I2CTarget
from sim.models.mt9d112.target import MT9D112Model
from sim.models.i2c.table import expected_writes
from sim.waves.i2c_filter import decode, transaction_text, transactions
from sim.testbench.system.setup import SystemSetup

CLK = 1_000_000


def record(table, targets, vcd, limit_s):
    """Simulate the sequencer on ``table`` against ``targets`` until done or error; VCD + save file at ``vcd``."""
    seq = InitSequencer(table, clk_hz=CLK, retries=1, retry_delay_us=50, timeout_us=500)
    bench = I2CBench({"bus": seq})
    monitor = I2CBusMonitor()

    async def bench_done(ctx):
        await ctx.changed(bench.status.bus.done, bench.status.bus.error)
        await ctx.delay(100e-6)
    bus = bench.bus.bus
    simulate(bench, clocks={"sync": CLK}, testbenches=[bench_done],
             processes=[amaranth_target_process(bus, targets, CLK, bench.cycles, monitor)], vcd=vcd,
             timeout_s=limit_s, traces=Waves(groups={"bus": [I2CBus("bus", bus.scl, bus.sda)]}))
    return monitor


def bus_levels(vcd):
    """``[(time, scl, sda)]`` of the bus in the VCD, read straight from the dump."""
    variables, _ = read_vars(vcd)
    ids = {line: next(v.ident for v in variables if v.scope[-1] == "bus_bus" and v.name.split("__")[-1] == line)
           for line in ("scl", "sda")}      # the lines of the bus resolver (sim.models.i2c.bus.OpenDrainBus)
    seen, _ = changes(vcd, set(ids.values()))
    level, out = {"scl": True, "sda": True}, []
    merged = sorted([(t, "scl", v) for t, v in seen[ids["scl"]]] + [(t, "sda", v) for t, v in seen[ids["sda"]]])
    for t, line, v in merged:
        level[line] = v != "0"
        if out and out[-1][0] == t:
            out[-1] = (t, level["scl"], level["sda"])
        else:
            out.append((t, level["scl"], level["sda"]))
    return out


def as_monitor(group):
    """A decoded transaction in the monitor's form: ``[(byte, acked) or "Sr", ...]``."""
    return ["Sr" if s.kind == "restart" else (s.value, s.ack)
            for s in group if s.kind in ("restart", "address", "data")]


def as_writes(device, group, reg_bytes, data_bytes):
    """``(device, register, value)`` of a write transaction (address byte, register bytes, data bytes)."""
    data = [s.value for s in group if s.kind == "data"]
    reg = int.from_bytes(bytes(data[:reg_bytes]), "big")
    return device, reg, int.from_bytes(bytes(data[reg_bytes:reg_bytes + data_bytes]), "big")


@pytest.fixture(scope="module")
def camera_bus(tmp_path_factory):
    table = SystemSetup.small().cam_table
    cam = MT9D112Model(boot_s=1e-6, pll_lock_s=10e-6)
    vcd = tmp_path_factory.mktemp("i2c") / "camera.vcd"
    monitor = record(table, [cam], vcd, limit_s=0.05)
    return table, cam, monitor, vcd


def test_camera_bus_decodes_as_the_monitor_and_the_golden_writes(camera_bus):
    table, cam, monitor, vcd = camera_bus
    found = transactions(decode(bus_levels(vcd)))
    assert [as_monitor(g) for _, _, g in found] == monitor.transactions
    assert len(found) == len(cam.writes) + len(cam.reads) > 10
    writes = [as_writes("mt9d112", g, 2, 2) for _, _, g in found if not any(s.kind == "restart" for s in g)]
    assert writes == expected_writes(table)
    polls = [g for _, _, g in found if any(s.kind == "restart" for s in g)]
    assert len(polls) == len(cam.reads)                            # each register read: S addr W reg Sr addr R
    assert all(transaction_text(g).startswith("3C W ") and " Sr 3C R " in transaction_text(g) for g in polls)
    assert all(not s.error for _, _, g in found for s in g)        # the controller's final NACK is no error


def test_a_nacked_address_is_decoded(tmp_path):
    vcd = tmp_path / "nack.vcd"
    monitor = record(CH7301C_TABLE, [I2CTarget(0x76, nack_address=True)], vcd, limit_s=0.05)
    found = transactions(decode(bus_levels(vcd)))
    assert [as_monitor(g) for _, _, g in found] == monitor.transactions
    assert len(found) == 2                                         # the first write and its one retry
    assert all(transaction_text(g) == "76 WN" for _, _, g in found)
    assert all(g[1].error for _, _, g in found)


@pytest.mark.skipif(not gtkwave_check.available(), reason="gtkwave or xvfb-run not installed")
def test_gtkwave_runs_the_filter_on_the_save_file(camera_bus, tmp_path):
    table, cam, monitor, vcd = camera_bus
    log = tmp_path / "filter.log"
    gtkwave_check.displayed(vcd.with_suffix(".gtkw"), env={"STEREO_I2C_FILTER_LOG": str(log)})
    lines = log.read_text().splitlines()
    direct = [f"bus {start} {transaction_text(g)}" for start, _, g in transactions(decode(bus_levels(vcd)))]
    assert lines == direct and len(lines) == len(monitor.transactions)
