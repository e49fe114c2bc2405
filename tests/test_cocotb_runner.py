"""The cocotb runner reports a failing cocotb test as a pytest failure (so no cocotb test passes vacuously)."""

import pytest
from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import Out

from sim.cocotb_runner import run_cocotb


class Counter(wiring.Component):
    count: Out(8)

    def elaborate(self, platform):
        m = Module()
        m.d.sync += self.count.eq(self.count + 1)
        return m


def test_passing_cocotb_test_passes():
    run_cocotb(Counter(), name="runner_selftest", test_module="cocotb_runner_selftest", simulator="icarus")


def test_failing_cocotb_test_fails():
    with pytest.raises(AssertionError, match="cocotb tests failed"):
        run_cocotb(Counter(), name="runner_selftest", test_module="cocotb_runner_selftest", simulator="icarus",
                   params={"expect_off_by": 1})


def test_missing_test_module_fails():
    with pytest.raises(AssertionError):
        run_cocotb(Counter(), name="runner_selftest", test_module="no_such_cocotb_module", simulator="icarus")
