"""The whole-system scenario inside a cocotb simulation (Verilator or Icarus), in phases.

``sim/testbench/system/system_cocotb.py`` runs :func:`end_to_end` (and, for the benchmark, :func:`rate_probe`) on
the design :func:`sim.testbench.system.run_cocotb.run_cocotb_system` exported. The phases up to the display
frames are :func:`sim.testbench.system.phases.before_display` (reset, I2C init, capture), the scenario their
primitives in cocotb triggers (a wait polls every :data:`POLL_NS` step of what it waits for); the **display** is the
scenario's own, because the in-simulator route's pin recorder writes one stretch of display frames: the CH7301C
pins sampled from a display frame start, a still pair's ``max_frames`` display frames, a sequence's frames up to its
settled frame (:class:`~sim.testbench.system.result.DisplayFrames`); then the **check** (what the models and the
buses saw, :func:`sim.testbench.system.result.record_parts`; the display frames are judged by the run,
:mod:`sim.system.verdict`). The route (``sim/testbench/system/cocotb_routes.py``) drives the clocks, the cameras
and the display; a coroutine notes each capture's frame starts and ends and the design's skew meter as they change.

Parameters (``sim.runners.cocotb.test_params()``): ``setup`` (``SystemSetup.to_spec()``), ``route``
(``CocotbRoute.spec()``), ``sequence`` (an ``.npz`` of ``left`` and ``right``, N x H x W x 3, fitted to the
sensor), ``still`` (the one pair sent for ever), ``max_frames``, ``out_dir`` (``frames.npz``: the display frames,
their start times and the frames captured before each; ``result.json``: the status), ``progress_file`` (optional:
``"<done> 1000 <stage>"`` as simulated time passes), ``mig_latency`` (the DDR2 build's read latency, or None: drawn).

The DDR2 build: the MIG model's read latency is drawn per run (:func:`sim.models.mig.draw_latency`, as on every
backend; ``status["mig_latency"]``) and set before time advances; a coroutine watches the model's violation code
and, on the clock it leaves 0, writes ``{"violation": [code, addr, cycle], "t_ps": now}`` to ``out_dir``'s
:data:`~sim.testbench.system.run_cocotb.VIOLATION_FILE` and stops the run with the model's one-line message.
"""

import json
import time
from pathlib import Path

import cocotb
import numpy as np
from cocotb.triggers import First, ReadOnly, RisingEdge, Timer
from cocotb.utils import get_sim_time

from hdl.system import CAMERAS, DISPLAY_LATENCY, I2C_BUSES
from sim.models.mig import READ_LATENCY_RANGE, MIGProtocolViolation, Violation, draw_latency
from sim.runners.cocotb import TopPorts
from sim.models.i2c.bus import start_cocotb_targets
from sim.models.i2c.monitor import I2CBusMonitor
from sim.testbench.system.cocotb_routes import period_ps, route_from_spec
from sim.testbench.system.phases import CAPTURE, INIT, LOCK, PIX_RESET_S, PUBLISH_S, before_display, mark
from sim.testbench.system.result import DisplayFrames, SystemTimeout, record_parts
from sim.testbench.system.setup import SystemSetup

__all__ = ["end_to_end", "rate_probe"]

#: The scenario's polling step while it waits (``until``), by what it waits for (the capture: 20 us above 100
#: pixels wide).
POLL_NS = {LOCK: 20, INIT: 2000, CAPTURE: 1000}


def _now_s():
    return get_sim_time("ns") * 1e-9


def _write_progress(path, done, stage):
    if path:
        tmp = Path(f"{path}.tmp")
        tmp.write_text(f"{done} 1000 {stage}\n")
        tmp.replace(path)


class _Run:
    """One run in progress (see the module docstring for the phases)."""

    def __init__(self, dut, params):
        self.ports, self.params = TopPorts(dut), params
        self.setup = SystemSetup.from_spec(params["setup"])
        self.route = route_from_spec(params["route"])
        self.out_dir = Path(params["out_dir"])
        self.progress_file = params.get("progress_file")
        self.still, self.max_frames = bool(params["still"]), int(params.get("max_frames", 1))
        with np.load(params["sequence"]) as npz:
            self.images = {"a": list(npz["left"]), "b": list(npz["right"])}
        self.deadline = self.setup.deadline_s()
        self.status = {"route": self.route.spec()}
        self.wall0 = time.perf_counter()
        self.stage, self.running = "i2c", True
        self.models = self.setup.i2c_models()
        self.monitors = {bus: I2CBusMonitor() for bus in I2C_BUSES}
        self.replay_checks = {}
        sent = None if self.still else {c: len(self.images[c]) for c in CAMERAS}
        self.frames = DisplayFrames(self.setup, CAMERAS, sent)
        self.shown = []

    async def write_progress(self):
        """Writes the progress file every 50 us of simulated time."""
        total = self.setup.expected_sim_time_s()
        while self.running and self.progress_file:
            await Timer(50, unit="us")
            _write_progress(self.progress_file, min(999, int(1000 * _now_s() / total)), self.stage)

    async def camera(self, c, seed):
        model = self.models[f"cam_{c}"][0]
        while not model.sensor_config().rgb565:
            await Timer(1000, unit="ns")
        sensor = self.setup.sensor(model, seed=seed)
        check = await self.route.camera(self.ports, c, sensor, self.images[c], self.setup.cam_phase_s.get(c, 0.0),
                                        still=self.still, setup=self.setup)
        if check is not None:
            self.replay_checks[c] = check

    async def watch_captures(self):
        """Note each capture's frame starts and ends and the skew meter's measurements as they change."""
        ports = self.ports
        captures = [getattr(ports.capture, f"cam_{c}") for c in CAMERAS]
        signals = [s for status in captures for s in (status.in_frame, status.frame_count)] + [ports.skew.count]
        last = [int(s.value) for s in signals]
        while True:
            await First(*(s.value_change for s in signals))
            await ReadOnly()                        # every register of this edge updated (the meter's together)
            values, now = [int(s.value) for s in signals], _now_s()
            for i, c in enumerate(CAMERAS):
                started, done = values[2 * i] and not last[2 * i], values[2 * i + 1] != last[2 * i + 1]
                self.frames.note_capture(c, now, started, done)
            if values[-1] != last[-1]:
                self.frames.note_skew(now, ports.skew.skew.value.to_signed(), bool(int(ports.skew.aligned.value)))
            last = values

    async def watch_violation(self):
        """The DDR2 build: stop the run on the MIG model's first violation (see the module docstring)."""
        from sim.testbench.system.run_cocotb import VIOLATION_FILE
        report = self.ports.memory.violation
        while not (report.code.value.is_resolvable and int(report.code.value) != Violation.NONE.value):
            await report.code.value_change
        await ReadOnly()
        seen = [int(report.code.value), int(report.addr.value), int(report.cycle.value)]
        self.status["mig_violation"] = seen
        (self.out_dir / VIOLATION_FILE).write_text(json.dumps({"violation": seen, "t_ps": get_sim_time("ps")}))
        raise MIGProtocolViolation(*seen)

    def settings(self):
        ports = self.ports
        return {"disparity": int(ports.settings.disparity.value),
                "rectification": ports.settings.rectification.value.to_signed(),      # two's complement
                "auto_rectification": {n: int(getattr(ports.rectification, n).value)
                                       for n in ("auto", "confident", "held", "locked")}}

    def start(self):
        """Before time advances: the route's idle inputs and clocks, the I2C targets, the cameras (each starts
        once configured), the progress file and the captures' watch."""
        self.route.start(self.ports, self.setup)
        if self.setup.memory == "ddr2":
            latency = self.params.get("mig_latency")
            self.status["mig_latency"] = draw_latency(0, READ_LATENCY_RANGE) if latency is None else int(latency)
            self.ports.memory.latency.value = self.status["mig_latency"]
            cocotb.start_soon(self.watch_violation())
        for bus in I2C_BUSES:
            start_cocotb_targets(getattr(self.ports.bus, bus), self.models[bus], self.monitors[bus])
        for seed, c in enumerate(CAMERAS):
            cocotb.start_soon(self.camera(c, seed))
        cocotb.start_soon(self.write_progress())
        cocotb.start_soon(self.watch_captures())

    # --- the primitives of the phases before the display (sim.testbench.system.phases) -------------------------

    def button(self, pressed):
        self.ports.button.value = int(pressed)
        if pressed:
            self.ports.panel.sw.value = 0

    async def start_pix(self):
        await self.route.start_pix(self.ports, self.setup)

    async def pix_out_of_reset(self):
        await Timer(round(PIX_RESET_S * 1e12), unit="ps")

    async def advance(self, seconds):
        await Timer(round(seconds * 1e12), unit="ps")

    async def advance_pix(self, clocks):
        await Timer(clocks * period_ps(self.setup.timing.pixel_hz, 4), unit="ps")

    async def until(self, what, condition, timeout_s):
        """Poll ``condition`` every step :data:`POLL_NS` gives for ``what`` (1 us otherwise)."""
        step_ns = POLL_NS.get(what, 1000)
        if what == CAPTURE and self.setup.geometry.width > 100:
            step_ns = 20_000
        start = _now_s()
        while not condition():
            if _now_s() - start > timeout_s:
                raise SystemTimeout(f"{what} did not happen within {timeout_s * 1e3:.3f} ms of simulated time")
            await Timer(step_ns, unit="ns")

    def set_switches(self, word):
        self.ports.panel.sw.value = word

    def now(self):
        return _now_s()

    def locked(self):
        return int(self.ports.locked.value) == 1

    def init_flags(self):
        return {b: (int(getattr(self.ports.init, b).done.value), int(getattr(self.ports.init, b).error.value))
                for b in I2C_BUSES}

    def frame_counts(self):
        return {c: int(getattr(self.ports.capture, f"cam_{c}").frame_count.value) for c in CAMERAS}

    def frames_ok(self):
        return {c: int(getattr(self.ports.capture, f"cam_{c}").frame_ok.value) for c in CAMERAS}

    def progress(self, stage):
        self.stage = stage

    # --- the display phase: the route records one stretch of display frames -----------------------------------

    async def display(self):
        ports, setup = self.ports, self.setup
        self.stage = "display"
        self.route.before_display(ports)
        if setup.memory == "ddr2":
            await Timer(round(PUBLISH_S * 1e12), unit="ps")
        await RisingEdge(ports.frame_start)
        # Start sampling outside an hsync pulse (the pins lag the raster by DISPLAY_LATENCY clocks, which can put
        # them inside the previous line's pulse): the sink must see whole pulses.
        h_idle = 0 if setup.timing.hsync_positive else 1
        while int(ports.ch7301c.hsync.value) != h_idle:
            await RisingEdge(ports.clocks.pix)
        settings = self.settings()
        self.status.update(settings)
        cpf = setup.timing.clocks_per_frame
        self.frames.start(_now_s(), cpf / setup.timing.pixel_hz)
        keep = self.shown.append
        if self.still:
            clocks = self.max_frames * cpf + DISPLAY_LATENCY + 2
            self.sink = await self.route.display(ports, setup, clocks, self.status)
            for frame in self.sink.frames:
                self.frames.completed(keep, frame, settings)
        else:
            self.sink = await self.route.display_frames(ports, setup, self.frames, keep, self.settings)
        self.status["violations"] = [str(v) for v in self.sink.violations]
        self.status["leds"] = int(ports.panel.leds.value)
        if setup.memory == "ddr2":                 # display reads the frame store refused (hdl/system.py)
            self.status["display_missed"] = int(ports.display_missed.value)
        self.status["drive_high"] = {b: bool(int(getattr(ports.bus, b).drive_high.value)) for b in I2C_BUSES}
        self.status["t_end_s"] = _now_s()
        self.status["wall_s"] = time.perf_counter() - self.wall0
        mark(self.status, "display", self.wall0)
        self.stage = "done"
        self.status["replay_checks"] = self.replay_checks
        self.status.update(self.frames.record())
        self.running = False
        _write_progress(self.progress_file, 1000, "done")

    def check(self):
        """What the parts and the buses saw; the display frames and the status written; the route's own checks
        asserted (the recorder against the Python sink, the replayed pins against the model's stream)."""
        status = self.status
        # Protocol errors after time 0 (at time 0 the monitor sees the lines resolve from their pre-evaluation value).
        record_parts(status, self.models, self.monitors, after_s=0.0)
        self.out_dir.mkdir(parents=True, exist_ok=True)
        shown = self.shown
        empty = np.zeros((0, self.setup.timing.v_active, self.setup.timing.h_active, 3), np.uint8)
        np.savez(self.out_dir / "frames.npz", frames=np.stack([f.frame for f in shown]) if shown else empty,
                 t_start_s=np.array([f.t_start_s for f in shown]),
                 captured=np.array([[f.captured[c] for c in CAMERAS] for f in shown]).reshape(-1, len(CAMERAS)))
        (self.out_dir / "result.json").write_text(json.dumps(status, indent=1, default=str))
        if "sink_vs_recorder_mismatches" in status:
            assert status["sink_vs_recorder_mismatches"] == 0, "the recorder and the Python sink saw different pins"
            assert not status["recorder_violations"]
        for c, check in self.replay_checks.items():
            assert check["mismatches"] == 0, f"camera {c}: replayed pins differ from the model's stream"


async def end_to_end(dut, params):
    """The whole scenario, phase by phase."""
    run = _Run(dut, params)
    run.start()
    if not await before_display(run, run.setup, still=run.still, deadline_s=run.deadline, status=run.status,
                                wall0=run.wall0):
        raise AssertionError(f"I2C initialisation failed: {run.status}")
    await run.display()
    run.check()


async def rate_probe(dut, params):
    """For the benchmark: run every clock of the in-simulator route's design (cameras replaying pseudo-random words,
    I2C idle) for ``probe_us`` of simulated time and write the wall time to ``out_dir/probe.json``."""
    from sim.replay.sensor import write_hex
    ports = TopPorts(dut)
    setup = SystemSetup.from_spec(params["setup"])
    probe_us = float(params.get("probe_us", 100))
    out_dir = Path(params["out_dir"])
    out_dir.mkdir(parents=True, exist_ok=True)
    words = np.random.default_rng(0).integers(0, 1024, 100_000)
    route = route_from_spec(params["route"])
    route.start(ports, setup)
    for c in CAMERAS:
        replay = getattr(ports.replay, f"cam_{c}")
        replay.length.value = write_hex(words, Path.cwd() / f"cam_{c}.hex")
        replay.load.value = 1
    ports.button.value = 0
    ports.panel.sw.value = 0
    await Timer(1, unit="ns")
    for c in CAMERAS:
        getattr(ports.replay, f"cam_{c}").load.value = 0
        getattr(ports.replay, f"cam_{c}").run.value = 1
        getattr(ports.clock_en, f"cam_{c}").value = 1
    await route.start_pix(ports, setup)
    await Timer(10, unit="us")                      # out of reset
    wall = time.perf_counter()
    await Timer(round(probe_us * 1000), unit="ns")
    wall = time.perf_counter() - wall
    (out_dir / "probe.json").write_text(json.dumps({"probe_us": probe_us, "wall_s": wall,
                                                    "pixel_hz": setup.timing.pixel_hz}))
