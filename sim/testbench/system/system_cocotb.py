"""cocotb end-to-end test of the whole system, on Verilator and Icarus: a still pair or a sequence in, the display
frames out. The scenario and its phases are ``sim/testbench/system/cocotb_scenario.py``; the design and the
parameters come from ``sim.testbench.system.run_cocotb.run_cocotb_system`` (the cocotb backend of
``sim.system``)."""

import cocotb

from sim.runners.cocotb import test_params
from sim.testbench.system import cocotb_scenario

PARAMS = test_params()


@cocotb.test()
async def end_to_end(dut):
    await cocotb_scenario.end_to_end(dut, PARAMS)


@cocotb.test(skip="probe_us" not in PARAMS)   # only the bench (bench/bench_system.py) asks for the probe
async def rate_probe(dut):
    await cocotb_scenario.rate_probe(dut, PARAMS)
