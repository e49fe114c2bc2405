"""The frame store's memory arbiter against a behavioural model of MIG's user interface (tests/frame_store_memory.py,
from the facts sheet): what it writes lands, each reader gets its own words in order, MIG's rules hold (nothing
before phy_init_done, data before command, no FIFO overfilled), and the priority is the documented one."""

import random

from amaranth import DomainRenamer
from amaranth.sim import Simulator

from frame_store_memory import MemoryModel
from hdl.frame_store.arbiter import MemoryArbiter
from spec.memory import MIG


def simulate(arbiter, clients, model, clocks):
    """Run ``arbiter`` with the model and ``clients`` (async testbench functions of ``ctx``) for ``clocks``."""
    sim = Simulator(DomainRenamer("mem")(arbiter))
    sim.add_clock(8e-9, domain="mem")

    async def memory(ctx):
        await model.run(ctx, arbiter.mig)

    async def stop(ctx):
        await ctx.tick("mem").repeat(clocks)

    sim.add_testbench(memory, background=True)
    for client in clients:
        sim.add_testbench(client, background=True)
    sim.add_testbench(stop)
    sim.run()


def burst(rng):
    return rng.getrandbits(256), rng.getrandbits(32) & rng.choice([0, 0, 0xFFFF0000, 0x0000000F])


def test_writes_land_and_reads_return_to_their_reader():
    arbiter = MemoryArbiter(writers=2, readers=2, urgent=1)
    model = MemoryModel(seed=3, stall_rate=0.1)
    rng = random.Random(5)
    written = {}                                        # burst address -> (data, mask), in grant order
    bursts = {w: [(0x1000 * (w + 1) + 4 * k, *burst(rng)) for k in range(24)] for w in range(2)}
    got = {0: [], 1: []}
    asked = {0: [], 1: []}

    def writer(w):
        async def run(ctx):
            client = arbiter.writers[w]
            for addr, data, mask in bursts[w]:
                ctx.set(client.request, 1)
                ctx.set(client.addr, addr)
                ctx.set(client.data, data)
                ctx.set(client.mask, mask)
                await ctx.tick("mem").until(client.grant)
                written[addr] = (data, mask)
            ctx.set(client.request, 0)
        return run

    def reader(r):
        async def run(ctx):
            client = arbiter.readers[r]
            await ctx.tick("mem").repeat(400)          # after the writes
            for k in range(24):
                addr = 0x1000 * (r + 1) + 4 * k
                ctx.set(client.request, 1)
                ctx.set(client.addr, addr)
                await ctx.tick("mem").until(client.grant)
                asked[r].append(addr)
                ctx.set(client.request, 0)
                await ctx.tick("mem").repeat(rng.randrange(1, 3))
        return run

    def receiver(r):
        async def run(ctx):
            client = arbiter.readers[r]
            async for _, _, data, valid in ctx.tick("mem").sample(client.data, client.valid):
                if valid:
                    got[r].append(data)
        return run

    simulate(arbiter, [writer(0), writer(1), reader(0), reader(1), receiver(0), receiver(1)], model, 1200)
    assert model.violations == []
    for r in range(2):
        assert len(got[r]) == 2 * len(asked[r]) == 48
        for k, addr in enumerate(asked[r]):
            data, mask = written[addr]
            expect = int.from_bytes(bytes(model.read_bytes(addr * 8, 32)), "little")
            kept = sum(0xFF << (8 * b) for b in range(32) if not (mask >> b) & 1)
            assert expect & kept == data & kept
            assert got[r][2 * k] | (got[r][2 * k + 1] << 128) == expect


def test_priority_and_mig_rules():
    """All clients request at once, always: the urgent reader gets every grant it can, then the writers, the other
    reader only when nothing else asks; nothing is issued before phy_init_done or while a FIFO is almost full."""
    arbiter = MemoryArbiter(writers=1, readers=2, urgent=1, read_tags=4)
    model = MemoryModel(seed=1, stall_rate=0.2, latency=9)
    order = []

    async def clients(ctx):
        w, urgent, late = arbiter.writers[0], arbiter.readers[0], arbiter.readers[1]
        for client, addr in ((w, 0x100), (urgent, 0x200), (late, 0x300)):
            ctx.set(client.request, 1)
            ctx.set(client.addr, addr)
        stop_urgent = 80
        for clock in range(200):
            if clock == stop_urgent:
                ctx.set(urgent.request, 0)
            if clock == 140:
                ctx.set(w.request, 0)
            await ctx.tick("mem")
            order.extend(name for name, c in (("write", w), ("urgent", urgent), ("late", late)) if ctx.get(c.grant))

    simulate(arbiter, [clients], model, 260)
    assert model.violations == []
    assert model.commands[0][0] >= model.init_clocks
    first_write = order.index("write")
    assert "write" not in order[:order.index("urgent")] and "late" not in order[:first_write]
    assert order.index("late") > first_write and set(order[:order.index("late")]) == {"urgent", "write"}
    reads = [c for c in model.commands if c[1] == MIG.CMD_READ]
    assert len(reads) >= 4
