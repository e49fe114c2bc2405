"""hdl.shift_add.times against Python's ``*``: every value of a small signal, several constants, both signs."""

import pytest
from amaranth import Module, Signal, signed, unsigned
from amaranth.sim import Simulator

from hdl.shift_add import times


@pytest.mark.parametrize("shape", [unsigned(6), signed(6)])
@pytest.mark.parametrize("k", [0, 1, 2, 3, 43, 400, 401, 1023])
def test_times_equals_product(shape, k):
    m = Module()
    value = Signal(shape)
    product = Signal(signed(24))
    m.d.comb += product.eq(times(value, k))
    sim = Simulator(m)
    seen = []

    async def bench(ctx):
        lo, hi = (-32, 32) if shape.signed else (0, 64)
        for v in range(lo, hi):
            ctx.set(value, v)
            seen.append((v, ctx.get(product)))

    sim.add_testbench(bench)
    sim.run()
    assert seen and all(p == v * k for v, p in seen)


def test_times_uses_no_multiplier():
    value = Signal(9)
    assert "*" not in repr(times(value, 400))


@pytest.mark.parametrize("k", [-1, 2.5])
def test_times_rejects_bad_constant(k):
    with pytest.raises(ValueError, match="non-negative integer"):
        times(Signal(4), k)
