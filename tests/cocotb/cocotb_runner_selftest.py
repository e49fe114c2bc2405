"""cocotb side of tests/test_cocotb_runner.py: a counter checked right, and (on request) checked wrong."""

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from sim.cocotb_runner import test_params


@cocotb.test()
async def counter_counts(dut):
    expect_off_by = test_params().get("expect_off_by", 0)
    cocotb.start_soon(Clock(dut.clk, 10, unit="ns").start())
    dut.rst.value = 1
    await ClockCycles(dut.clk, 2)
    dut.rst.value = 0
    await RisingEdge(dut.clk)
    await ReadOnly()
    start = int(dut.count.value)
    for n in range(1, 20):
        await RisingEdge(dut.clk)
        await ReadOnly()
        assert int(dut.count.value) == (start + n + expect_off_by) % 256, "counter value"
