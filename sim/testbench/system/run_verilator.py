"""The whole system on Verilator with its testbench in C++: :class:`VerilatorRun`, the Verilator backend's driver.

The route of the full-size runs (``make demo``, ``stereodepth run``, the slow tests, the bench). The design is
:class:`sim.testbench.system.testbench.SystemTestbench` with clock inputs, Verilated without ``--timing`` and without
VPI (:mod:`sim.runners.verilator.build`); the testbench around it is C++ (``sim/runners/verilator/testbench.h``):
the four clocks at the edge times of the cocotb in-simulator route's generators (``sync`` from time 0, its first
rising edge half a period in; the pixel clock rising when it starts; each PCLK half a period after its camera
starts) and, in the DDR2 build, MIG's ``clk0`` for ``mem`` (8 ns, from time 0 like ``sync``), each camera's stream
on its pins (the next sample at every falling PCLK edge, from word 0 again after the last), and the CH7301C pins
sampled a quarter pixel period after each pixel-clock edge.

Each camera's stream is made before the run by the sensor model for the configuration the I2C init must produce
(:func:`sim.models.mt9d112.config.expected_sensor_config`): for a still pair (``sequence.still``) one frame period
of its images, repeated for ever; for a sequence the frame periods of its images one after the other (each shaped
by the sequence's ``faults``), then FV low for the rest of the run (the sensors stop: so the last display frame
shows the last pair on buffers no capture writes any more). A camera starts the instant its register-file model
says RGB565 and streaming, and only if that configuration is exactly the expected one (a
:class:`~sim.testbench.system.result.SystemTimeout` otherwise: the configuration guard).

The DDR2 build's MIG model (:class:`sim.models.mig.MIGModel`, its storage in Verilog) gets the run's read latency
at power-up (drawn per run, :func:`sim.models.mig.draw_latency`, as on every backend; ``status["mig_latency"]``),
and its violation code is one of the watched status outputs: the run stops with the model's one-line message
(:class:`sim.models.mig.MIGProtocolViolation`) at the instant the code leaves 0.

Python keeps the models and runs the phases (:func:`sim.testbench.system.phases.phases`: reset, I2C init, capture,
display frames), the driver's primitives plain calls (the coroutine never suspends,
:func:`~sim.testbench.system.phases.run_to_end`): the simulation runs in C++ until something Python must answer --
an I2C line changes (the register-file models answer at that instant; the bus monitors see every change of the whole
run), a status output changes (a phase waits for it; the captures' frame starts and ends are noted all along, with
the design's skew meter), or a time a phase set -- so nothing polls and no Python runs per clock. Each display frame
period of the pins is recorded in one chunk and fed to the phases' HDMI sink; after each, the switch words
``switch_changes`` gives for that count are scheduled.

The check phase of the driver: what the models and the bus monitors saw
(:func:`sim.testbench.system.result.record_parts`) and the replay check (every sample each camera's pins carried
at its rising PCLK edges equals the model's stream); the display frames' verdict is the run's
(:mod:`sim.system.verdict`).
"""

import time

import numpy as np

from hdl.system import CAMERAS, DISPLAY_LATENCY, I2C_BUSES
from sim.models.mig import READ_LATENCY_RANGE, MIGProtocolViolation, Violation, draw_latency
from sim.models.i2c.monitor import I2CBusMonitor
from sim.models.mt9d112.config import expected_sensor_config
from sim.models.mt9d112.sensor import SensorStream
from sim.replay.sensor import pack_stream
from sim.testbench.system.cocotb_routes import period_ps
from sim.testbench.system.phases import PIX_RESET_S, display_limit, phases, run_to_end
from sim.testbench.system.result import DisplayFrames, sent_frames, SystemTimeout, record_parts
from sim.runners.verilator.build import build
from sim.runners.verilator.ctestbench import RECORDED, CTestbench
from sim.runners.verilator.recording import feed_sink
from spec.memory import MIG

__all__ = ["VerilatorRun", "camera_pins", "CH7301C_PINS"]

_PS = 1e-12
#: The testbench's clocks and the ports they drive (``mem``: the DDR2 build's).
CLOCK_PORTS = {"sync": ("clocks", "sync"), "pix": ("clocks", "pix"), "cam_a": ("clocks", "cam_a"),
               "cam_b": ("clocks", "cam_b"), "mem": ("clocks", "mem")}
#: The MIG model's ports in the DDR2 build.
MIG_LATENCY, MIG_VIOLATION = ("memory", "latency"), tuple(("memory", "violation", k) for k in ("code", "addr", "cycle"))
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
    """One run of ``sequence`` (see the module docstring). :meth:`run` simulates and returns the status; the
    testbench, the streams, the recording and the models stay here for the check and for the raw model
    (:mod:`bench.raw_model`, with ``keep_stimulus``). ``on_frame(DisplayFrame)`` receives each display frame (a
    still pair's run ends when it returns True); ``progress(stage, fraction)``; ``switch_changes``: ``{display
    frames recorded: [SW words]}`` set mid-stream (:meth:`switch_plan`); ``mig_latency``: the DDR2 build's read
    latency in clk0 clocks (default drawn, see the module docstring; one outside the model's range is a harness
    violation the model reports at ``phy_init_done``)."""

    def __init__(self, setup, sequence, *, on_frame=None, progress=None, deadline_s=None, keep_stimulus=False,
                 switch_changes=None, max_frames=1, mig_latency=None):
        self.setup, self.sequence = setup, sequence
        self.still = bool(getattr(sequence, "still", False))
        self.on_frame = on_frame or (lambda frame: None)
        self.max_frames = max_frames
        self.switch_changes, self.pending_switches = switch_changes or {}, []
        self.build = build(setup)
        self.expected_config = expected_sensor_config(setup.geometry)
        self.words = self.streams()
        self.ddr2 = setup.memory == "ddr2"
        self.mig_latency = (draw_latency(0, READ_LATENCY_RANGE) if mig_latency is None else mig_latency) \
            if self.ddr2 else None
        self.periods = {"sync": period_ps(setup.sys_hz), "pix": period_ps(setup.timing.pixel_hz, 4),
                        **{f"cam_{c}": period_ps(setup.camera_pclk_hz(c)) for c in CAMERAS},
                        **({"mem": period_ps(MIG.CLK0_HZ)} if self.ddr2 else {})}
        self.frame_clocks = setup.timing.clocks_per_frame
        self.deadline_s = deadline_s or setup.deadline_s()
        self.deadline_ps = round(self.deadline_s / _PS)
        self.report = progress or (lambda stage, fraction: None)
        tail_s = 0 if self.still else len(self.words["a"]) / setup.pclk_hz
        self.total_ps = (setup.expected_sim_time_s() + tail_s) / _PS
        self.h = CTestbench(self.build, log=keep_stimulus)
        self.models = setup.i2c_models()
        self.buses = _Buses(self.h, self.models)
        # Room for every sample the cameras send in a run: the replay check reads them all.
        self.seen = {c: np.zeros(2 * len(self.words[c]), dtype=np.uint16) for c in CAMERAS}
        # The first chunk holds a display frame and the pins' latency: the sink completes frame k in chunk k.
        self.recording = np.zeros(self.frame_clocks + DISPLAY_LATENCY + 2, dtype=np.uint32)
        self.started, self.activity = {}, {c: -1 for c in CAMERAS}
        self.status, self.stage, self.powered, self.chunks, self.sink = {}, "i2c", False, 0, None
        self.frames = DisplayFrames(setup, CAMERAS, sent_frames(sequence, CAMERAS))
        self.last = {c: (0, 0) for c in CAMERAS}
        self.skew_count = 0
        for clock in self.periods:
            self.h.bind_clock(clock, CLOCK_PORTS[clock], self.periods[clock] // 2)
        for i, c in enumerate(CAMERAS):
            self.h.bind_camera(i, camera_pins(c), self.words[c], self.seen[c])
        self.h.bind_recorder(CH7301C_PINS, self.recording)

    def streams(self):
        """Each camera's replayed words (uint16 ``{fv, lv, d}``), see the module docstring."""
        words = {}
        tail_s = 4 * self.setup.timing.clocks_per_frame / self.setup.timing.pixel_hz
        for seed, c in enumerate(CAMERAS):
            sensor = self.setup.sensor(self.expected_config, seed=seed)
            images = [self.setup.fit(image) for image in self.sequence.images(c)]
            if self.still:
                words[c] = pack_stream(sensor.frame(images[0])).astype(np.uint16)
                continue
            chunks = [sensor.blank(sensor.timing.v_blank_lines + self.setup.geometry.height) if fault == "drop"
                      else sensor.frame(image, fault)
                      for image, fault in zip(images, self.sequence.camera_faults(c))]
            line = sensor.timing.line_time(self.setup.geometry.width)
            chunks.append(sensor.blank(max(1, round(tail_s * self.setup.pclk_hz / line))))
            words[c] = pack_stream(SensorStream.concat(chunks)).astype(np.uint16)
        return words

    # --- waiting without polling ------------------------------------------------------------------------------

    def _status_ports(self):
        return [("capture", f"cam_{c}", k) for c in CAMERAS for k in ("in_frame", "frame_count")] + \
            [("skew", "count"), "locked"] + [("init", b, k) for b in I2C_BUSES for k in ("done", "error")] + \
            ([MIG_VIOLATION[0]] if self.ddr2 else [])

    def _wake(self):
        """Whatever stopped the simulation: the MIG model's violation stops the run, the buses answer, a camera
        configured by now starts, the captures' status changes are noted."""
        if self.ddr2 and self.h[MIG_VIOLATION[0]] != Violation.NONE.value:
            self.status["mig_violation"] = [self.h[port] for port in MIG_VIOLATION]
            raise MIGProtocolViolation(*self.status["mig_violation"])
        self.buses.service()
        for i, c in enumerate(CAMERAS):
            if c not in self.started:
                self._maybe_start_camera(i, c)
        self._note()
        self.report(self.stage, min(0.999, self.h.now_ps / self.total_ps))

    def _note(self):
        """The captures' frame starts and ends and the skew meter's measurements since the last wake."""
        h, now = self.h, self.h.now_ps * _PS
        for c in CAMERAS:
            in_frame, count = h[("capture", f"cam_{c}", "in_frame")], h[("capture", f"cam_{c}", "frame_count")]
            self.frames.note_capture(c, now, in_frame and not self.last[c][0], count != self.last[c][1])
            self.last[c] = (in_frame, count)
        count = h[("skew", "count")]
        if count != self.skew_count:
            self.skew_count = count
            self.frames.note_skew(now, h.signed(("skew", "skew")), bool(h[("skew", "aligned")]))

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
        """Simulate until ``done()`` (asked whenever the simulation stops: a port of ``watch``, a capture status
        or an I2C line changed, a target's deadline, a scheduled switch word, every simulated millisecond), until
        ``limit_ps``, or until the recorder is full; a :class:`SystemTimeout` after ``timeout_ps``. Returns why
        the last run stopped."""
        h = self.h
        deadline = h.now_ps + timeout_ps if timeout_ps is not None else None
        h.watch([*self.buses.lines, *watch, *self._status_ports()])
        reason = None
        while not done():
            stops = (deadline, limit_ps, self.buses.deadline_ps(), self._switch_events(),
                     h.now_ps + 1_000_000_000)
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

    # --- the primitives of the phases (sim.testbench.system.phases) ---------------------------------------------

    def run(self):
        """Simulate the phases; returns the status."""
        wall0 = time.perf_counter()
        cpu0 = time.process_time()
        deadline_s = self.deadline_s
        self.sink = run_to_end(phases(self, self.setup, still=self.still, frames=self.frames, on_frame=self.on_frame,
                                      max_frames=self.max_frames, deadline_s=deadline_s,
                                      limit_frames=display_limit(self.setup, self.sequence, self.max_frames,
                                                                 deadline_s),
                                      status=self.status))
        self.status["wall_s"] = time.perf_counter() - wall0
        self.status["cpu_s"] = time.process_time() - cpu0
        self.status["i2c_wakes"], self.status["evals"] = self.buses.wakes, self.h.evals
        return self.status

    def button(self, pressed):
        """The reset button; its first press powers the board up: the switches and the camera pins at 0, the
        ``sync`` clock started (and in the DDR2 build ``mem``, with the MIG model's read latency)."""
        h = self.h
        h["button"] = int(pressed)
        if pressed and not self.powered:
            self.powered = True
            h[("panel", "sw")] = 0
            for c in CAMERAS:
                for pin in camera_pins(c):
                    h[pin] = 0
            h.start_clock("sync", self.periods["sync"] // 2)
            if self.ddr2:
                h[MIG_LATENCY] = self.mig_latency
                self.status["mig_latency"] = self.mig_latency
                h.start_clock("mem", self.periods["mem"] // 2)

    async def start_pix(self):
        self.h.start_clock("pix", self.h.now_ps)

    async def pix_out_of_reset(self):
        self._advance(round(PIX_RESET_S / _PS))

    async def advance(self, seconds):
        self._advance(round(seconds / _PS))

    async def advance_pix(self, clocks):
        self._advance(clocks * self.periods["pix"])

    async def until(self, what, condition, timeout_s):
        self._until(what, condition, timeout_ps=round(timeout_s / _PS))

    def set_switches(self, word):
        self.h[("panel", "sw")] = word

    def now(self):
        return self.h.now_ps * _PS

    def locked(self):
        return self.h["locked"] == 1

    def init_flags(self):
        return {b: (self.h[("init", b, "done")], self.h[("init", b, "error")]) for b in I2C_BUSES}

    def frame_counts(self):
        return {c: self.h[("capture", f"cam_{c}", "frame_count")] for c in CAMERAS}

    def frames_ok(self):
        return {c: self.h[("capture", f"cam_{c}", "frame_ok")] for c in CAMERAS}

    def settings(self):
        """The switch settings and the automatic rectification's state the design shows now."""
        h = self.h
        bits = h[("settings", "rectification")] & 0x7F
        return {"disparity": h[("settings", "disparity")],
                "rectification": bits - 0x80 if bits & 0x40 else bits,          # two's complement
                "auto_rectification": {n: h[("rectification", n)] for n in ("auto", "confident", "held", "locked")}}

    def panel(self):
        h = self.h
        out = {"leds": h[("panel", "leds")], "drive_high": {b: bool(h[("bus", b, "drive_high")]) for b in I2C_BUSES}}
        if self.ddr2:                               # display reads the frame store refused (hdl/system.py)
            out["display_missed"] = h[("display_missed",)]
        return out

    def progress(self, stage):
        self.stage = stage
        self.report(stage, 1.0 if stage == "done" else min(0.999, self.h.now_ps / self.total_ps))

    async def display_frame_start(self):
        h = self.h
        last = [h["frame_start"]]

        def frame_start_rose():
            rose, last[0] = h["frame_start"] and not last[0], h["frame_start"]
            return rose
        self._until("a display frame start", frame_start_rose, ["frame_start"], timeout_ps=self.deadline_ps)
        idle = 0 if self.setup.timing.hsync_positive else 1
        self._until("hsync idle", lambda: h[("ch7301c", "hsync")] == idle, [("ch7301c", "hsync")],
                    timeout_ps=self.deadline_ps)

    async def display_frame(self, sink, clocks):
        """Record ``clocks`` pixel clocks of the CH7301C pins and feed them to ``sink``; then schedule the switch
        words of this display frame count (:meth:`switch_plan`)."""
        h = self.h
        h.record(clocks)
        if self._until("a display frame", lambda: False, limit_ps=h.now_ps + 2 * clocks * self.periods["pix"]) \
                != RECORDED:
            raise SystemTimeout("the CH7301C pins of a display frame were not recorded in time")
        feed_sink(self.recording[:h.recorded], sink)
        self.chunks += 1
        self.switch_plan(self.chunks)

    def switch_plan(self, chunk):
        """Schedule the switch words ``switch_changes`` gives after ``chunk`` recorded display frames (a mode
        change mid-stream), one every 30 pixel clocks from now; they are set while the next display frame is
        recorded (:meth:`_switch_events`)."""
        now, step = self.h.now_ps, 30 * self.periods["pix"]
        for i, word in enumerate(self.switch_changes.get(chunk, ())):
            self.pending_switches.append((now + i * step, word))

    def _switch_events(self):
        """Set the scheduled switch words that are due; returns the time of the next one (or None)."""
        while self.pending_switches and self.pending_switches[0][0] <= self.h.now_ps:
            self.h[("panel", "sw")] = self.pending_switches.pop(0)[1]
        return self.pending_switches[0][0] if self.pending_switches else None

    # --- after the simulation ----------------------------------------------------------------------------------

    def replay_checks(self):
        """Every sample each camera's pins carried at its rising PCLK edges, against the model's stream."""
        out = {}
        for i, c in enumerate(CAMERAS):
            n = self.h.camera_seen(i)
            want = np.resize(self.words[c], n)
            out[c] = {"samples": int(n), "mismatches": int(np.count_nonzero(self.seen[c][:n] != want))}
        return out

    def check(self):
        """The driver's check phase: the parts' state and the bus monitors (:func:`record_parts`), the replay
        check. Returns the status."""
        record_parts(self.status, self.models, self.buses.monitors, after_s=0.0)
        self.status["replay_checks"] = self.replay_checks()
        return self.status
