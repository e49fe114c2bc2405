"""cocotb side of tests/test_cocotb_runner.py: a counter checked right, and (on request) checked wrong."""

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from sim.runners.cocotb import test_params


@cocotb.test()
async def combinational_outputs_defined_at_time_zero(dut):
    """Before any clock edge, an output computed in an ``always @*`` block already has its value (Icarus needs
    sim.runners.cocotb.icarus_time_zero_fix for this)."""
    from cocotb.triggers import Timer
    await Timer(1, unit="ns")
    assert dut.at_zero.value.is_resolvable, f"at_zero is {dut.at_zero.value} at time 0"
    assert int(dut.at_zero.value) == 1


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


@cocotb.test(skip="expect_inner_visible" not in test_params())
async def hierarchy_visibility(dut):
    """The design's inner instance is reachable through VPI exactly when the test expects it (it is not, by
    design, in a ``verilator_fast`` build), while the top-level ports always are."""
    from cocotb.triggers import Timer
    await Timer(1, unit="ns")
    int(dut.count.value)
    try:
        int(dut.inner.count.value)
        visible = True
    except AttributeError:
        visible = False
    assert visible == test_params()["expect_inner_visible"], f"inner instance visible: {visible}"
