"""What every harness of the MIG model shares: the per-run latency draw and, for Amaranth's simulator, the
background testbench that stops the simulation on the model's first violation."""

import random

from .violations import MIGProtocolViolation, Violation

__all__ = ["draw_latency", "watch_violations"]


def draw_latency(seed, latency_range):
    """The run's read latency (the model's ``latency`` input): drawn from ``latency_range`` (inclusive) by
    ``seed``, the same for the same seed on every backend."""
    lo, hi = latency_range
    return random.Random(f"mig-latency-{seed}").randint(lo, hi)


def watch_violations(model):
    """An Amaranth testbench (``sim.add_testbench(watch_violations(model), background=True)``) that raises
    :class:`MIGProtocolViolation` (its message from the one table) on the clock ``model.violation.code`` leaves
    ``Violation.NONE``."""
    async def testbench(ctx):
        async for code, addr, cycle in ctx.changed(model.violation.code, model.violation.addr,
                                                   model.violation.cycle):
            if code != Violation.NONE:
                raise MIGProtocolViolation(code, addr, cycle)
    return testbench
