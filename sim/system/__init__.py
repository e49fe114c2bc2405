"""The whole-system run: one entry point for every user of the whole system (the command line, the benchmarks,
the tests).

====================  ========================================================================================
``run.py``            :func:`~sim.system.run.simulate` (setup, sequence, backend -> :class:`~sim.system.run.SystemResult`),
                      :func:`~sim.system.run.still_pair` (a one-frame run's sequence)
``backends.py``       the simulators behind the run, one interface: :class:`~sim.system.backends.Verilator` (the C++
                      testbench), :class:`~sim.system.backends.Amaranth`, :class:`~sim.system.backends.Cocotb`
``verdict.py``        the check phase: each display frame against its golden frame, the camera frames its rows came
                      from, the frame a still pair's run shows, the settled frame (:class:`~sim.system.verdict.Judge`)
``frame_files.py``    what a multi-frame run writes: per display frame its PNGs and table row, the animations, the MP4
====================  ========================================================================================

The drivers that simulate the phases are in ``sim/testbench/system/``; this package adds the verdict, which needs
the golden models' analysis (``sim/analysis/``) and the test bed's sequences (``sim/testbed/``).
"""

from sim.system.backends import SIMULATORS, Amaranth, Backend, Cocotb, Verilator, backend_named
from sim.system.run import SystemResult, simulate, still_pair

__all__ = ["simulate", "still_pair", "SystemResult", "Backend", "Verilator", "Amaranth", "Cocotb",
           "backend_named", "SIMULATORS"]
