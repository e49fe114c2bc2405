"""The whole system through cocotb (Verilator or Icarus): build the route's design, run the scenario, collect the
display frames: the cocotb backend's driver.

:func:`run_cocotb_system` exports the design of a route (``sim/testbench/system/cocotb_routes.py``) for a
:class:`sim.testbench.system.setup.SystemSetup`, hands the sequence to the simulator as an ``.npz``, runs
``sim/testbench/system/system_cocotb.py`` (the scenario of ``sim/testbench/system/cocotb_scenario.py``) on it with
``sim.runners.cocotb.run_cocotb`` (builds are cached by Verilog text) and returns the status and the display
frames. A failed scenario raises ``AssertionError`` from the runner with the log tail; one the DDR2 build's MIG
model stopped raises :class:`sim.models.mig.MIGProtocolViolation` (its one-line message) instead. With
``progress``, the run goes on in a thread while the scenario's progress file is polled.
"""

import json
import threading
from pathlib import Path

import numpy as np

from golden.stereo_pair import DATA_DIR
from hdl.system import CAMERAS
from sim.models.mig import MIGProtocolViolation
from sim.runners.cocotb import run_cocotb
from sim.testbench.system.cocotb_routes import InSimulator, PythonModels
from sim.testbench.system.result import DisplayFrame
from sim.testbench.system.testbench import export_text
from sim.testbench.system.waves import cocotb_system_waves

__all__ = ["DEFAULT_PAIR", "VIOLATION_FILE", "run_cocotb_system", "run_rate_probe"]

#: The bundled stereo pair (golden/data/README.md).
DEFAULT_PAIR = (DATA_DIR / "motorcycle_left.png", DATA_DIR / "motorcycle_right.png")
#: Where the scenario writes the MIG model's violation (``{"violation": [code, addr, cycle], "t_ps": when}``)
#: before it stops the run.
VIOLATION_FILE = "mig_violation.json"


def _design_verilog(route, setup):
    """Verilog of the route's design, with the frame buffers' all-zero initial blocks written as loops
    (``board.export``): the same values, a much smaller file for Verilator and Icarus; the DDR2 build's with the MIG
    model's storage module."""
    return export_text(route.design(setup), f"system_{route.name}")


def run_cocotb_system(setup, simulator, sequence, *, route=None, out_dir, progress=None, waves=None, max_frames=1,
                      mig_latency=None):
    """Run the end-to-end scenario of ``setup`` on ``simulator`` with ``sequence`` (a still pair, along ``route``,
    default :class:`~sim.testbench.system.cocotb_routes.InSimulator`, ``max_frames`` display frames; or a
    sequence, with the Python models). Writes into ``out_dir``; returns ``(status, [DisplayFrame, ...],
    test_dir)``.

    ``progress(stage, fraction)``, if given, is called about twice a second while the run goes on;
    ``mig_latency``: the DDR2 build's read latency (default drawn per run). Raises ``AssertionError`` when the
    scenario fails (:class:`~sim.models.mig.MIGProtocolViolation` when the MIG model stopped it)."""
    still = bool(getattr(sequence, "still", False))
    route = route or (InSimulator() if still else PythonModels())
    out_dir = Path(out_dir).resolve()
    out_dir.mkdir(parents=True, exist_ok=True)
    progress_file = out_dir / "progress"
    progress_file.unlink(missing_ok=True)
    (out_dir / "result.json").unlink(missing_ok=True)
    (out_dir / VIOLATION_FILE).unlink(missing_ok=True)
    np.savez(out_dir / "sequence.npz", left=np.stack(sequence.images("a")), right=np.stack(sequence.images("b")))
    params = {"setup": setup.to_spec(), "route": route.spec(), "sequence": str(out_dir / "sequence.npz"),
              "still": still, "max_frames": max_frames, "out_dir": str(out_dir),
              "progress_file": str(progress_file), "mig_latency": mig_latency}

    def run():
        try:
            return run_scenario(route, setup, simulator, params, waves=waves, testcase="end_to_end")
        except AssertionError as failed:
            if (out_dir / VIOLATION_FILE).exists():
                seen = json.loads((out_dir / VIOLATION_FILE).read_text())["violation"]
                raise MIGProtocolViolation(*seen) from failed
            raise

    test_dir = run() if progress is None else _with_progress(run, progress_file, progress)
    status = json.loads((out_dir / "result.json").read_text())
    with np.load(out_dir / "frames.npz") as npz:
        frames = [DisplayFrame(k, frame, float(t), dict(zip(CAMERAS, map(int, captured))),
                               {n: status.get(n) for n in ("disparity", "rectification", "auto_rectification")})
                  for k, (frame, t, captured) in enumerate(zip(npz["frames"], npz["t_start_s"], npz["captured"]))]
    return status, frames, Path(test_dir)


def run_rate_probe(setup, simulator, probe_us, out_dir):
    """For the benchmark: the in-simulator route's design with every clock running for ``probe_us`` of simulated time
    (the scenario's ``rate_probe``). Returns ``{"probe_us", "wall_s", "pixel_hz"}``."""
    route = InSimulator()
    out_dir = Path(out_dir)
    params = {"setup": setup.to_spec(), "route": route.spec(), "out_dir": str(out_dir.resolve()),
              "probe_us": probe_us}
    run_scenario(route, setup, simulator, params, testcase="rate_probe")
    return json.loads((out_dir / "probe.json").read_text())


def run_scenario(route, setup, simulator, params, *, waves=None, testcase=None):
    """Export ``route``'s design of ``setup`` and run ``testcase`` of the system cocotb module with ``params``."""
    return run_cocotb(_design_verilog(route, setup), name=f"system_{route.name}",
                      test_module="sim.testbench.system.system_cocotb", simulator=simulator, params=params,
                      waves=waves, testcase=testcase, build_args=route.build_args(simulator),
                      extra_sources=route.extra_sources(), verilator_fast=route.verilator_fast,
                      run_waves=cocotb_system_waves(route, setup))


def _with_progress(run, progress_file, progress):
    outcome = {}

    def target():
        try:
            outcome["test_dir"] = run()
        except BaseException as exc:                    # re-raised in the caller's thread below
            outcome["error"] = exc

    thread = threading.Thread(target=target, daemon=True)
    thread.start()
    while thread.is_alive():
        thread.join(0.5)
        try:
            done, total, *stage = progress_file.read_text().split()
            progress(stage[0] if stage else "", int(done) / int(total))
        except (OSError, ValueError, ZeroDivisionError):
            pass
    if "error" in outcome:
        raise outcome["error"]
    return outcome["test_dir"]
