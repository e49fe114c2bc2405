"""cocotb tests of the exported MIG model (sim/models/mig/; driven by tests/test_mig_model.py).

``bursts_read_back``: after ``phy_init_done``, random BL4 writes (the command with the first data word, some bytes
masked), then reads; every word comes back in order equal to this module's own reference; the first read's and
its repetition's latencies (the repetition's is the run's ``latency`` input exactly: open row, no turnaround) and
the violation codes seen (none expected) go to ``result.json``. ``violation_stops``: an unaligned read address; the model's code, address and
cycle, and the one-line message of sim.models.mig's table, go to ``result.json``.
"""

import json
import random

try:
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, ReadOnly
except ImportError:          # imported outside a cocotb run
    cocotb = None

CLOCK_PS = 8000


class Host:
    """The user's side, one falling edge per clock (inputs set there, outputs sampled there)."""

    def __init__(self, dut):
        self.dut, self.clock, self.returned = dut, 0, []

    async def step(self, cmd=None, addr=0, data=None, mask=0):
        dut = self.dut
        dut.user__command__wren.value = int(cmd is not None)
        dut.user__command__cmd.value = cmd or 0
        dut.user__command__addr.value = addr
        dut.user__write__wren.value = int(data is not None)
        dut.user__write__data.value = data or 0
        dut.user__write__mask.value = mask
        await ReadOnly()
        if dut.user__read__valid.value:
            self.returned.append((self.clock, int(dut.user__read__data.value)))
        code = int(dut.violation__code.value)
        await FallingEdge(dut.clk)
        self.clock += 1
        return code

    async def start(self, latency):
        dut = self.dut
        Clock(dut.clk, CLOCK_PS, unit="ps").start()
        dut.rst.value = 1
        dut.latency.value = latency
        dut.read_ready.value = 1
        await self.step()
        await self.step()
        dut.rst.value = 0
        while not dut.user__phy_init_done.value:
            await self.step()


if cocotb is not None:
    from sim.models.mig import violation_message
    from sim.runners.cocotb import test_params
    from spec.memory import MIG

    @cocotb.test()
    async def bursts_read_back(dut):
        p = test_params()
        rng, host, memory, expected = random.Random(p["seed"]), Host(dut), {}, []
        await host.start(p["latency"])
        base = p["base"]
        addrs = [base + 4 * rng.randrange(p["words"] // 4) for _ in range(24)]
        codes = []
        for addr in addrs:
            words = [(rng.getrandbits(128), rng.getrandbits(16) if rng.random() < 0.5 else 0) for _ in range(2)]
            for i, (data, mask) in enumerate(words):
                keep = sum(0xFF << (8 * b) for b in range(16) if mask >> b & 1)
                memory[addr + 2 * i] = (memory.get(addr + 2 * i, 0) & keep) | (data & ~keep)
                codes.append(await host.step(data=data, mask=mask,
                                             **(dict(cmd=MIG.CMD_WRITE, addr=addr) if i == 0 else {})))
            for _ in range(12):                        # slower than a row conflict: no almost full
                codes.append(await host.step())
        for _ in range(40):
            codes.append(await host.step())
        marks = []
        for addr in [addrs[0], addrs[0]] + rng.sample(addrs, len(addrs)):
            marks.append(host.clock)
            expected += [memory[addr], memory[addr + 2]]
            codes.append(await host.step(cmd=MIG.CMD_READ, addr=addr))
            for _ in range(60 if len(marks) <= 2 else 12):
                codes.append(await host.step())
        for _ in range(80):
            codes.append(await host.step())
        got = [d for _, d in host.returned]
        latencies = [next(c for c, _ in host.returned if c > m) - m for m in marks[:2]]
        with open(p["result"], "w") as f:
            json.dump(dict(words=len(got), equal=got == expected, latencies=latencies,
                           violations=sorted(set(codes) - {0})), f)

    @cocotb.test()
    async def violation_stops(dut):
        p = test_params()
        host = Host(dut)
        await host.start(p["latency"])
        await host.step(cmd=MIG.CMD_READ, addr=p["base"] + 2)
        code = 0
        for _ in range(4):
            code = code or await host.step()
        addr, cycle = int(dut.violation__addr.value), int(dut.violation__cycle.value)
        with open(p["result"], "w") as f:
            json.dump(dict(code=code, addr=addr, cycle=cycle, message=violation_message(code, addr, cycle)), f)
