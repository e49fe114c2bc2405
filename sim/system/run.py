"""The one entry point of a whole-system run: :func:`simulate`.

Every user of the whole system -- the command line's ``run`` and ``demo``, the benchmarks, the tests -- calls
:func:`simulate` with a :class:`~sim.testbench.system.setup.SystemSetup`, a sequence and a backend
(:mod:`sim.system.backends`). A one-frame run is a still pair (:func:`still_pair`: the sensors send the pair's
images for ever, and the run shows the display frames from the first that starts after both captures completed a
frame); a multi-frame run is a :class:`~sim.testbed.sequence.FrameSequence` (the sensors send its images one per
frame period, then stop; every display frame from the first after the I2C init to the settled one). The phases
(reset, I2C init, capture, display frames) are the backend's driver's; the check phase is here: each display frame
is judged as it arrives (:class:`sim.system.verdict.Judge`: its golden frame and verdict), before ``on_frame`` sees
it, and the run as a whole at the end. The result is a :class:`SystemResult`.

A run that fails (a phase that does not complete in its simulated time, a configuration the sensors' streams were
not made for, a build or a simulator that fails) raises :class:`sim.SimulationFailed` with a one-line message, the
original exception as its cause; bad input is a :class:`sim.UserError` (:meth:`Backend.require
<sim.system.backends.Backend.require>`) raised before anything is simulated.
"""

from dataclasses import dataclass, field

from sim import SimulationFailed
from sim.system.verdict import Judge
from sim.testbed.sequence import FrameSequence

__all__ = ["simulate", "still_pair", "StillPair", "SystemResult"]


class StillPair(FrameSequence):
    """A still pair as a sequence: ``pairs`` holds the one pair, which the sensors send for ever (``still``)."""

    still = True


def still_pair(left, right, setup, sources=()):
    """The sequence of a one-frame run: ``left``/``right`` (RGB arrays, any size: fitted to the sensor), sent for
    ever (:class:`StillPair`); ``sources``: the input files."""
    return StillPair([(setup.fit(left), setup.fit(right))], names=["still pair"], sources=list(sources))


@dataclass
class SystemResult:
    """A run's outcome: the ``setup``, the ``sequence``, the ``backend``'s name, the driver's ``status`` (the
    phases' marks: ``<bus>_init_done``, ``t_init_s``, ``t_captured_s``, ``t_end_s``, the settings read at the first
    display frame, ``violations``, the parts' and buses' checks, ``capture_events_s``, ``hardware_skew``, ...), every
    display frame (``frames``: :class:`~sim.testbench.system.result.DisplayFrame` s with their golden frame and
    verdict), the run's ``verdict`` (:meth:`sim.system.verdict.Judge.run_verdict`: ``ok``; a still pair's
    ``chosen`` frame; a sequence's ``settled_frame``, ...), wall-time ``figures``, and where the backend has them
    the device ``models``, the bus ``monitors``, the ``sink``, the ``driver`` and the cocotb ``test_dir``; the
    ``judge`` that gave the verdict."""
    setup: object
    sequence: object
    backend: str
    status: dict
    frames: list
    verdict: dict
    figures: dict = field(default_factory=dict)
    models: dict = None
    monitors: dict = None
    sink: object = None
    driver: object = None
    test_dir: object = None
    judge: object = None

    @property
    def ok(self):
        return self.verdict["ok"]

    @property
    def chosen(self):
        """The display frame a still pair's run shows (None without one)."""
        k = self.verdict.get("chosen")
        return None if k is None else self.frames[k]

    @property
    def frame(self):
        """The chosen display frame's picture (None without one)."""
        return None if self.chosen is None else self.chosen.frame

    @property
    def golden(self):
        """The chosen display frame's golden frame (without a frame: the pair's with the settings the status
        holds)."""
        return self.chosen.golden if self.chosen is not None else self.judge.still_golden(self.status)

    @property
    def mismatched_pixels(self):
        return None if self.chosen is None else self.chosen.verdict["mismatched_pixels"]


def simulate(setup, sequence, backend, *, on_frame=None, progress=None, policy="first", max_frames=None):
    """Run ``sequence`` on ``setup`` through ``backend`` (see the module docstring); returns a
    :class:`SystemResult`.

    ``on_frame(DisplayFrame)`` is called for each display frame once judged (its files can be written at once);
    ``progress(stage, fraction)`` as the run goes on. A still pair's run shows the first display frame
    (``policy="first"``) or the first whose depth map has no withheld rows and, in automatic rectification, whose
    offset has locked (``"whole"``), within ``max_frames`` display frames (default 1 for ``first``, 8 for
    ``whole``; with the maps in the frame store, ``setup.maps == "store"``, ``first`` is the first display frame
    from the second on whose images and map are of a pair the run captured, within 1 + 2 M display frames, M those
    a map takes: ``setup.map_frames``; a frame before the first whole map is never shown).
    Raises :class:`~sim.UserError` for what the backend cannot run and
    :class:`~sim.SimulationFailed` for a run that fails."""
    judge = Judge(setup, sequence, policy)
    backend.require(setup, sequence)
    frames = []
    # With the maps in the frame store the first display frame's map is of a pair before the run, and a map of the
    # empty buffers begun before the captures completed may hold the pair back by a map's display frames.
    max_frames = max_frames or (1 if policy == "first" else 8) + 2 * setup.map_frames

    def judged(shown):
        judge(shown)
        frames.append(shown)
        if on_frame is not None:
            on_frame(shown)
        return judge.still and judge.enough(shown)
    try:
        out = backend.run(setup, sequence, on_frame=judged, progress=progress or (lambda stage, fraction: None),
                          max_frames=max_frames)
    except SimulationFailed:
        raise
    except (RuntimeError, OSError, AssertionError) as exc:  # a build, a library or a simulator failed
        raise SimulationFailed(str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__) \
            from exc
    verdict = judge.run_verdict(frames, out.status)
    result = SystemResult(setup, sequence, backend.name, out.status, frames, verdict, out.figures, out.models,
                          out.monitors, out.sink, out.driver, out.test_dir, judge)
    if judge.still:
        chosen = result.chosen
        out.status["tear"] = None if chosen is None else chosen.verdict["tear"]
        out.status["mismatched_pixels"] = result.mismatched_pixels
    return result
