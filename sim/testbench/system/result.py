"""What a whole-system driver hands back, and the checks every driver ends with.

:class:`DisplayFrame` is one display frame as the HDMI sink rebuilt it from the simulated pins; :class:`DisplayFrames`
is the bookkeeping every driver shares while it records them: the captures' frame starts and ends and the design's
skew meter as the driver notes them, which camera frames each display frame started after, and when a run has
seen enough (the settled frame of a sequence, or a still pair's frame its caller accepts). :func:`record_parts` is
the part of the check phase about the parts: what the device models and the bus monitors saw.

The cameras of a still pair stream its images over and over, so a display frame's depth map may have been computed
across a tear: rows of two camera frames (the same images), told apart by the row tags, and the rows at the tear
invalid (docs/depth.md, "Rows from different camera frames"). :func:`tear_golden` finds the golden frame of that
tear (the tear row c found by trying each near the depth panel's first row that differs, row c torn or not);
:func:`check_run` is the whole check of a one-frame run of the board top (``sim/board/``).
"""

import math
from dataclasses import dataclass

import numpy as np

from hdl.system import I2C_BUSES
from sim import SimulationFailed

__all__ = ["DisplayFrame", "DisplayFrames", "SystemTimeout", "sent_frames", "record_parts", "check_run", "tear_golden",
           "tear_tags"]


class SystemTimeout(SimulationFailed):
    """The simulation did not reach a stage in the allowed simulated time (or could not go on)."""


@dataclass
class DisplayFrame:
    """One display frame: ``index`` (0 = the first recorded), ``frame`` (uint8 RGB, as the sink rebuilt it from the
    pins), ``t_start_s`` (simulated time of its first recorded pixel clock), ``captured`` (frames each capture had
    completed by then, ``{camera: count}``), ``settings`` (the switch settings and the automatic rectification's
    state the design showed as it started: ``disparity``, ``rectification`` in use, ``auto_rectification``), and,
    once the run has judged it (:mod:`sim.system.verdict`), its ``golden`` frame and ``verdict``."""
    index: int
    frame: np.ndarray
    t_start_s: float
    captured: dict
    settings: dict = None
    golden: np.ndarray = None
    verdict: dict = None


class DisplayFrames:
    """A driver's display frames and the captures' events (see the module docstring); ``sent``: the frames each
    camera sends (``{camera: count}``) of a sequence, None for a still pair."""

    def __init__(self, setup, cameras, sent=None):
        self.setup, self.sent = setup, sent
        self.map_frames = getattr(setup, "map_frames", 0)     # the last pair's map comes this many frames late
        self.events = {c: {"frame_start": [], "frame_done": []} for c in cameras}
        self.hardware_skew = []
        self.shown, self.settled, self.t0, self.period_s = 0, None, None, None

    def note_capture(self, camera, now, started, done):
        """Camera ``camera``'s capture started a frame (``started``) or completed one (``done``) at ``now``."""
        if started:
            self.events[camera]["frame_start"].append(now)
        if done:
            self.events[camera]["frame_done"].append(now)

    def note_skew(self, now, skew, aligned):
        """A new measurement of the design's skew meter (``skew`` in ``sync`` clocks)."""
        self.hardware_skew.append({"t_s": now, "skew_sync_clocks": skew, "aligned": aligned})

    def start(self, t0, period_s):
        """The first display frame starts at ``t0``, the next every ``period_s``."""
        self.t0, self.period_s = t0, period_s

    def completed(self, on_frame, frame, settings=None):
        """The sink completed the next display frame: hand it to ``on_frame``; returns its answer as a bool."""
        start = self.t0 + self.shown * self.period_s
        captured = {c: sum(1 for t in e["frame_done"] if t <= start) for c, e in self.events.items()}
        shown = DisplayFrame(self.shown, frame, start, captured, settings)
        self.shown += 1
        return bool(on_frame(shown))

    def finished(self, enough, max_frames):
        """Whether the run has its display frames: a still pair's when ``enough`` or after ``max_frames``, a
        sequence's with its settled frame (the first that starts after both captures completed every frame the
        camera sent; with the maps in the frame store the frame a map's display frames after it, which shows that pair's
        map)."""
        if self.sent is None:
            return enough or self.shown >= max_frames
        sent = self.sent
        if self.settled is None and all(len(e["frame_done"]) >= sent[c] for c, e in self.events.items()):
            end = max(self.events[c]["frame_done"][sent[c] - 1] for c in self.events)
            self.settled = math.ceil((end - self.t0) / self.period_s)
        # With the maps in the frame store the last pair's map is shown the display frames a map takes after its
        # images (``SystemSetup.map_frames``).
        return self.settled is not None and self.shown > self.settled + self.map_frames

    def overdue(self):
        """The message of a run whose display frames did not come in time."""
        if self.sent is None:
            return f"the display frames did not complete in time ({self.shown} so far)"
        return f"the captures did not complete {max(self.sent.values())} frames in time"

    def record(self):
        """The status entries of the display frames and the captures' events."""
        return {"display_frames": self.shown, "settled_frame": self.settled, "t_display_start_s": self.t0,
                "capture_events_s": self.events, "hardware_skew": self.hardware_skew}


def sent_frames(sequence, cameras):
    """``{camera: frames it sends}`` of a sequence, None for a still pair (``sequence.still``): the ``sent`` of
    :class:`DisplayFrames`."""
    if getattr(sequence, "still", False):
        return None
    return {c: sequence.frames_sent(c) for c in cameras}


def record_parts(status, models, monitors, *, after_s=None):
    """Record in ``status`` what the device ``models`` and the bus ``monitors`` saw (bus protocol errors after
    ``after_s``, default all)."""
    status["mt9d112_problems"] = {b: models[b][0].problems() for b in ("cam_a", "cam_b")}
    status["sensor_config"] = {b: repr(models[b][0].sensor_config()) for b in ("cam_a", "cam_b")}
    status["dvi_config"] = dict(models["dvi"][0].dvi_config().__dict__)
    status["i2c_protocol_errors"] = {b: [str(e) for e in monitors[b].protocol_errors
                                         if after_s is None or e[0] > after_s] for b in I2C_BUSES}
    status["i2c_transactions"] = {b: len(monitors[b].transactions) for b in I2C_BUSES}


def check_run(status, setup, left, right, sink, models, monitors, *, after_s=None):
    """The check of a one-frame run: compare the sink's frame 0 with the golden frame of ``left``/``right`` (that of
    a tear when one explains it) and record what the models and monitors saw. Fills ``status`` and returns
    ``(frame, golden)``."""
    kwargs = {"in_use": status.get("rectification"), "held": status.get("auto_rectification", {}).get("held", False)}
    golden = setup.golden_frame(left, right, **kwargs)
    frame = sink.frames[0] if sink.frames else None
    status["tear"] = None
    if frame is not None and not np.array_equal(frame, golden):
        golden, status["tear"] = tear_golden(setup, left, right, frame, golden, **kwargs)
    status["violations"] = [str(v) for v in sink.violations]
    record_parts(status, models, monitors, after_s=after_s)
    status["mismatched_pixels"] = None if frame is None else int(np.any(frame != golden, axis=-1).sum())
    return frame, golden


def tear_tags(height, tear):
    """The buffers' row tags of a tear ``(c, torn)`` (:func:`tear_golden`): rows 0..c-1 new (1), c..H-1 old (0), row
    c None when torn; None for no tear (``tear`` None)."""
    if tear is None:
        return None
    c, torn = tear
    tags = [1] * c + [0] * (height - c)
    if torn:
        tags[c] = None
    return tags, list(tags)


def tear_golden(setup, left, right, frame, golden, **kwargs):
    """``(golden frame, (c, torn))`` of the tear that explains ``frame`` (the map computed across a new camera frame
    of the same images overwriting the old one: buffer rows 0..c-1 tagged new, c..H-1 old, row c torn or not), or
    ``(golden, None)`` when none does. c is tried from 2 rows above the depth panel's first differing row to
    ``census_height`` rows below it (the rows above a tear's invalid band are the untorn map's)."""
    g = setup.geometry
    h = g.buf_height
    region = setup.display_layout.region("depth")
    panel = np.any(frame[region.y0:region.y1, region.x0:region.x1] != golden[region.y0:region.y1, region.x0:region.x1],
                   axis=(1, 2)).reshape(h, region.scale).any(axis=1)
    first = int(np.argmax(panel)) if panel.any() else 0
    for c in range(max(1, first - 2), min(h, first + setup.depth.census_height + 1)):
        for torn in (False, True):
            candidate = setup.golden_frame(left, right, row_tags=tear_tags(h, (c, torn)), **kwargs)
            if np.array_equal(frame, candidate):
                return candidate, (c, torn)
    return golden, None
