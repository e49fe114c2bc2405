"""The whole system on Verilator with its testbench in C++: :class:`VerilatorRun`, the Verilator backend's driver.

The route of the full-size runs (``make demo``, ``stereodepth run``, the slow tests, the bench). The design is
:class:`sim.testbench.system.testbench.SystemTestbench` with clock inputs, Verilated without ``--timing`` and without
VPI (:mod:`sim.runners.verilator.build`); the testbench around it is C++ (``sim/runners/verilator/testbench.h``):
the four clocks at the edge times of the cocotb in-simulator route's generators (``sync`` from time 0, its first
rising edge half a period in; the pixel clock rising when it starts; each PCLK half a period after its camera
starts), each camera's stream on its pins (the next sample at every falling PCLK edge, from word 0 again after the
last), and the CH7301C pins sampled a quarter pixel period after each pixel-clock edge.

Each camera's stream is made before the run by the sensor model for the configuration the I2C init must produce
(:func:`sim.models.mt9d112.config.expected_sensor_config`): for a still pair (``sequence.still``) one frame period
of its images, repeated for ever; for a sequence the frame periods of its images one after the other (each shaped
by the sequence's ``faults``), then FV low for the rest of the run (the sensors stop: so the last display frame
shows the last pair on buffers no capture writes any more). A camera starts the instant its register-file model
says RGB565 and streaming, and only if that configuration is exactly the expected one (a
:class:`~sim.testbench.system.result.SystemTimeout` otherwise: the configuration guard).

Python keeps the models and the phases (reset, I2C init, capture, display frames, check): the simulation runs in
C++ until something Python must answer -- an I2C line changes (the register-file models answer at that instant;
the bus monitors see every change of the whole run), a status output changes (a phase waits for it; the captures'
frame starts and ends are noted all along, with the design's skew meter), or a time a phase set -- so nothing polls
and no Python runs per clock. The display frames are recorded one display frame period at a time from a display
frame start (for a still pair the first after both captures completed a frame, for a sequence the first after the
I2C init), each chunk fed to one HDMI sink, and each frame the sink completes handed to ``on_frame`` at once as a
:class:`~sim.testbench.system.result.DisplayFrame`. A sequence ends with its settled frame (the first display frame
that starts after both captures completed the whole sequence); a still pair when ``on_frame`` returns True (enough)
or after ``max_frames`` display frames.

The check phase of the driver: what the models and the bus monitors saw
(:func:`sim.testbench.system.result.record_parts`) and the replay check (every sample each camera's pins carried
at its rising PCLK edges equals the model's stream); the display frames' verdict is the run's
(:mod:`sim.system.verdict`).
"""

import time

import numpy as np

from hdl.system import CAMERAS, DISPLAY_LATENCY, I2C_BUSES
from sim.models.ch7301c.hdmi_sink import HdmiSink
from sim.models.i2c.monitor import I2CBusMonitor
from sim.models.mt9d112.config import expected_sensor_config
from sim.models.mt9d112.sensor import SensorStream
from sim.replay.sensor import pack_stream
from sim.testbench.system.cocotb_routes import period_ps
from sim.testbench.system.result import DisplayFrames, sent_frames, SystemTimeout, record_parts
from sim.runners.verilator.build import build
from sim.runners.verilator.ctestbench import RECORDED, CTestbench
from sim.runners.verilator.recording import feed_sink

__all__ = ["VerilatorRun", "camera_pins", "CH7301C_PINS"]

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
    """One run of ``sequence`` (see the module docstring). :meth:`run` simulates and returns the status; the
    testbench, the streams, the recording and the models stay here for the check and for the raw model
    (:mod:`bench.raw_model`, with ``keep_stimulus``). ``on_frame(DisplayFrame)`` receives each display frame (a
    still pair's run ends when it returns True); ``progress(stage, fraction)``; ``switch_changes``: ``{display
    frames recorded: [SW words]}`` set mid-stream (:meth:`switch_plan`)."""

    def __init__(self, setup, sequence, *, on_frame=None, progress=None, deadline_s=None, keep_stimulus=False,
                 switch_changes=None, max_frames=1):
        self.setup, self.sequence = setup, sequence
        self.still = bool(getattr(sequence, "still", False))
        self.on_frame = on_frame or (lambda frame: None)
        self.max_frames = max_frames
        self.switch_changes, self.pending_switches = switch_changes or {}, []
        self.build = build(setup)
        self.expected_config = expected_sensor_config(setup.geometry)
        self.words = self.streams()
        self.periods = {"sync": period_ps(setup.sys_hz), "pix": period_ps(setup.timing.pixel_hz, 4),
                        **{f"cam_{c}": period_ps(setup.camera_pclk_hz(c)) for c in CAMERAS}}
        self.frame_clocks = setup.timing.clocks_per_frame
        self.deadline_ps = round((deadline_s or setup.deadline_s()) / _PS)
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
        self.status, self.stage = {}, "i2c"
        self.frames = DisplayFrames(setup, CAMERAS, sent_frames(sequence, CAMERAS))
        self.last = {c: (0, 0) for c in CAMERAS}
        self.skew_count = 0
        for clock, port in CLOCK_PORTS.items():
            self.h.bind_clock(clock, port, self.periods[clock] // 2)
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
            [("skew", "count")]

    def _wake(self):
        """Whatever stopped the simulation: the buses answer, a camera configured by now starts, the captures'
        status changes are noted."""
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

    # --- the phases -----------------------------------------------------------------------------------------

    def run(self):
        wall0 = time.perf_counter()
        cpu0 = time.process_time()
        self.phase_wall = {}
        self.reset()
        if self.init():
            self.phase_wall["init"] = time.perf_counter() - wall0
            if self.still:
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
        """Until both captures completed a frame (a still pair's run)."""
        h = self.h
        self.stage = "capture"
        counts = [("capture", f"cam_{c}", "frame_count") for c in CAMERAS]
        counts0 = {n: h[n] for n in counts}
        self._until("a complete frame from both cameras", lambda: all(h[n] != counts0[n] for n in counts), counts,
                    timeout_ps=self.deadline_ps)
        for c in CAMERAS:
            self.status[f"cam_{c}_frame_ok"] = bool(h[("capture", f"cam_{c}", "frame_ok")])
        self.status["t_captured_s"] = h.now_ps * _PS

    def settings(self):
        """The switch settings and the automatic rectification's state the design shows now."""
        h = self.h
        bits = h[("settings", "rectification")] & 0x7F
        return {"disparity": h[("settings", "disparity")],
                "rectification": bits - 0x80 if bits & 0x40 else bits,          # two's complement
                "auto_rectification": {n: h[("rectification", n)] for n in ("auto", "confident", "held", "locked")}}

    def display(self):
        """The display frames, one display frame period at a time from the next display frame start (see the
        module docstring)."""
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
        status.update(self.settings())
        sink = HdmiSink(self.setup.timing, keep_frames=1)
        self.frames.start(h.now_ps * _PS, self.frame_clocks / self.setup.timing.pixel_hz)
        limit_ps = h.now_ps + self.deadline_ps + self._frames_ps()
        recorded, chunk = 0, 0
        while True:
            settings = self.settings()
            h.record(len(self.recording) if chunk == 0 else self.frame_clocks)
            if self._until("the display frames", lambda: False, limit_ps=limit_ps) != RECORDED:
                raise SystemTimeout(self.frames.overdue())
            recorded += h.recorded
            before = sink.frames_completed
            feed_sink(self.recording[:h.recorded], sink)
            chunk += 1
            enough = any([self.frames.completed(self.on_frame, sink.frames[-1], settings)
                          for _ in range(before, sink.frames_completed)])
            self.switch_plan(chunk)
            if self.frames.finished(enough, self.max_frames):
                break
            if not self.frames.shown and chunk > 3:
                raise SystemTimeout("the HDMI sink rebuilt no frame from three display frame periods of pins")
        status["recorded_clocks"] = recorded
        status["violations"] = [str(v) for v in sink.violations]
        status["leds"] = h[("panel", "leds")]
        status["drive_high"] = {b: bool(h[("bus", b, "drive_high")]) for b in I2C_BUSES}
        status["t_end_s"] = h.now_ps * _PS
        status.update(self.frames.record())
        self.report("done", 1.0)

    def _frames_ps(self):
        """Simulated time the display frames may take beyond the deadline: the sequence's stream, or
        ``max_frames`` display frames of a still pair."""
        if self.still:
            return round(self.max_frames * self.frame_clocks / self.setup.timing.pixel_hz / _PS)
        return round(2 * len(self.words["a"]) / self.setup.pclk_hz / _PS)

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
