"""The frame store's memory arbiter against the MIG model (sim/models/mig, its checker stopping the run on any
violation: nothing before phy_init_done, data before command, nothing written after almost full beyond MIG's room, no
read word left untaken): what it writes lands, each reader gets its own words in order, and the priority is the
documented one."""

import random

from amaranth import DomainRenamer, Module
from amaranth.lib import wiring
from amaranth.sim import Simulator

from hdl.frame_store.arbiter import MemoryArbiter
from sim.models.mig import MIGModel, watch_violations
from spec.memory import MIG

#: The model's memory: the words the tests use (bursts from 0x100 to 0x2000 + 96).
WINDOW = dict(window_base=0x100, window_words=0x2000)


def simulate(arbiter, clients, clocks, latency=17, **model_kwargs):
    """Run ``arbiter`` on the MIG model (``model_kwargs`` on top of small FIFOs) with ``clients`` (async testbench
    functions of ``ctx``) for ``clocks``; the commands MIG took, ``(clock, cmd, addr)``, the first clock of
    ``phy_init_done``, the clocks of ``app_af_afull`` or ``app_wdf_afull`` high and the most read bursts in flight
    (commanded, their second word not yet returned)."""
    m = Module()
    m.submodules.arbiter = DomainRenamer("mem")(arbiter)
    model = MIGModel(**{"af_depth": 32, "wdf_depth": 32, "init_clocks": 20, **WINDOW, **model_kwargs})
    m.submodules.mig = DomainRenamer("mem")(model)
    wiring.connect(m, arbiter.mig, model.user)
    seen = {"commands": [], "init": None, "afull": 0, "in_flight": 0}
    user = arbiter.mig

    async def set_up(ctx):
        ctx.set(model.latency, latency)

    async def monitor(ctx):
        clock, reads, words = 0, 0, 0
        async for _, _, wren, cmd, addr, init, af_afull, wdf_afull, valid in ctx.tick("mem").sample(
                user.command.wren, user.command.cmd, user.command.addr, user.phy_init_done, user.command.afull,
                user.write.afull, user.read.valid):
            if wren:
                seen["commands"].append((clock, cmd, addr))
                reads += cmd == MIG.CMD_READ
            words += valid
            seen["in_flight"] = max(seen["in_flight"], reads - words // 2)
            if init and seen["init"] is None:
                seen["init"] = clock
            seen["afull"] += af_afull | wdf_afull
            clock += 1

    async def stop(ctx):
        await ctx.tick("mem").repeat(clocks)

    sim = Simulator(m)
    sim.add_clock(1 / MIG.CLK0_HZ, domain="mem")
    sim.add_testbench(set_up)
    sim.add_testbench(watch_violations(model), background=True)
    sim.add_testbench(monitor, background=True)
    for client in clients:
        sim.add_testbench(client, background=True)
    sim.add_testbench(stop)
    sim.run()
    return seen


def burst(rng):
    return rng.getrandbits(256), rng.getrandbits(32) & rng.choice([0, 0, 0xFFFF0000, 0x0000000F])


def test_writes_land_and_reads_return_to_their_reader():
    arbiter = MemoryArbiter(writers=2, readers=2, urgent=1)
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

    seen = simulate(arbiter, [writer(0), writer(1), reader(0), reader(1), receiver(0), receiver(1)], 1200)
    assert seen["commands"][0][0] > seen["init"]
    for r in range(2):
        assert len(got[r]) == 2 * len(asked[r]) == 48
        for k, addr in enumerate(asked[r]):
            data, mask = written[addr]
            kept = sum(0xFF << (8 * b) for b in range(32) if not (mask >> b) & 1)
            # each burst written once into the model's zeros: its unmasked bytes, zeros where masked
            assert got[r][2 * k] | (got[r][2 * k + 1] << 128) == data & kept


def test_priority_and_mig_rules():
    """All clients request at once, always: the urgent reader gets every grant it can, then the writers, the other
    reader only when nothing else asks; nothing is issued before phy_init_done, and with refreshes every 80 clocks
    taking 45 the FIFOs run almost full without a command beyond MIG's room; the reads in flight reach the tag FIFO's
    4 entries and never pass them."""
    arbiter = MemoryArbiter(writers=1, readers=2, urgent=1, read_tags=4)
    order = []

    async def clients(ctx):
        w, urgent, late = arbiter.writers[0], arbiter.readers[0], arbiter.readers[1]
        for client, addr in ((w, 0x100), (urgent, 0x200), (late, 0x300)):
            ctx.set(client.request, 1)
            ctx.set(client.addr, addr)
        stop_urgent = 80
        for clock in range(400):
            if clock == stop_urgent:
                ctx.set(urgent.request, 0)
            if clock == 140:
                ctx.set(w.request, 0)
            await ctx.tick("mem")
            order.extend(name for name, c in (("write", w), ("urgent", urgent), ("late", late)) if ctx.get(c.grant))

    seen = simulate(arbiter, [clients], 460, trefi=80, trfc=40)
    assert seen["commands"][0][0] > seen["init"] and seen["afull"] > 0
    first_write = order.index("write")
    assert "write" not in order[:order.index("urgent")] and "late" not in order[:first_write]
    assert order.index("late") > first_write and set(order[:order.index("late")]) == {"urgent", "write"}
    reads = [c for c in seen["commands"] if c[1] == MIG.CMD_READ]
    assert len(reads) >= 4
    assert seen["in_flight"] == 4
