"""What a whole-system run gives back, and the check that ends every run (both simulators, every route).

:func:`check_run` is the last phase of a run: from the sink's rebuilt frame, the golden frame, the device models and
the bus monitors it fills the run's status with the comparison and what the models saw; :class:`SystemResult`
carries it all back to the caller.

The cameras stream their image over and over while a run records its display frame, so that frame's depth map may
have been computed across a tear: rows of two camera frames (the same image), told apart by the row tags, and the
rows at the tear invalid (docs/depth.md, "Rows from different camera frames"). The frame is then compared with the
golden frame of that tear (:func:`tear_golden`: the tear row c found by trying each near the depth panel's first
row that differs, row c torn or not) and ``status["tear"]`` says which; it is None for a frame without a tear.
"""

from dataclasses import dataclass, field

import numpy as np

from hdl.system import I2C_BUSES

__all__ = ["SystemResult", "SystemTimeout", "check_run", "tear_golden", "tear_tags"]


class SystemTimeout(AssertionError):
    """The simulation did not reach a stage in the allowed simulated time (or could not go on)."""


@dataclass
class SystemResult:
    """A run's outcome: the rebuilt ``frame`` (None if none was rebuilt), the ``golden`` frame, the ``status``
    (:func:`check_run`'s keys and the phases' marks: ``<bus>_init_done``, ``t_init_s``, ``cam_<c>_frame_ok``,
    ``t_captured_s``, ``t_end_s``, ...), wall-time ``figures``; from Amaranth's simulator also the ``sink``, the
    device ``models`` and the bus ``monitors``, from cocotb the ``test_dir`` (logs, waves)."""
    frame: np.ndarray
    golden: np.ndarray
    status: dict
    figures: dict = field(default_factory=dict)
    sink: object = None
    models: dict = None
    monitors: dict = None
    test_dir: object = None

    @property
    def mismatched_pixels(self):
        if self.frame is None:
            return None
        return int(np.any(self.frame != self.golden, axis=-1).sum())


def check_run(status, setup, left, right, sink, models, monitors, *, after_s=None):
    """The check phase: compare the sink's frame 0 with the golden frame of ``left``/``right`` and record what the
    models and monitors saw (bus protocol errors after ``after_s``, default all). Fills ``status`` and returns
    ``(frame, golden)``."""
    kwargs = {"in_use": status.get("rectification"), "held": status.get("auto_rectification", {}).get("held", False)}
    golden = setup.golden_frame(left, right, **kwargs)
    frame = sink.frames[0] if sink.frames else None
    status["tear"] = None
    if frame is not None and not np.array_equal(frame, golden):
        golden, status["tear"] = tear_golden(setup, left, right, frame, golden, **kwargs)
    status["violations"] = [str(v) for v in sink.violations]
    status["mt9d112_problems"] = {b: models[b][0].problems() for b in ("cam_a", "cam_b")}
    status["sensor_config"] = {b: repr(models[b][0].sensor_config()) for b in ("cam_a", "cam_b")}
    status["dvi_config"] = dict(models["dvi"][0].dvi_config().__dict__)
    status["i2c_protocol_errors"] = {b: [str(e) for e in monitors[b].protocol_errors
                                         if after_s is None or e[0] > after_s] for b in I2C_BUSES}
    status["i2c_transactions"] = {b: len(monitors[b].transactions) for b in I2C_BUSES}
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
