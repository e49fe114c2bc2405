"""Many camera frames through the whole system in cocotb (Verilator or Icarus), small size:
:func:`run_cocotb_frames` exports the design of the Python-models route, hands the sequence to the simulator as an
``.npz`` and runs ``sim/testbench/system/cocotb_frames.py`` inside it; the display frames come back as
:class:`~sim.testbench.system.frames_verilator.DisplayFrame` s, as from the other simulators."""

import json
from pathlib import Path

import numpy as np

from hdl.system import CAMERAS
from sim.testbench.system.cocotb_routes import PythonModels
from sim.testbench.system.frames_verilator import DisplayFrame
from sim.testbench.system.run_cocotb import run_scenario

__all__ = ["run_cocotb_frames"]


def run_cocotb_frames(sequence, setup, simulator, out_dir):
    """Simulate ``sequence`` (a :class:`~sim.testbed.sequence.FrameSequence`, no faults) on ``simulator``; returns
    ``(status, [DisplayFrame, ...])``. Raises ``AssertionError`` when the scenario fails."""
    if setup.preset != "small":
        raise ValueError("the cocotb multi-frame scenario runs the small preset")
    if sequence.faults:
        raise ValueError("the cocotb multi-frame scenario sends no faults (the Verilator route does)")
    out_dir = Path(out_dir).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    np.savez(out_dir / "sequence.npz", left=np.stack(sequence.images("a")), right=np.stack(sequence.images("b")))
    route = PythonModels()
    params = {"setup": setup.to_spec(), "route": route.spec(), "sequence": str(out_dir / "sequence.npz"),
              "out_dir": str(out_dir)}
    run_scenario(route, setup, simulator, params, testcase="multi_frame")
    status = json.loads((out_dir / "result.json").read_text())
    with np.load(out_dir / "frames.npz") as npz:
        frames, starts = npz["frames"], npz["t_start_s"]
    events = status["capture_events_s"]
    shown = [DisplayFrame(k, frame, float(t), {c: sum(1 for e in events[c]["frame_done"] if e <= t)
                                               for c in CAMERAS})
             for k, (frame, t) in enumerate(zip(frames, starts))]
    return status, shown
