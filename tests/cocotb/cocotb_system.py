"""cocotb end-to-end test of the whole system, on Verilator and Icarus: stereo pair in, HDMI frame out, compared
with the golden model.

The design is ``sim.system_bench.SystemBench`` or, for the fast route, ``sim.system_fast.FastSystemBench`` (the
same bench plus behavioural Verilog sensor-replay and bus-recorder modules). Driven from pytest through
``sim.cocotb_runner.run_cocotb`` (tests/test_system.py; ``sim/system_cocotb.py`` builds the parameters) and used
by the bench and the ``run``/``demo`` commands. Parameters (``sim.cocotb_runner.test_params()``):

* ``setup``: the :class:`sim.system_setup.SystemSetup` as ``{"preset": "small"|"full", **overrides}``;
* ``left``, ``right``: image files (any size: fitted to the sensor as the sensor model does);
* ``out_dir``: where ``frame.npy``, ``golden.npy``, ``result.json`` (and with ``save_samples`` the sink's
  per-clock samples) go;
* ``sensor``: ``"python"`` (``sim.mt9d112.drive_cocotb`` per PCLK) or ``"replay"`` (fast bench only);
* ``sink``: ``"python"`` (``sim.hdmi_sink.CocotbSink``), ``"recorder"`` (fast bench only) or ``"both"`` (both
  sample the same pins; the test fails unless every per-clock sample is identical);
* ``check_replay``: with ``sensor="replay"``, the number of PCLK samples of each camera's pins to read back at
  the rising edges and compare with the model's stream (0: none);
* ``progress_file``: optional, ``"<done> <total>"`` for a progress bar in the parent process.

Scenario (the same as ``sim/system_amaranth.py``): reset button, clock lock, I2C init of the three buses by the
RTL against the register-file models (``sim.i2c_devices``), the switches, both sensor models streaming once
their register files say RGB565 + streaming, and one display frame sampled from a frame start after both
cameras have completed a frame. Clocks: ``clk`` 100 MHz, ``pix_clk`` 6736 ps (148.456 MHz: the nearest period
to 148.5 MHz that is a multiple of 4 ps, which the quarter-period sampling needs) from time 0 or from the end of
the I2C init (``pix_after_init``), ``cam_<c>_clk`` from the sensor models (80 MHz, 12.5 ns, camera B 3.1 ns
later).
"""

import json
import os
import time
from pathlib import Path

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, RisingEdge, Timer
from cocotb.utils import get_sim_time

from golden.stereo_pair import load_pair
from hdl.system import CAMERAS, DISPLAY_LATENCY, I2C_BUSES
from sim.cocotb_runner import test_params
from sim.hdmi_sink import CocotbSink, HdmiSink
from sim.i2c_devices import I2CBusMonitor, start_cocotb_targets
from sim.mt9d112 import drive_cocotb
from sim.system_cocotb import setup_from_spec

PARAMS = test_params()
PIX_PERIOD_PS = 6736
SYS_PERIOD_PS = 10_000


def _progress(path, done, total, stage=""):
    if path:
        tmp = f"{path}.tmp"
        with open(tmp, "w") as f:
            f.write(f"{done} {total} {stage}\n")
        Path(tmp).replace(path)


def expected_sim_time_s(setup):
    """A rough estimate of the run's simulated time (for the progress bar only): the I2C init (table waits and
    bus time), one sensor frame period, one and a half display frames."""
    from hdl.init_tables import Poll, Wait
    table = setup.cam_table
    init = sum(e.us for e in table.entries if isinstance(e, Wait)) * 1e-6
    init += sum(e.interval_us for e in table.entries if isinstance(e, Poll)) * 3e-6
    init += len(table.entries) * 50 / setup.i2c_hz
    g, t = setup.geometry, setup.timing
    sensor = (g.height + 10) * (2 * g.width + 256) / setup.pclk_hz
    return init + sensor + 1.5 * t.clocks_per_frame / t.pixel_hz


class _StageProgress:
    """Writes ``"<done> 1000 <stage>"`` to the progress file as simulated time passes (every 50 us of it)."""

    def __init__(self, path, total_s):
        self.path, self.total_s, self.stage, self.running = path, total_s, "I2C-init", bool(path)

    async def run(self):
        while self.running:
            await Timer(50, unit="us")
            done = min(999, int(1000 * get_sim_time("ns") * 1e-9 / self.total_s))
            _progress(self.path, done, 1000, self.stage)


async def _wait(cond, what, timeout_s, step_ns=1000):
    start = get_sim_time("ns")
    while not cond():
        if (get_sim_time("ns") - start) * 1e-9 > timeout_s:
            raise AssertionError(f"{what} did not happen within {timeout_s * 1e3:.3f} ms of simulated time")
        await Timer(step_ns, unit="ns")


class _Recording:
    """Wraps a sink's ``sample`` to keep every per-clock sample."""

    def __init__(self, sink):
        self.samples = []
        inner = sink.sample

        def sample(hsync, vsync, de, first, second):
            self.samples.append((bool(hsync), bool(vsync), bool(de), first, second))
            inner(hsync, vsync, de, first, second)
        sink.sample = sample


@cocotb.test()
async def end_to_end(dut):
    setup = setup_from_spec(PARAMS["setup"])
    out_dir = Path(PARAMS["out_dir"])
    out_dir.mkdir(parents=True, exist_ok=True)
    progress_file = PARAMS.get("progress_file")
    sensor_mode = PARAMS.get("sensor", "python")
    sink_mode = PARAMS.get("sink", "python")
    fast = hasattr(dut, "use_replay")
    if (sensor_mode == "replay" or sink_mode in ("recorder", "both")) and not fast:
        raise AssertionError("the replay sensor and the bus recorder need sim.system_fast.FastSystemBench")
    g = setup.geometry
    left, right = load_pair(PARAMS["left"], PARAMS["right"], g.width, g.height)
    images = {"a": left, "b": right}
    wall0 = time.perf_counter()
    phase_wall = {}

    # Stimulus state before time advances.
    dut.button.value = 1
    dut.sw.value = 0
    for c in CAMERAS:
        for pin in ("data", "lv", "fv"):
            getattr(dut, f"cam_{c}_{pin}").value = 0
    if fast:
        # FastSystemBench generates its clocks inside the simulator; enables start them.
        if sensor_mode != "replay":
            raise AssertionError("the fast bench runs its cameras from the replay modules")
        dut.use_replay.value = 1
        dut.rec_enable.value = 0
        dut.rec_limit.value = 0
        for c in CAMERAS:
            for pin in ("load", "run", "length", "en"):
                getattr(dut, f"cam_{c}_{pin}").value = 0
        dut.pix_en.value = 0
        dut.rec_clk_en.value = 0
        dut.sync_en.value = 1
    else:
        for c in CAMERAS:
            getattr(dut, f"cam_{c}_clk").value = 0
        Clock(dut.clk, SYS_PERIOD_PS, unit="ps").start()
        dut.pix_clk.value = 0
        pix_clock = Clock(dut.pix_clk, PIX_PERIOD_PS, unit="ps")

    async def start_pix():
        if fast:
            dut.pix_en.value = 1
        else:
            pix_clock.start(start_high=True)
    if not setup.pix_after_init:
        await start_pix()

    models = setup.i2c_models()
    monitors = {bus: I2CBusMonitor() for bus in I2C_BUSES}
    for bus in I2C_BUSES:
        start_cocotb_targets(dut, bus, models[bus], monitors[bus])

    replay_checks = {}

    async def camera(c, seed):
        model = models[f"cam_{c}"][0]
        sensor = setup.sensor(model, seed=seed)
        while not model.sensor_config().rgb565:
            await Timer(1000, unit="ns")
        phase = setup.cam_phase_s.get(c, 0.0)
        if sensor_mode == "python":
            await drive_cocotb(
                sensor.frames([images[c]] * 1_000_000, tail=False, max_idle=10),
                clk=getattr(dut, f"cam_{c}_clk"), data=getattr(dut, f"cam_{c}_data"),
                lv=getattr(dut, f"cam_{c}_lv"), fv=getattr(dut, f"cam_{c}_fv"),
                pclk_hz=setup.pclk_hz, start_delay=phase)
            return
        # Replay: the model's frame period (blanking + frame) as a ROM, repeated.
        stream = sensor.frame(images[c])
        from sim.system_fast import stream_to_hex
        n = stream_to_hex(stream, Path(os.getcwd()) / f"cam_{c}.hex")
        getattr(dut, f"cam_{c}_length").value = n
        load = getattr(dut, f"cam_{c}_load")
        load.value = 1
        await Timer(1, unit="ns")
        load.value = 0
        (Path(os.getcwd()) / f"cam_{c}.hex").unlink(missing_ok=True)    # loaded into the ROM (tens of MB)
        if phase:
            await Timer(round(phase * 1e12), unit="ps")
        clk = getattr(dut, f"cam_{c}_clk")
        getattr(dut, f"cam_{c}_run").value = 1
        getattr(dut, f"cam_{c}_en").value = 1       # PCLK (generated in the simulator) starts low
        check = int(PARAMS.get("check_replay", 0))
        if check:
            check = min(check, n)
            seen = getattr(dut, f"cam_{c}_seen")
            got = []
            # The replay puts sample 0 on the pins at the first falling edge (one PCLK later than the Python
            # driver, which sets it before starting the clock): compare from the rising edge after that.
            await FallingEdge(clk)
            for _ in range(check):
                await RisingEdge(clk)
                v = int(seen.value)
                got.append(((v >> 9) & 1, (v >> 8) & 1, v & 0xFF))
            want = list(zip(stream.fv[:check].tolist(), stream.lv[:check].tolist(), stream.data[:check].tolist()))
            replay_checks[c] = {"samples": check,
                                "mismatches": sum(1 for a, b in zip(got, want) if a != b)}

    for seed, c in enumerate(CAMERAS):
        cocotb.start_soon(camera(c, seed))

    status = {"sensor": sensor_mode, "sink": sink_mode}
    progress = _StageProgress(progress_file, expected_sim_time_s(setup))
    cocotb.start_soon(progress.run())
    await Timer(50, unit="ns")
    dut.button.value = 0
    await _wait(lambda: int(dut.locked.value) == 1, "clock lock", 1e-3, step_ns=20)

    async def set_switches():
        await Timer(200, unit="ns")                 # pix out of reset: 2 synchroniser stages
        for word in setup.switch_words():
            dut.sw.value = word
            await Timer(30 * PIX_PERIOD_PS, unit="ps")
    if not setup.pix_after_init:
        await set_switches()

    from sim.system_amaranth import _deadline_s
    deadline = _deadline_s(setup)

    def init_finished():
        return all(int(getattr(dut, f"{b}_init_done").value) or int(getattr(dut, f"{b}_init_error").value)
                   for b in I2C_BUSES)
    await _wait(init_finished, "I2C initialisation", deadline, step_ns=2000)
    for b in I2C_BUSES:
        status[f"{b}_init_done"] = bool(int(getattr(dut, f"{b}_init_done").value))
        status[f"{b}_init_error"] = bool(int(getattr(dut, f"{b}_init_error").value))
    status["t_init_s"] = get_sim_time("ns") * 1e-9
    phase_wall["init"] = time.perf_counter() - wall0
    progress.stage = "capture"
    assert all(status[f"{b}_init_done"] for b in I2C_BUSES), f"I2C initialisation failed: {status}"
    if setup.pix_after_init:
        await start_pix()
        await set_switches()

    counts0 = {c: int(getattr(dut, f"cam_{c}_frame_count").value) for c in CAMERAS}
    await _wait(lambda: all(int(getattr(dut, f"cam_{c}_frame_count").value) != counts0[c] for c in CAMERAS),
                "a complete frame from both cameras", deadline, step_ns=20_000 if g.width > 100 else 1000)
    for c in CAMERAS:
        status[f"cam_{c}_frame_ok"] = bool(int(getattr(dut, f"cam_{c}_frame_ok").value))
    status["t_captured_s"] = get_sim_time("ns") * 1e-9
    phase_wall["capture"] = time.perf_counter() - wall0
    progress.stage = "display"

    if fast and sink_mode in ("recorder", "both"):
        dut.rec_clk_en.value = 1                    # the recorder's clock, from the next pixel clock on
    await RisingEdge(dut.frame_start)
    # Start sampling outside an hsync pulse (the pins lag the raster by DISPLAY_LATENCY clocks, which can put
    # them inside the previous line's pulse): the sink must see whole pulses.
    h_idle = 0 if setup.timing.hsync_positive else 1
    while int(dut.hsync.value) != h_idle:
        await RisingEdge(dut.pix_clk)
    status["disparity"] = int(dut.disparity.value)
    status["rectification"] = int(dut.rectification.value)
    clocks = setup.timing.clocks_per_frame + DISPLAY_LATENCY + 2
    sink = HdmiSink(setup.timing)
    rec_sink = None
    if sink_mode in ("recorder", "both"):
        # Start the recorder on the same XCLK rising edge as CocotbSink starts on (it awaits the next one).
        async def enable_recorder():
            await RisingEdge(dut.xclk_p)
            dut.rec_enable.value = 1
        dut.rec_limit.value = clocks
        cocotb.start_soon(enable_recorder())
    python_samples = None
    if sink_mode in ("python", "both"):
        recording = _Recording(sink) if sink_mode == "both" else None
        await CocotbSink(dut, sink, period_ps=PIX_PERIOD_PS).run(clocks)
        python_samples = recording.samples if recording else None
    if sink_mode in ("recorder", "both"):
        if not int(dut.rec_done.value):
            await RisingEdge(dut.rec_done)
        await Timer(1, unit="ns")
        from sim.system_fast import read_recording, replay_recording
        records = read_recording(Path(os.getcwd()) / "bus.txt")
        (Path(os.getcwd()) / "bus.txt").unlink()                        # read (tens of MB at 1080p)
        rec_sink = HdmiSink(setup.timing)
        replay_recording(records, rec_sink)
        status["recorded_clocks"] = len(records)
        if sink_mode == "recorder":
            sink = rec_sink
        else:
            rec_samples = [(bool(h & 4), bool(h & 2), bool(h & 1), a, b) for h, _, a, b in records]
            status["sink_vs_recorder_mismatches"] = sum(1 for x, y in zip(python_samples, rec_samples) if x != y) \
                + abs(len(python_samples) - len(rec_samples))
            status["recorder_violations"] = [str(v) for v in rec_sink.violations]
    status["leds"] = int(dut.leds.value)
    status["drive_high"] = {b: bool(int(getattr(dut, f"{b}_drive_high").value)) for b in I2C_BUSES}
    status["t_end_s"] = get_sim_time("ns") * 1e-9
    status["wall_s"] = time.perf_counter() - wall0
    phase_wall["display"] = status["wall_s"]
    status["phase_wall_s"] = phase_wall
    status["replay_checks"] = replay_checks
    progress.running = False
    _progress(progress_file, 1000, 1000, "done")

    golden = setup.golden_frame(left, right)
    frame = sink.frames[0] if sink.frames else None
    np.save(out_dir / "golden.npy", golden)
    if frame is not None:
        np.save(out_dir / "frame.npy", frame)
    status["violations"] = [str(v) for v in sink.violations]
    status["mt9d112_problems"] = {b: models[b][0].problems() for b in ("cam_a", "cam_b")}
    status["sensor_config"] = {b: repr(models[b][0].sensor_config()) for b in ("cam_a", "cam_b")}
    dvi = models["dvi"][0].dvi_config()
    status["dvi_config"] = dict(dvi.__dict__)
    # Protocol errors after time 0 (at time 0 the monitor sees the lines resolve from their pre-evaluation value).
    status["i2c_protocol_errors"] = {b: [str(e) for e in monitors[b].protocol_errors if e[0] > 0]
                                     for b in I2C_BUSES}
    status["i2c_transactions"] = {b: len(monitors[b].transactions) for b in I2C_BUSES}
    status["mismatched_pixels"] = None if frame is None else int(np.any(frame != golden, axis=-1).sum())
    (out_dir / "result.json").write_text(json.dumps(status, indent=1, default=str))

    assert frame is not None, "the sink rebuilt no frame"
    assert not sink.violations, f"HDMI timing violations: {status['violations'][:5]}"
    assert status["mismatched_pixels"] == 0, f"{status['mismatched_pixels']} pixels differ from the golden frame"
    if sink_mode == "both":
        assert status["sink_vs_recorder_mismatches"] == 0, "the recorder and the Python sink saw different pins"
        assert not status["recorder_violations"]
    for c, check in replay_checks.items():
        assert check["mismatches"] == 0, f"camera {c}: replayed pins differ from the model's stream"


@cocotb.test(skip="probe_us" not in PARAMS)   # only the bench (bench/bench_system.py) asks for the probe
async def rate_probe(dut):
    """For the bench: run every clock of the fast bench (cameras replaying a stream of pseudo-random bytes,
    I2C idle) for ``probe_us`` of simulated time and write the wall time to ``out_dir/probe.json``."""
    if not hasattr(dut, "use_replay"):
        raise AssertionError("the rate probe needs sim.system_fast.FastSystemBench")
    setup = setup_from_spec(PARAMS["setup"])
    probe_us = float(PARAMS.get("probe_us", 100))
    out_dir = Path(PARAMS["out_dir"])
    out_dir.mkdir(parents=True, exist_ok=True)
    n = 100_000
    rng = np.random.default_rng(0)
    words = rng.integers(0, 1024, n)
    for c in CAMERAS:
        Path(os.getcwd(), f"cam_{c}.hex").write_text("\n".join(f"{w:03x}" for w in words) + "\n")
        getattr(dut, f"cam_{c}_length").value = n
        getattr(dut, f"cam_{c}_load").value = 1
    dut.use_replay.value = 1
    dut.rec_enable.value = 0
    dut.rec_clk_en.value = 0
    dut.button.value = 0
    dut.sw.value = 0
    await Timer(1, unit="ns")
    for c in CAMERAS:
        getattr(dut, f"cam_{c}_load").value = 0
        getattr(dut, f"cam_{c}_run").value = 1
    dut.sync_en.value = 1
    dut.pix_en.value = 1
    dut.cam_a_en.value = 1
    dut.cam_b_en.value = 1
    await Timer(10, unit="us")                      # out of reset
    wall = time.perf_counter()
    await Timer(round(probe_us * 1000), unit="ns")
    wall = time.perf_counter() - wall
    (out_dir / "probe.json").write_text(json.dumps({"probe_us": probe_us, "wall_s": wall,
                                                    "pixel_hz": setup.timing.pixel_hz}))
