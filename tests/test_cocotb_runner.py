"""The cocotb runner reports a failing cocotb test as a pytest failure (so no cocotb test passes vacuously)."""

import pytest
from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import Out

from sim.runners.cocotb import run_cocotb


class Counter(wiring.Component):
    count: Out(8)
    at_zero: Out(1)   # combinational (an ``always @*`` block in the Verilog): count == 0

    def elaborate(self, platform):
        m = Module()
        m.d.sync += self.count.eq(self.count + 1)
        with m.If(self.count == 0):
            m.d.comb += self.at_zero.eq(1)
        return m


def test_passing_cocotb_test_passes():
    run_cocotb(Counter(), name="runner_selftest", test_module="cocotb_runner_selftest", simulator="icarus")


def test_passing_cocotb_test_passes_on_verilator():
    run_cocotb(Counter(), name="runner_selftest", test_module="cocotb_runner_selftest", simulator="verilator")


class Wrapper(wiring.Component):
    """A :class:`Counter` one level down (instance ``inner``): for the VPI-scope tests."""
    count: Out(8)
    at_zero: Out(1)

    def elaborate(self, platform):
        m = Module()
        m.submodules.inner = inner = Counter()
        m.d.comb += [self.count.eq(inner.count), self.at_zero.eq(inner.at_zero)]
        return m


@pytest.mark.parametrize("fast", [False, True], ids=["default", "verilator_fast"])
def test_verilator_fast_hides_only_the_hierarchy(fast):
    """``verilator_fast`` builds still pass the port-level tests, and the inner instance is hidden from VPI
    only in them (so the option is in effect, and the default build keeps the whole hierarchy)."""
    run_cocotb(Wrapper(), name="runner_selftest_wrapped", test_module="cocotb_runner_selftest",
               simulator="verilator", verilator_fast=fast, params={"expect_inner_visible": not fast})


def test_verilator_fast_failure_is_reported():
    with pytest.raises(AssertionError, match="cocotb tests failed"):
        run_cocotb(Wrapper(), name="runner_selftest_wrapped", test_module="cocotb_runner_selftest",
                   simulator="verilator", verilator_fast=True, params={"expect_inner_visible": True})


def test_icarus_fix_is_needed():
    """Without the time-zero fix, Icarus leaves the ``always @*`` output X: the check above can fail."""
    from board.export import amaranth_verilog as export_verilog
    from sim.runners.cocotb import icarus_time_zero_fix
    verilog_text = export_verilog(Counter(), "runner_selftest")
    assert icarus_time_zero_fix(verilog_text) != verilog_text
    assert "initial #0" in icarus_time_zero_fix(verilog_text)


def test_failing_cocotb_test_fails():
    with pytest.raises(AssertionError, match="cocotb tests failed"):
        run_cocotb(Counter(), name="runner_selftest", test_module="cocotb_runner_selftest", simulator="icarus",
                   params={"expect_off_by": 1})


def test_missing_test_module_fails():
    with pytest.raises(AssertionError):
        run_cocotb(Counter(), name="runner_selftest", test_module="no_such_cocotb_module", simulator="icarus")
