"""A small behavioural model of MIG's user interface for the frame store's tests, written from the facts sheet
(/work/shared/ddr2-facts.md; spec/memory.py): commands and write data in FIFOs with almost-full flags, data before
command for a write, two words a read returned in command order after a fixed latency with no backpressure,
nothing before ``phy_init_done``, and stalls (refresh) that keep the FIFOs from draining. It records every rule a
client breaks in ``violations``."""

import random

from spec.memory import MIG


class MemoryModel:
    """Drive it with ``await model.run(ctx, mig)`` as a background testbench in the ``mem`` domain (``mig`` the
    controller's side: the user's ``Out(MIGUserSignature())`` member)."""

    def __init__(self, *, latency=17, init_clocks=20, stall_rate=0.05, seed=0, af_depth=32, wdf_depth=32):
        self.latency, self.init_clocks, self.stall_rate = latency, init_clocks, stall_rate
        self.rng = random.Random(seed)
        self.af_depth, self.wdf_depth = af_depth, wdf_depth
        self.words = {}                 # 64-bit memory word address -> 8 bytes
        self.af, self.wdf, self.returns = [], [], []
        self.violations, self.commands = [], []
        self.now = 0

    def read_bytes(self, address, count):
        """``count`` bytes from byte address ``address``."""
        return [self.words.get((address + k) // 8, [0] * 8)[(address + k) % 8] for k in range(count)]

    def _store(self, addr, data, mask):
        for half in range(2):
            word = self.words.setdefault(addr + half, [0] * 8)
            for b in range(8):
                k = 8 * half + b
                if not (mask >> k) & 1:
                    word[b] = (data >> (8 * k)) & 0xFF

    def _load(self, addr):
        value = 0
        for half in range(2):
            word = self.words.get(addr + half, [0] * 8)
            for b in range(8):
                value |= word[b] << (8 * (8 * half + b))
        return value

    def _accept(self, ctx, mig, init):
        if ctx.get(mig.write.wren):
            if not init:
                self.violations.append((self.now, "write data before phy_init_done"))
            if len(self.wdf) >= self.wdf_depth:
                self.violations.append((self.now, "write-data FIFO overfilled"))
            self.wdf.append((ctx.get(mig.write.data), ctx.get(mig.write.mask)))
        if ctx.get(mig.command.wren):
            cmd, addr = ctx.get(mig.command.cmd), ctx.get(mig.command.addr)
            self.commands.append((self.now, cmd, addr))
            if not init:
                self.violations.append((self.now, "command before phy_init_done"))
            if addr % MIG.BURST_LENGTH:
                self.violations.append((self.now, f"address {addr} not burst-aligned"))
            if len(self.af) >= self.af_depth:
                self.violations.append((self.now, "address FIFO overfilled"))
            # AR 24146: a BL4 write command no earlier than its burst's first data word.
            if cmd == MIG.CMD_WRITE and len(self.wdf) - 2 * sum(c == MIG.CMD_WRITE for c, _ in self.af) < 1:
                self.violations.append((self.now, f"write command at {addr} ahead of its data"))
            self.af.append((cmd, addr))

    def _serve(self):
        """One command every other clock unless stalled (a refresh, a row miss)."""
        if self.af and self.now % 2 == 0 and self.rng.random() >= self.stall_rate * 4:
            cmd, addr = self.af.pop(0)
            if cmd == MIG.CMD_WRITE:
                if len(self.wdf) < 2:
                    self.violations.append((self.now, f"write at {addr} served without its two data words"))
                    return
                for k in range(2):
                    data, mask = self.wdf.pop(0)
                    self._store(addr + 2 * k, data, mask)
            else:
                for k in range(2):
                    self.returns.append((self.now + self.latency + k, self._load(addr + 2 * k)))

    async def run(self, ctx, mig):
        while True:
            init = self.now >= self.init_clocks
            ctx.set(mig.phy_init_done, int(init))
            self._accept(ctx, mig, init)
            self._serve()
            ready = self.returns and self.returns[0][0] <= self.now
            ctx.set(mig.read.valid, int(bool(ready)))
            if ready:
                ctx.set(mig.read.data, self.returns.pop(0)[1])
            stall = self.rng.random() < self.stall_rate
            ctx.set(mig.command.afull, int(stall or len(self.af) >= self.af_depth - MIG.AFULL_OFFSET))
            ctx.set(mig.write.afull, int(stall or len(self.wdf) >= self.wdf_depth - MIG.AFULL_OFFSET))
            await ctx.tick("mem")
            self.now += 1
