"""Simulation: part models, testbenches, simulator runners, waveform tools, the formal runner, the test bed.

=================  =====================================================  ====================================
package            what                                                   may import (of the project)
=================  =====================================================  ====================================
``sim.models``     the parts around the FPGA: MT9D112, CH7301C + HDMI     ``spec``, ``hdl``, ``golden``,
                   sink, the I2C bus and its devices, the clocking model  ``sim.waves``
``sim.replay``     camera pins replayed, display pins recorded inside     ``spec``, ``hdl``, ``sim.models``
                   the simulator (no Python per clock)
``sim.waves``      GTKWave save files, translate filters, the headless    ``spec``, ``hdl``
                   GTKWave check
``sim.runners``    Amaranth, cocotb and Verilator runners                 ``spec``, ``hdl``, ``board``,
                                                                          ``sim.waves``
``sim.testbench``  testbenches: capture, display, subtractor, depth,      ``spec``, ``hdl``, ``golden``,
                   the whole system                                       ``board``, the four above
``sim.formal``     the formal runner, its engines and the harnesses       ``spec``, ``hdl``, ``sim.runners``
``sim.testbed``    the thesis's test bed and the synthetic scenes         ``spec``, ``hdl``, ``golden``,
                                                                          ``sim.runners``, ``sim.testbench``
``sim.board``      the board's ``top.v`` (``board.top``) simulated as     ``spec``, ``hdl``, ``board``,
                   built, with the Virtex-5 primitive models              ``sim.testbench``
``sim.analysis``   ground truth, bad-pixel figures, reading pictures      ``spec``, ``golden``, ``sim.models``,
                   back                                                   ``sim.testbed``
``sim.system``     the whole-system run: ``simulate``, the backends, the  all of the above
                   verdict
=================  =====================================================  ====================================

Every package may also import the exceptions below. ``tests/test_layering.py`` holds the exact rule.

The exceptions library code raises for the command line to report live here: :class:`UserError` for bad input
(one-line error, exit code 2, no traceback; ``stereodepth.errors`` re-exports it) and :class:`SimulationFailed`
for a simulation that ended without a result.
"""

__all__ = ["UserError", "SimulationFailed"]


class UserError(Exception):
    """Bad input from the user: a missing or unreadable file, mismatched images, an out-of-range value."""


class SimulationFailed(RuntimeError):
    """A simulation ended without a result (build error, crash, I2C failure): the message says why and where the
    log is."""
