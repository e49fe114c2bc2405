"""Many camera frames through the whole system on Verilator (the C++ testbench): :func:`run_verilator_frames`.

The one-frame route (``sim/testbench/system/run_verilator.py``) with a :class:`~sim.testbed.sequence.
FrameSequence` in place of one pair: each camera's replayed stream is the sensor model's frame periods of the
sequence's images one after the other (the sensor model takes a new image every frame), then FV low for the rest
of the run (the sensors stop: a simulation choice, so the last display frame shows the last pair on buffers that no
capture writes any more and is the golden model's frame of that pair bit for bit).

The phases: reset, I2C init, pixel clock and switches as in the one-frame route; then the display is recorded one
display frame period at a time from the first display frame start, each chunk fed to one HDMI sink, and every
frame the sink completes is handed to ``on_frame`` at once (so an interrupted run keeps what it finished). The
run ends with the first display frame that starts after both captures have completed all the sequence's frames
(the "settled" frame). While it runs, the times at which each capture's ``frame_start`` and ``frame_count`` change
(the design's own status outputs) are kept: the frame-start skew between the cameras in simulation.
"""

import time

import numpy as np

from hdl.system import CAMERAS, DISPLAY_LATENCY
from sim.models.ch7301c.hdmi_sink import HdmiSink
from sim.models.mt9d112.sensor import SensorStream
from sim.replay.sensor import pack_stream
from sim.runners.verilator.ctestbench import RECORDED
from sim.runners.verilator.recording import feed_sink
from sim.testbench.system.result import SystemTimeout
from sim.testbench.system.run_verilator import VerilatorRun, _PS

__all__ = ["run_verilator_frames", "VerilatorFramesRun", "DisplayFrame"]


class DisplayFrame:
    """One display frame as the sink rebuilt it: ``index`` (0 = the first recorded), ``frame`` (uint8 RGB),
    ``t_start_s`` (simulated time of its first recorded pixel clock), ``captured`` (frames each capture had
    completed by then, ``{camera: count}``)."""

    def __init__(self, index, frame, t_start_s, captured):
        self.index, self.frame, self.t_start_s, self.captured = index, frame, t_start_s, captured


class VerilatorFramesRun(VerilatorRun):
    """See the module docstring. ``on_frame(DisplayFrame)`` is called for each display frame."""

    def __init__(self, setup, sequence, *, on_frame=None, progress=None, deadline_s=None, switch_changes=None):
        self.sequence = sequence
        self.switch_changes = switch_changes or {}
        self.pending_switches = []
        self.on_frame = on_frame or (lambda frame: None)
        left, right = sequence.pairs[0]
        super().__init__(setup, left, right, progress=progress, deadline_s=deadline_s)
        cam_s = len(self.words["a"]) / setup.pclk_hz
        self.total_ps = (setup.expected_sim_time_s() + cam_s) / _PS
        self.frame_clocks = setup.timing.clocks_per_frame
        self.recording = np.zeros(self.frame_clocks, dtype=np.uint32)
        self.h.bind_recorder(self._recorder_pins(), self.recording)
        self.events = {c: {"frame_start": [], "frame_done": []} for c in CAMERAS}
        self.frames_shown = 0
        self.last = {c: (0, 0) for c in CAMERAS}
        self.skew_count, self.hardware_skew = 0, []

    @staticmethod
    def _recorder_pins():
        from sim.testbench.system.run_verilator import CH7301C_PINS
        return CH7301C_PINS

    def streams(self):
        """Each camera's frame periods of the sequence, then FV low (see the module docstring)."""
        words = {}
        n = len(self.sequence)
        tail_s = 4 * self.setup.timing.clocks_per_frame / self.setup.timing.pixel_hz
        for seed, c in enumerate(CAMERAS):
            sensor = self.setup.sensor(self.expected_config, seed=seed)
            chunks = [sensor.blank(sensor.timing.v_blank_lines + self.setup.geometry.height) if fault == "drop"
                      else sensor.frame(image, fault)
                      for image, fault in zip(self.sequence.images(c), self.sequence.camera_faults(c))]
            line = sensor.timing.line_time(self.setup.geometry.width)
            chunks.append(sensor.blank(max(1, round(tail_s * self.setup.pclk_hz / line))))
            words[c] = pack_stream(SensorStream.concat(chunks)).astype(np.uint16)
        return words

    def _until(self, what, done, watch=(), timeout_ps=None, limit_ps=None):
        """The one-frame route's wait, also watching the captures' status (their frame starts and ends are noted
        from the first one on)."""
        return super()._until(what, done, [*watch, *self._status_ports()], timeout_ps, limit_ps)

    def _wake(self):
        super()._wake()
        if hasattr(self, "last"):
            self._note(self.last)

    def _status_ports(self):
        return [("capture", f"cam_{c}", k) for c in CAMERAS for k in ("in_frame", "frame_count")] + \
            [("skew", "count")]

    def _note(self, last):
        """Record the capture status changes since ``last`` (updated in place)."""
        h, now = self.h, self.h.now_ps * _PS
        for c in CAMERAS:
            in_frame, count = h[("capture", f"cam_{c}", "in_frame")], h[("capture", f"cam_{c}", "frame_count")]
            if in_frame and not last[c][0]:
                self.events[c]["frame_start"].append(now)
            if count != last[c][1]:
                self.events[c]["frame_done"].append(now)
            last[c] = (in_frame, count)
        count = h[("skew", "count")]
        if count != self.skew_count:
            self.skew_count = count
            self.hardware_skew.append({"t_s": now, "skew_sync_clocks": h.signed(("skew", "skew")),
                                       "aligned": bool(h[("skew", "aligned")])})

    def frames(self):
        """Record display frames until the settled frame (see the module docstring)."""
        h, status = self.h, self.status
        self.stage = "frames"
        n = len(self.sequence)
        last = self.last
        watch = [*self.buses.lines, *self._status_ports()]
        rose = [h["frame_start"]]

        def frame_start_rose():
            r, rose[0] = h["frame_start"] and not rose[0], h["frame_start"]
            return r
        self._until("a display frame start", frame_start_rose, ["frame_start", *self._status_ports()],
                    timeout_ps=self.deadline_ps)
        idle = 0 if self.setup.timing.hsync_positive else 1
        self._until("hsync idle", lambda: h[("ch7301c", "hsync")] == idle, [("ch7301c", "hsync")],
                    timeout_ps=self.deadline_ps)
        status["disparity"] = h[("settings", "disparity")]
        status["rectification"] = h[("settings", "rectification")]
        sink = self.frames_sink = HdmiSink(self.setup.timing, keep_frames=1)
        period_s = self.frame_clocks / self.setup.timing.pixel_hz
        t0 = h.now_ps * _PS
        status["t_display_start_s"] = t0
        limit_s = t0 + self.setup.deadline_s() + (n + 2) * len(self.words["a"]) / n / self.setup.pclk_hz
        chunk = 0
        settled_at = None
        while True:
            h.record(self.frame_clocks)
            h.watch(watch)
            while True:
                stops = (self.buses.deadline_ps(), self._switch_events(), h.now_ps + 1_000_000_000)
                reason = h.run(min(t for t in stops if t is not None))
                self._wake()
                if reason == RECORDED:
                    break
                if h.now_ps * _PS > limit_s:
                    raise SystemTimeout(f"the captures did not complete {n} frames by {limit_s * 1e3:.1f} ms")
            before = sink.frames_completed
            feed_sink(self.recording, sink)
            chunk += 1
            for k in range(before, sink.frames_completed):
                start = t0 + k * period_s
                captured = {c: sum(1 for t in self.events[c]["frame_done"] if t <= start) for c in CAMERAS}
                self.on_frame(DisplayFrame(k, sink.frames[-1], start, captured))
                self.frames_shown += 1
            sent = {c: self.sequence.frames_sent(c) for c in CAMERAS}
            done = all(len(self.events[c]["frame_done"]) >= sent[c] for c in CAMERAS)
            if done and settled_at is None:
                # the next display frame to start is the first one with every capture finished
                settled_at = int(np.ceil((max(self.events[c]["frame_done"][sent[c] - 1] for c in CAMERAS) - t0)
                                         / period_s))
            self.switch_plan(chunk)
            if settled_at is not None and self.frames_shown > settled_at:
                break
            if self.frames_shown == 0 and chunk > 3:
                raise SystemTimeout("the HDMI sink rebuilt no frame from three display frame periods of pins")
        status["display_frames"] = self.frames_shown
        status["settled_frame"] = settled_at
        status["violations"] = [str(v) for v in sink.violations]
        status["t_end_s"] = h.now_ps * _PS
        status["capture_events_s"] = self.events
        status["hardware_skew"] = self.hardware_skew
        status["leds"] = h[("panel", "leds")]
        self.report("done", 1.0)

    def switch_plan(self, chunk):
        """Schedule the switch words the plan gives after ``chunk`` recorded display frames (a mode change
        mid-stream: ``switch_changes`` ``{chunk: [SW words]}``), one every 30 pixel clocks from now; they are set
        while the next display frame is recorded (:meth:`_switch_events`)."""
        now, step = self.h.now_ps, 30 * self.periods["pix"]
        for i, word in enumerate(self.switch_changes.get(chunk, ())):
            self.pending_switches.append((now + i * step, word))

    def _switch_events(self):
        """Set the scheduled switch words that are due; returns the time of the next one (or None)."""
        while self.pending_switches and self.pending_switches[0][0] <= self.h.now_ps:
            self.h[("panel", "sw")] = self.pending_switches.pop(0)[1]
        return self.pending_switches[0][0] if self.pending_switches else None

    def run(self):
        wall0 = time.perf_counter()
        self.phase_wall = {}
        self.reset()
        if self.init():
            self.phase_wall["init"] = time.perf_counter() - wall0
            self.frames()
        self.status["wall_s"] = self.phase_wall["frames"] = time.perf_counter() - wall0
        return self.status


def run_verilator_frames(sequence, setup, *, on_frame=None, progress=None, deadline_s=None, switch_changes=None):
    """Simulate ``sequence`` (a :class:`~sim.testbed.sequence.FrameSequence`) through the whole system on
    Verilator (see the module docstring); ``on_frame(DisplayFrame)`` for each display frame as it completes.
    Returns the run's status (``display_frames``, ``settled_frame``, ``capture_events_s``, the I2C outcome,
    ``violations``, ``wall_s``). Raises :class:`~sim.testbench.system.result.SystemTimeout` as the one-frame
    route does. ``switch_changes``: ``{display frames recorded: [SW words]}`` set mid-stream (see
    :meth:`VerilatorFramesRun.switch_plan`); the sequence's ``faults`` shape each camera's frames."""
    run = VerilatorFramesRun(setup, sequence, on_frame=on_frame, progress=progress, deadline_s=deadline_s,
                             switch_changes=switch_changes)
    status = run.run()
    status["frames_in"] = len(sequence)
    return status, run
