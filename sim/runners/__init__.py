"""Simulator runners: how a design gets into a simulator and a result back out.

==========================  ============================================================================
module                      what
==========================  ============================================================================
``sim.runners.amaranth``    Amaranth's Python simulator with every clock domain at its real frequency
``sim.runners.cocotb``      Verilog export + cocotb on Verilator or Icarus; ``TopPorts`` for flat port names
``sim.runners.verilator``   the Verilated system with the project's C++ testbench (the fastest route)
==========================  ============================================================================

Every runner keeps what it builds under :func:`build_dir` (``./build``, or ``$STEREO_BUILD_DIR``).

May import: ``spec``, ``hdl``, ``board`` (Verilog export), ``golden``, ``sim.models``, ``sim.replay``, ``sim.waves``.
"""

import os
from pathlib import Path

__all__ = ["BUILD_DIR_ENV", "build_dir"]

#: The environment variable that moves every build directory (default ``build`` in the working directory).
BUILD_DIR_ENV = "STEREO_BUILD_DIR"


def build_dir(*parts):
    """The build directory ``$STEREO_BUILD_DIR/<parts>`` (default ``./build/<parts>``), not created."""
    return Path(os.environ.get(BUILD_DIR_ENV) or "build").joinpath(*parts).resolve()
