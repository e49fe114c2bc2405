"""The whole system end to end on Verilator with its testbench in C++: :func:`run_verilator`.

The route of the full-size runs (``make demo``, ``stereodepth run``, the slow test, the bench). The design is
:class:`sim.testbench.system.testbench.SystemTestbench` with clock inputs, Verilated without ``--timing`` and without VPI
(:mod:`sim.runners.verilator.build`); the testbench around it is C++ (``sim/runners/verilator/testbench.h``): the four clocks at
the edge times of the cocotb in-simulator route's generators (``sync`` from time 0, its first rising edge half a
period in; the pixel clock rising when it starts; each PCLK half a period after its camera starts), each camera's
frame-period stream on its pins (the next sample at every falling PCLK edge, from word 0 again after the last),
and the CH7301C pins sampled a quarter pixel period after each pixel-clock edge.

Python keeps the models and the phases of every run (``sim/testbench/system/run_amaranth.py`` lists them): the simulation
runs in C++ until something Python must answer -- an I2C line changes (the register-file models answer at that
instant; the bus monitors see every change of the whole run), a status output a phase waits for changes, or a
time a phase set -- so nothing polls and no Python runs per clock. Each sensor's stream is made before the run by
the sensor model for the configuration the I2C init must produce (:func:`sim.models.mt9d112.config.expected_sensor_config`);
a camera starts the instant its register-file model says RGB565 and streaming, and only if that configuration is
exactly the expected one (a :class:`~sim.testbench.system.result.SystemTimeout` otherwise: the configuration guard).

The check phase is :func:`sim.testbench.system.result.check_run` on the frame :class:`sim.models.ch7301c.hdmi_sink.HdmiSink` rebuilds from
the recorded pins (with the XCLK levels checked at every sample), plus the replay check: every sample each
camera's pins carried at its rising PCLK edges equals the model's stream.
"""

import time

import numpy as np

from hdl.system import CAMERAS, DISPLAY_LATENCY, I2C_BUSES
from sim.models.ch7301c.hdmi_sink import HdmiSink
from sim.models.i2c.monitor import I2CBusMonitor
from sim.models.mt9d112.config import expected_sensor_config
from sim.replay.sensor import pack_stream
from sim.testbench.system.cocotb_routes import period_ps
from sim.testbench.system.result import SystemResult, SystemTimeout, check_run
from sim.runners.verilator.build import build
from sim.runners.verilator.ctestbench import RECORDED, CTestbench
from sim.runners.verilator.recording import feed_sink

__all__ = ["run_verilator", "VerilatorRun"]

_PS = 1e-12
#: The testbench's clocks and the ports they drive.
CLOCK_PORTS = {"sync": ("clocks", "sync"), "pix": ("clocks", "pix"), "cam_a": ("clocks", "cam_a"),
               "cam_b": ("clocks", "cam_b")}
CH7301C_PINS = tuple(("ch7301c", p) for p in ("data", "hsync", "vsync", "de", "xclk_p", "xclk_n"))


def camera_pins(c):
    return tuple((f"cam_{c}", p) for p in ("data", "lv", "fv"))


class _Buses:
    """The three I2C buses' Python side: the register-file targets and a monitor per bus, serviced whenever the
    simulation stops (a watched line changed, or a target's deadline came)."""

    def __init__(self, testbench, models):
        self.h, self.models = testbench, models
        self.monitors = {b: I2CBusMonitor() for b in I2C_BUSES}
        self.levels = {b: (1, 1) for b in I2C_BUSES}
        self.pulls = {b: (False, False) for b in I2C_BUSES}
        self.lines = [("bus", b, line) for b in I2C_BUSES for line in ("scl", "sda")]
        self.wakes = 0
        for b in I2C_BUSES:
            testbench[("bus", b, "ext_scl_low")] = testbench[("bus", b, "ext_sda_low")] = 0

    def deadline_ps(self):
        """The earliest time a target asked to be woken at (clock stretching), or None."""
        times = [d for ts in self.models.values() for d in (t.deadline() for t in ts) if d is not None]
        return round(min(times) / _PS) + 1 if times else None

    def service(self):
        h, now = self.h, self.h.now_ps * _PS
        self.wakes += 1
        for b in I2C_BUSES:
            levels = (h[("bus", b, "scl")], h[("bus", b, "sda")])
            targets = self.models[b]
            due = any(t.deadline() is not None and t.deadline() <= now + 1e-12 for t in targets)
            if levels == self.levels[b] and not due:
                continue
            self.levels[b] = levels
            self.monitors[b].observe(now, *levels)
            for t in targets:
                t.update(levels[0], levels[1], now)
            pulls = (any(t.scl_low for t in targets), any(t.sda_low for t in targets))
            if pulls != self.pulls[b]:
                h[("bus", b, "ext_scl_low")], h[("bus", b, "ext_sda_low")] = int(pulls[0]), int(pulls[1])
                self.pulls[b] = pulls


class VerilatorRun:
    """One run (see the module docstring). :meth:`run` simulates and returns the status; the testbench, the streams,
    the recording and the models stay here for the check and for the raw model (:mod:`bench.raw_model`)."""

    def __init__(self, setup, left, right, *, keep_stimulus=False, progress=None, deadline_s=None):
        self.setup = setup
        self.images = {"a": setup.fit(left), "b": setup.fit(right)}
        self.build = build(setup)
        self.expected_config = expected_sensor_config(setup.geometry)
        self.words = self.streams()
        self.periods = {"sync": period_ps(setup.sys_hz), "pix": period_ps(setup.timing.pixel_hz, 4),
                        **{f"cam_{c}": period_ps(setup.camera_pclk_hz(c)) for c in CAMERAS}}
        self.clocks = setup.timing.clocks_per_frame + DISPLAY_LATENCY + 2
        self.deadline_ps = round((deadline_s or setup.deadline_s()) / _PS)
        self.report = progress or (lambda stage, fraction: None)
        self.total_ps = setup.expected_sim_time_s() / _PS
        self.h = CTestbench(self.build, log=keep_stimulus)
        self.models = setup.i2c_models()
        self.buses = _Buses(self.h, self.models)
        # Room for every sample the cameras send in a run: the replay check reads them all.
        self.seen = {c: np.zeros(2 * len(self.words[c]), dtype=np.uint16) for c in CAMERAS}
        self.recording = np.zeros(self.clocks, dtype=np.uint32)
        self.started, self.activity = {}, {c: -1 for c in CAMERAS}
        self.status, self.stage = {}, "i2c"
        for clock, port in CLOCK_PORTS.items():
            self.h.bind_clock(clock, port, self.periods[clock] // 2)
        for i, c in enumerate(CAMERAS):
            self.h.bind_camera(i, camera_pins(c), self.words[c], self.seen[c])
        self.h.bind_recorder(CH7301C_PINS, self.recording)

    def streams(self):
        """Each camera's replayed words (uint16 ``{fv, lv, d}``): one frame period of its image, repeated."""
        return {c: pack_stream(self.setup.sensor(self.expected_config, seed=seed).frame(self.images[c]))
                .astype(np.uint16) for seed, c in enumerate(CAMERAS)}

    # --- waiting without polling ------------------------------------------------------------------------------

    def _wake(self):
        """Whatever stopped the simulation: the buses answer, a camera configured by now starts."""
        self.buses.service()
        for i, c in enumerate(CAMERAS):
            if c not in self.started:
                self._maybe_start_camera(i, c)
        self.report(self.stage, min(0.999, self.h.now_ps / self.total_ps))

    def _maybe_start_camera(self, i, c):
        model = self.models[f"cam_{c}"][0]
        activity = len(model.writes) + len(model.reads)       # its configuration only changes with these
        if activity == self.activity[c]:
            return
        self.activity[c] = activity
        config = model.sensor_config()
        if not config.rgb565:
            return
        if config != self.expected_config:
            raise SystemTimeout(f"camera {c}: the I2C init configured {config}; the replayed stream is the sensor "
                                f"model's for {self.expected_config}")
        now = self.h.now_ps
        self.started[c] = now
        self.h.start_camera(i)
        phase = round(self.setup.cam_phase_s.get(c, 0.0) / _PS)
        self.h.start_clock(f"cam_{c}", now + phase + self.periods[f"cam_{c}"] // 2)

    def _until(self, what, done, watch=(), timeout_ps=None, limit_ps=None):
        """Simulate until ``done()`` (asked whenever the simulation stops: a port of ``watch`` or an I2C line
        changed, a target's deadline, every simulated millisecond), until ``limit_ps``, or until the recorder is
        full; a :class:`SystemTimeout` after ``timeout_ps``. Returns why the last run stopped."""
        h = self.h
        deadline = h.now_ps + timeout_ps if timeout_ps is not None else None
        h.watch([*self.buses.lines, *watch])
        reason = None
        while not done():
            stops = (deadline, limit_ps, self.buses.deadline_ps(), h.now_ps + 1_000_000_000)
            reason = h.run(min(t for t in stops if t is not None))
            self._wake()
            if reason == RECORDED or (limit_ps is not None and h.now_ps >= limit_ps):
                break
            if deadline is not None and h.now_ps >= deadline and not done():
                raise SystemTimeout(f"{what} did not happen within {timeout_ps * 1e-9:.3f} ms of simulated time")
        return reason

    def _advance(self, ps):
        target = self.h.now_ps + ps
        self._until("time", lambda: self.h.now_ps >= target, limit_ps=target)

    # --- the phases -----------------------------------------------------------------------------------------

    def run(self):
        wall0 = time.perf_counter()
        cpu0 = time.process_time()
        self.phase_wall = {}
        self.reset()
        if self.init():
            self.phase_wall["init"] = time.perf_counter() - wall0
            self.capture()
            self.phase_wall["capture"] = time.perf_counter() - wall0
            self.display()
        self.status["wall_s"] = self.phase_wall["display"] = time.perf_counter() - wall0
        self.status["cpu_s"] = time.process_time() - cpu0
        self.status["phase_wall_s"] = self.phase_wall
        self.status["i2c_wakes"], self.status["evals"] = self.buses.wakes, self.h.evals
        return self.status

    def reset(self):
        h = self.h
        h["button"], h[("panel", "sw")] = 1, 0
        for c in CAMERAS:
            for pin in camera_pins(c):
                h[pin] = 0
        h.start_clock("sync", self.periods["sync"] // 2)
        if not self.setup.pix_after_init:
            h.start_clock("pix", 0)
        self._advance(50_000)
        h["button"] = 0
        self._until("clock lock", lambda: h["locked"] == 1, ["locked"], timeout_ps=self.deadline_ps)
        if not self.setup.pix_after_init:
            self.set_switches()

    def init(self):
        """The I2C init; then the pixel clock and the switches. False if a bus failed (the caller reports it)."""
        h, status = self.h, self.status
        flags = [("init", b, k) for b in I2C_BUSES for k in ("done", "error")]
        self._until("I2C initialisation", lambda: all(h[("init", b, "done")] or h[("init", b, "error")]
                                                      for b in I2C_BUSES), flags, timeout_ps=self.deadline_ps)
        for b in I2C_BUSES:
            status[f"{b}_init_done"] = bool(h[("init", b, "done")])
            status[f"{b}_init_error"] = bool(h[("init", b, "error")])
        status["t_init_s"] = h.now_ps * _PS
        if not all(status[f"{b}_init_done"] for b in I2C_BUSES):
            return False
        if self.setup.pix_after_init:
            h.start_clock("pix", h.now_ps)
            self.set_switches()
        return True

    def set_switches(self):
        self._advance(200_000)                      # pix out of reset: 2 synchroniser stages
        for word in self.setup.switch_words():
            self.h[("panel", "sw")] = word
            self._advance(30 * self.periods["pix"])

    def capture(self):
        h = self.h
        self.stage = "capture"
        counts = [("capture", f"cam_{c}", "frame_count") for c in CAMERAS]
        counts0 = {n: h[n] for n in counts}
        self._until("a complete frame from both cameras", lambda: all(h[n] != counts0[n] for n in counts), counts,
                    timeout_ps=self.deadline_ps)
        for c in CAMERAS:
            self.status[f"cam_{c}_frame_ok"] = bool(h[("capture", f"cam_{c}", "frame_ok")])
        self.status["t_captured_s"] = h.now_ps * _PS

    def display(self):
        h, status = self.h, self.status
        self.stage = "display"
        last = [h["frame_start"]]

        def frame_start_rose():
            rose, last[0] = h["frame_start"] and not last[0], h["frame_start"]
            return rose
        self._until("a display frame start", frame_start_rose, ["frame_start"], timeout_ps=self.deadline_ps)
        # Start outside an hsync pulse (the pins lag the raster by DISPLAY_LATENCY clocks, which can put them
        # inside the previous line's pulse): the sink must see whole pulses.
        idle = 0 if self.setup.timing.hsync_positive else 1
        self._until("hsync idle", lambda: h[("ch7301c", "hsync")] == idle, [("ch7301c", "hsync")],
                    timeout_ps=self.deadline_ps)
        status["disparity"] = h[("settings", "disparity")]
        bits = h[("settings", "rectification")] & 0x7F
        status["rectification"] = bits - 0x80 if bits & 0x40 else bits          # two's complement
        status["auto_rectification"] = {n: h[("rectification", n)] for n in ("auto", "confident", "held", "locked")}
        h.record(self.clocks)
        if self._until("the display frame", lambda: False, timeout_ps=self.deadline_ps) != RECORDED:
            raise SystemTimeout("the recorder did not fill")
        status["recorded_clocks"] = h.recorded
        status["leds"] = h[("panel", "leds")]
        status["drive_high"] = {b: bool(h[("bus", b, "drive_high")]) for b in I2C_BUSES}
        status["t_end_s"] = h.now_ps * _PS
        self.report("done", 1.0)

    # --- after the simulation ----------------------------------------------------------------------------------

    def replay_checks(self):
        """Every sample each camera's pins carried at its rising PCLK edges, against the model's stream."""
        out = {}
        for i, c in enumerate(CAMERAS):
            n = self.h.camera_seen(i)
            want = np.resize(self.words[c], n)
            out[c] = {"samples": int(n), "mismatches": int(np.count_nonzero(self.seen[c][:n] != want))}
        return out

    def sink(self):
        """A fresh :class:`~sim.models.ch7301c.hdmi_sink.HdmiSink` fed with the recorded pins."""
        return feed_sink(self.recording[:self.h.recorded], HdmiSink(self.setup.timing))

    def check(self):
        """The check phase; returns ``(frame, golden, sink)``."""
        sink = self.sink()
        frame, golden = check_run(self.status, self.setup, self.images["a"], self.images["b"], sink, self.models,
                                  self.buses.monitors, after_s=0.0)
        self.status["replay_checks"] = self.replay_checks()
        return frame, golden, sink


def run_verilator(left, right, setup, *, progress=None, deadline_s=None, keep_stimulus=False):
    """Simulate the pair ``left``/``right`` (RGB arrays, any size: fitted to the sensor) through the whole system on
    Verilator along this route (see the module docstring). Returns a :class:`~sim.testbench.system.result.SystemResult`
    (with ``sink``, ``models``, ``monitors``; ``figures["run"]`` is the :class:`VerilatorRun`).

    ``progress(stage, fraction)`` is called as the run goes on. Raises :class:`~sim.testbench.system.result.SystemTimeout`
    when a phase does not complete within ``deadline_s`` of simulated time (default: ``setup.deadline_s()``) or the
    I2C init configures a sensor otherwise than expected. ``keep_stimulus`` keeps the stimulus log for the raw
    model (:func:`bench.raw_model.run_raw`)."""
    t0 = time.perf_counter()
    run = VerilatorRun(setup, left, right, keep_stimulus=keep_stimulus, progress=progress, deadline_s=deadline_s)
    t_run = time.perf_counter()
    status = run.run()
    t_check = time.perf_counter()
    frame, golden, sink = run.check()
    figures = {"wall_s": status["wall_s"], "cpu_s": status["cpu_s"], "setup_s": t_run - t0,
               "check_s": time.perf_counter() - t_check, "t_init_s": status.get("t_init_s"),
               "t_captured_s": status.get("t_captured_s"), "run": run}
    return SystemResult(frame=frame, golden=golden, status=status, figures=figures, sink=sink, models=run.models,
                        monitors=run.buses.monitors)
