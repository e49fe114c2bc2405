# amaranth: UnusedElaboratable=no
"""The MIG model (sim/models/mig/) against MIG's contract as docs/memory.md states it from the facts
(/work/shared/ddr2-facts.md: the generated RTL, AR 24146, UG190's FIFO flags), not against the model's code.

The host below writes commands and data the way a design would, one clock at a time, and keeps a Python
reference: a dict of the user words written (bytes masked as ``app_wdf_mask_data`` says), the reads it issued in
order. What comes back is checked against it: every read returns two words, in command order, equal to the
reference; the latency of an isolated read is the run's drawn latency, within the documented range, plus the
documented costs (row miss, turnaround, refresh every tREFI). Every violation check is made to fire, and legal
traffic up to the almost-full slack does not fire any.
"""

import random

import pytest
from amaranth.sim import Simulator

from sim.models.mig import (MESSAGES, READ_LATENCY_RANGE, STORAGE_VERILOG, MIGModel, MIGProtocolViolation, Violation,
                            draw_latency, violation_message, watch_violations)
from spec.memory import MIG

BASE, WORDS = 0x0080_0000, 4096            # the test window: bank 1 (address bit 23), rows 0..3
SMALL = dict(af_depth=32, wdf_depth=32, window_base=BASE, window_words=WORDS, init_clocks=20)
MASK128 = (1 << 128) - 1


def addr_of(bank=1, row=0, col=0):
    """A 64-bit-word address from its fields (docs: column [9:0], row [22:10], bank [24:23])."""
    return (bank << 23) | (row << 10) | col


class Host:
    """The user's side, clock by clock, with the Python reference of what the memory must hold."""

    def __init__(self, model):
        self.model, self.clock = model, 0
        self.memory = {}                    # even 64-bit-word address -> 128-bit user word
        self.expected = []                  # per read word, in order: (command clock, expected data)
        self.returned = []                  # (clock, data) of every rd_data_valid
        self.afull = {"command": [], "write": []}
        self.init_clock = None
        self.flow_control = True            # wait while almost full (as a design must); off to test the slack

    async def step(self, ctx, *, cmd=None, addr=0, data=None, mask=0):
        """One clock: optionally a command and/or a write-data word; samples the outputs of this clock."""
        user = self.model.user
        ctx.set(user.command.wren, cmd is not None)
        ctx.set(user.command.cmd, cmd or 0)
        ctx.set(user.command.addr, addr)
        ctx.set(user.write.wren, data is not None)
        ctx.set(user.write.data, data or 0)
        ctx.set(user.write.mask, mask)
        if ctx.get(user.read.valid):
            self.returned.append((self.clock, ctx.get(user.read.data)))
        if self.init_clock is None and ctx.get(user.phy_init_done):
            self.init_clock = self.clock
        self.afull["command"].append(ctx.get(user.command.afull))
        self.afull["write"].append(ctx.get(user.write.afull))
        await ctx.tick()
        self.clock += 1

    async def idle(self, ctx, clocks):
        for _ in range(clocks):
            await self.step(ctx)

    async def until_init(self, ctx):
        while not ctx.get(self.model.user.phy_init_done):
            await self.step(ctx)
        await self.step(ctx)

    async def wait_room(self, ctx):
        """Idle while either almost-full flag was high on the last clock."""
        while self.flow_control and self.clock and (self.afull["command"][-1] or self.afull["write"][-1]):
            await self.step(ctx)

    def write_reference(self, addr, words):
        for i, (data, mask) in enumerate(words):
            old = self.memory.get(addr + 2 * i, 0)
            keep = sum(0xFF << (8 * b) for b in range(16) if mask >> b & 1)
            self.memory[addr + 2 * i] = (old & keep) | (data & ~keep & MASK128)

    async def write_burst(self, ctx, addr, words, *, command_on_word=0):
        """A BL4 write: its two words on consecutive clocks, the command with word ``command_on_word``."""
        await self.wait_room(ctx)
        for i, (data, mask) in enumerate(words):
            await self.step(ctx, data=data, mask=mask,
                            **(dict(cmd=MIG.CMD_WRITE, addr=addr) if i == command_on_word else {}))
        self.write_reference(addr, words)

    async def read_burst(self, ctx, addr):
        await self.wait_room(ctx)
        clock = self.clock
        await self.step(ctx, cmd=MIG.CMD_READ, addr=addr)
        self.expected += [(clock, self.memory.get(addr, 0)), (clock, self.memory.get(addr + 2, 0))]
        return clock

    async def drain(self, ctx, limit=400):
        """Idle until every read issued has returned (or ``limit`` clocks)."""
        for _ in range(limit):
            if len(self.returned) >= len(self.expected):
                break
            await self.step(ctx)
        await self.idle(ctx, 4)


def run(bench, *, latency=READ_LATENCY_RANGE[0], model=None, watch=True, **params):
    """Simulate ``bench(ctx, host)`` on a model (clk0 at 125 MHz); returns the host and the violation raised by
    the watcher (None if none)."""
    model = model or MIGModel(**{**SMALL, **params})
    host = Host(model)
    sim = Simulator(model)
    sim.add_clock(1 / MIG.CLK0_HZ)

    async def main(ctx):
        ctx.set(model.latency, latency)
        await bench(ctx, host)

    sim.add_testbench(main)
    if watch:
        sim.add_testbench(watch_violations(model), background=True)
    try:
        sim.run()
    except MIGProtocolViolation as violation:
        return host, violation
    return host, None


def random_words(rng, masked=True):
    return [(rng.getrandbits(128), rng.getrandbits(16) if masked and rng.random() < 0.5 else 0) for _ in range(2)]


def check_reads(host, latency):
    """Every read: two words, in order, equal to the reference, none earlier than the latency."""
    assert len(host.returned) == len(host.expected)
    for n, ((clock, got), (issued, want)) in enumerate(zip(host.returned, host.expected)):
        assert got == want, f"read word {n}: 0x{got:032x} != 0x{want:032x}"
        assert clock - issued >= latency + n % 2
    # the two words of a burst on consecutive clocks
    for n in range(0, len(host.returned), 2):
        assert host.returned[n + 1][0] == host.returned[n][0] + 1


# --- data ---------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("seed", [1, 2])
def test_written_bursts_read_back_in_order_with_masks(seed):
    """Random bursts over the window's rows, some masked, some rewritten; the command with the first or the
    second data word (both legal: the burst's first word is written by the command's clock); then reads in a
    random order, some back to back: every word equals the reference, two per read, in order."""
    rng = random.Random(seed)
    latency = draw_latency(seed, READ_LATENCY_RANGE)
    addrs = [BASE + 4 * rng.randrange(WORDS // 4) for _ in range(40)]

    async def bench(ctx, host):
        await host.until_init(ctx)
        for addr in addrs:
            await host.write_burst(ctx, addr, random_words(rng), command_on_word=rng.choice((0, 1)))
            await host.idle(ctx, rng.choice((0, 0, 3)))
        for addr in rng.sample(addrs, len(addrs)) + addrs[:5]:
            await host.read_burst(ctx, addr)
            await host.idle(ctx, rng.choice((0, 1, 5)))
        await host.drain(ctx)

    host, violation = run(bench, latency=latency)
    assert violation is None
    assert READ_LATENCY_RANGE[0] <= latency <= READ_LATENCY_RANGE[1]
    check_reads(host, latency)
    assert len(host.returned) == 2 * 45


def test_write_data_ahead_of_commands():
    """Data for several bursts first, their commands later (legal: data before address); then read back."""
    rng = random.Random(5)
    bursts = [(BASE + 64 * i, random_words(rng)) for i in range(6)]

    async def bench(ctx, host):
        await host.until_init(ctx)
        for _, words in bursts:
            for data, mask in words:
                await host.step(ctx, data=data, mask=mask)
        await host.idle(ctx, 3)
        for addr, words in bursts:
            await host.step(ctx, cmd=MIG.CMD_WRITE, addr=addr)
            host.write_reference(addr, words)
        for addr, _ in bursts:
            await host.read_burst(ctx, addr)
        await host.drain(ctx)

    host, violation = run(bench)
    assert violation is None
    check_reads(host, READ_LATENCY_RANGE[0])


# --- latency ------------------------------------------------------------------------------------------------

@pytest.mark.parametrize("seed", [3, 4])
def test_isolated_read_latency_and_its_costs(seed):
    """An isolated read of an open row in the read direction returns its first word exactly the drawn latency L
    after its command; the first read of a closed row pays an activate, a row conflict a precharge and an
    activate, a read after a write the write-to-read turnaround (spec.memory's figures)."""
    latency = draw_latency(seed, READ_LATENCY_RANGE)
    a, same_row, other_row = addr_of(row=0, col=0), addr_of(row=0, col=8), addr_of(row=1, col=0)

    async def bench(ctx, host):
        await host.until_init(ctx)
        marks = {}
        for name, addr, before in (("closed", a, None), ("open", same_row, None), ("conflict", other_row, None),
                                   ("after_write", other_row, "write")):
            if before == "write":
                await host.write_burst(ctx, addr_of(row=1, col=16), random_words(random.Random(0)))
                await host.idle(ctx, 20)                    # the write done (its own read-to-write turnaround)
            marks[name] = await host.read_burst(ctx, addr)
            await host.idle(ctx, 60)
        host.marks = marks

    host, violation = run(bench, latency=latency)
    assert violation is None
    first = {name: next(c for c, _ in host.returned if c > issued) - issued for name, issued in host.marks.items()}
    assert first == {"open": latency, "closed": latency + MIG.TRCD_CLK,
                     "conflict": latency + MIG.TRP_CLK + MIG.TRCD_CLK, "after_write": latency + MIG.WTR_CLK}


def test_latency_is_an_input_sampled_until_init():
    """The latency input counts until phy_init_done; a change afterwards does not move the reads."""
    async def bench(ctx, host):
        ctx.set(host.model.latency, 20)
        await host.until_init(ctx)
        ctx.set(host.model.latency, 30)
        await host.read_burst(ctx, addr_of())
        await host.idle(ctx, 60)
        host.mark = await host.read_burst(ctx, addr_of())
        await host.drain(ctx)

    host, violation = run(bench, latency=17)
    assert violation is None
    assert host.returned[2][0] - host.mark == 20


def test_refresh_every_trefi():
    """Reads streamed at the bus rate into one open row for over three refresh intervals: the read words come
    back to back except for a gap every tREFI (975 clk0) of at least tRFC (the refresh) + tRP (precharge all)."""
    async def bench(ctx, host):
        await host.until_init(ctx)
        for n in range(3 * MIG.TREFI_CLK // 2 + 200):
            if host.afull["command"] and host.afull["command"][-1]:
                await host.step(ctx)
                continue
            await host.read_burst(ctx, addr_of(col=4 * (n % 64)))
            await host.step(ctx)
        await host.drain(ctx, limit=2000)

    host, violation = run(bench)
    assert violation is None
    clocks = [c for c, _ in host.returned]
    gaps = [(b, b - a - 1) for a, b in zip(clocks, clocks[1:]) if b - a > 1]
    long_gaps = [(end, length) for end, length in gaps if length >= MIG.TRFC_CLK + MIG.TRP_CLK]
    assert len(long_gaps) >= 3
    starts = [end - length for end, length in long_gaps]
    assert all(abs((b - a) - MIG.TREFI_CLK) <= 1 for a, b in zip(starts, starts[1:]))
    assert all(length <= MIG.TRP_CLK + MIG.TRFC_CLK + MIG.TRCD_CLK + 1 for _, length in long_gaps)


def test_phy_init_done_after_the_start_up_delay():
    async def bench(ctx, host):
        await host.until_init(ctx)

    host, violation = run(bench, init_clocks=37)
    assert violation is None and host.init_clock == 37


# --- almost full ------------------------------------------------------------------------------------------------

def fill_data_fifo(extra):
    """Write-data words only (no command drains them) until app_wdf_afull is seen, then ``extra`` more clocks of
    words."""
    async def bench(ctx, host):
        await host.until_init(ctx)
        n = 0
        while not (host.afull["write"] and host.afull["write"][-1]):
            await host.step(ctx, data=n)
            n += 1
        host.free_at_afull = 32 - n + 1             # before the word of the clock it is first seen on
        for _ in range(extra - 1):
            await host.step(ctx, data=n)
            n += 1
        await host.idle(ctx, 5)
    return bench


def test_data_words_up_to_the_slack_are_legal():
    """app_wdf_afull is ALMOSTFULL of a multirate FIFO36 (ALMOST_FULL_OFFSET 15, asserted one write clock late,
    UG190): with a word written every clock it is first seen with 14 entries free; 14 more words fit."""
    host, violation = run(fill_data_fifo(MIG.AFULL_OFFSET - 1))
    assert violation is None
    assert host.free_at_afull == MIG.AFULL_OFFSET - 1


def test_data_word_past_the_slack_is_a_violation():
    host, violation = run(fill_data_fifo(MIG.AFULL_OFFSET))
    assert violation is not None and violation.code == Violation.DATA_AFULL


def fill_command_fifo(extra):
    """Reads every clock (the controller drains one per 2 clocks) until app_af_afull is seen (a synchronous
    FIFO36: with 15 entries free or more), then ``extra`` more."""
    async def bench(ctx, host):
        await host.until_init(ctx)
        host.flow_control = False
        while not (host.afull["command"] and host.afull["command"][-1]):
            await host.read_burst(ctx, addr_of())
        for _ in range(extra - 1):                      # the clock it was first seen on had one
            await host.read_burst(ctx, addr_of())
        await host.drain(ctx)
    return bench


def test_commands_up_to_the_slack_are_legal():
    host, violation = run(fill_command_fifo(MIG.AFULL_OFFSET))
    assert violation is None
    check_reads(host, READ_LATENCY_RANGE[0])


def test_command_past_the_slack_is_a_violation():
    host, violation = run(fill_command_fifo(MIG.AFULL_OFFSET + 1))
    assert violation is not None and violation.code == Violation.COMMAND_AFULL


# --- the other violations -------------------------------------------------------------------------------------

def violation_of(bench, **params):
    _, violation = run(bench, **params)
    assert violation is not None, "no violation reported"
    return violation


def test_command_before_its_first_data_word_is_a_violation():
    """AR 24146: the command no earlier than the burst's first data word; here it is one clock early."""
    async def bench(ctx, host):
        await host.until_init(ctx)
        await host.write_burst(ctx, addr_of(), random_words(random.Random(1)))   # legal, with the first word
        await host.step(ctx, cmd=MIG.CMD_WRITE, addr=addr_of(col=4))
        await host.step(ctx, data=1)
        await host.step(ctx, data=2)
        await host.idle(ctx, 5)
    violation = violation_of(bench)
    assert (violation.code, violation.addr) == (Violation.COMMAND_BEFORE_DATA, addr_of(col=4))


def test_missing_second_data_word_is_a_violation():
    async def bench(ctx, host):
        await host.until_init(ctx)
        await host.step(ctx, cmd=MIG.CMD_WRITE, addr=addr_of(col=8), data=1)
        await host.idle(ctx, 30)
    violation = violation_of(bench)
    assert (violation.code, violation.addr) == (Violation.WRITE_DATA_MISSING, addr_of(col=8))


@pytest.mark.parametrize("cmd, addr, code", [
    (0b010, addr_of(), Violation.UNKNOWN_COMMAND),
    (0b111, addr_of(), Violation.UNKNOWN_COMMAND),
    (MIG.CMD_READ, addr_of(col=2), Violation.UNALIGNED_ADDRESS),
    (MIG.CMD_READ, addr_of(col=1), Violation.UNALIGNED_ADDRESS),
    (MIG.CMD_READ, MIG.MEMORY_WORDS, Violation.ADDRESS_OUTSIDE_PART),
    (MIG.CMD_READ, BASE - 4, Violation.ADDRESS_OUTSIDE_WINDOW),
    (MIG.CMD_READ, BASE + WORDS, Violation.ADDRESS_OUTSIDE_WINDOW),
])
def test_bad_command_is_a_violation(cmd, addr, code):
    async def bench(ctx, host):
        await host.until_init(ctx)
        await host.read_burst(ctx, addr_of(col=4))
        await host.step(ctx, cmd=cmd, addr=addr)
        await host.idle(ctx, 5)
    violation = violation_of(bench)
    assert (violation.code, violation.addr) == (code, addr)
    assert str(violation) == violation_message(code, addr, violation.cycle)
    assert MESSAGES[code] in str(violation)


def test_edges_of_the_window_are_legal():
    async def bench(ctx, host):
        await host.until_init(ctx)
        for addr in (BASE, BASE + WORDS - 4):
            await host.write_burst(ctx, addr, random_words(random.Random(addr)))
            await host.read_burst(ctx, addr)
        await host.drain(ctx)
    host, violation = run(bench)
    assert violation is None
    check_reads(host, READ_LATENCY_RANGE[0])


#: A window over three banks: the same 64 words from 0x100 in banks 0, 1 and 2 (a frame store's buffers).
BANKED = dict(window_base=0x100, window_words=64, window_banks=3)


def test_a_window_over_banks_keeps_each_bank_s_words():
    """The same offset in three banks: three words of their own; each bank's window edges legal."""
    async def bench(ctx, host):
        await host.until_init(ctx)
        for bank in range(3):
            for offset in (0x100, 0x100 + 60):
                addr = addr_of(bank=bank) + offset
                await host.write_burst(ctx, addr, random_words(random.Random(addr)))
        for bank in range(3):
            for offset in (0x100, 0x100 + 60):
                await host.read_burst(ctx, addr_of(bank=bank) + offset)
        await host.drain(ctx)
    host, violation = run(bench, **BANKED)
    assert violation is None
    check_reads(host, READ_LATENCY_RANGE[0])


@pytest.mark.parametrize("addr", [addr_of(bank=3) + 0x100, addr_of(bank=1) + 0x100 + 64, addr_of(bank=2) + 0xFC])
def test_outside_a_window_over_banks_is_a_violation(addr):
    async def bench(ctx, host):
        await host.until_init(ctx)
        await host.step(ctx, cmd=MIG.CMD_READ, addr=addr)
        await host.idle(ctx, 5)
    violation = violation_of(bench, **BANKED)
    assert (violation.code, violation.addr) == (Violation.ADDRESS_OUTSIDE_WINDOW, addr)


@pytest.mark.parametrize("what, code", [("command", Violation.COMMAND_BEFORE_INIT),
                                        ("data", Violation.DATA_BEFORE_INIT)])
def test_traffic_before_phy_init_done_is_a_violation(what, code):
    async def bench(ctx, host):
        await host.idle(ctx, 3)
        await host.step(ctx, **(dict(cmd=MIG.CMD_READ, addr=addr_of()) if what == "command" else dict(data=5)))
        await host.idle(ctx, 3)
    violation = violation_of(bench)
    assert (violation.code, violation.cycle) == (code, 3)


def test_read_word_not_taken_is_a_violation():
    """The design's readiness (the simulation-only ``read_ready``) low when a read word comes."""
    async def bench(ctx, host):
        await host.until_init(ctx)
        await host.read_burst(ctx, addr_of())
        ctx.set(host.model.read_ready, 0)
        await host.drain(ctx)
    assert violation_of(bench).code == Violation.READ_NOT_TAKEN


def test_read_ready_high_when_words_come_is_legal():
    async def bench(ctx, host):
        await host.until_init(ctx)
        ctx.set(host.model.read_ready, 0)
        await host.read_burst(ctx, addr_of())
        await host.idle(ctx, READ_LATENCY_RANGE[0] - 2)
        ctx.set(host.model.read_ready, 1)
        await host.drain(ctx)
    host, violation = run(bench)
    assert violation is None and len(host.returned) == 2


@pytest.mark.parametrize("latency", [READ_LATENCY_RANGE[0] - 1, READ_LATENCY_RANGE[1] + 1])
def test_latency_outside_the_range_is_a_violation(latency):
    async def bench(ctx, host):
        await host.until_init(ctx)
        await host.idle(ctx, 3)
    assert violation_of(bench, latency=latency).code == Violation.LATENCY_OUT_OF_RANGE


def test_every_code_has_one_message():
    assert set(MESSAGES) == set(Violation) - {Violation.NONE}
    assert all("\n" not in m for m in MESSAGES.values())
    assert "unknown violation code" in violation_message(15, 0, 0)


def test_draw_latency_is_per_seed_and_within_the_range():
    draws = {draw_latency(seed, READ_LATENCY_RANGE) for seed in range(200)}
    assert min(draws) >= READ_LATENCY_RANGE[0] and max(draws) <= READ_LATENCY_RANGE[1] and len(draws) > 8
    assert draw_latency(7, READ_LATENCY_RANGE) == draw_latency(7, READ_LATENCY_RANGE)


@pytest.mark.parametrize("params", [dict(af_depth=24), dict(wdf_depth=16), dict(latency_range=(2, 8)),
                                    dict(af_slack=16), dict(wdf_slack=15), dict(window_words=6), dict(window_base=2),
                                    dict(window_base=MIG.MEMORY_WORDS - 4, window_words=8), dict(init_clocks=0),
                                    dict(storage="rom"), dict(window_banks=5),
                                    dict(window_banks=2, window_base=MIG.BANK_WORDS - 4, window_words=8)])
def test_bad_parameters_are_rejected(params):
    with pytest.raises(ValueError):
        MIGModel(**{**SMALL, **params})


# --- the exported model under cocotb (Verilator and Icarus) ------------------------------------------------------

def run_exported(simulator, storage, tmp_path):
    """The exported model (small) under cocotb: bursts read back in order and equal to the cocotb module's own
    reference, the latency from the ``latency`` input (no rebuild per draw), a violation reported by code with
    the one table's message."""
    import json

    from board.export import export_verilog
    from sim.runners.cocotb import run_cocotb

    latency = draw_latency(11, READ_LATENCY_RANGE)
    results = {case: tmp_path / f"{case}.json" for case in ("bursts_read_back", "violation_stops")}
    name = f"mig_model_small_{storage}"
    verilog = export_verilog(MIGModel(**SMALL, storage=storage), name)
    if storage == "verilog":
        verilog += STORAGE_VERILOG
    run_cocotb(verilog, name=name, test_module="cocotb_mig_model", simulator=simulator,
               params=dict(latency=latency, seed=3, base=BASE, words=WORDS,
                           results={case: str(path) for case, path in results.items()}))
    bursts = json.loads(results["bursts_read_back"].read_text())
    first, repeated = bursts.pop("latencies")
    assert bursts == dict(words=2 * 26, equal=True, violations=[])
    assert repeated == latency and first >= latency + MIG.WTR_CLK     # the first read after the writes
    stop = json.loads(results["violation_stops"].read_text())
    assert (stop["code"], stop["addr"]) == (Violation.UNALIGNED_ADDRESS.value, BASE + 2)
    assert stop["message"] == violation_message(Violation.UNALIGNED_ADDRESS, BASE + 2, stop["cycle"])


def test_exported_model_cocotb(simulator, tmp_path):
    """The compiled backends' model (``storage="verilog"``) on Verilator and Icarus."""
    run_exported(simulator, "verilog", tmp_path)


def test_exported_model_with_amaranth_memory_cocotb(tmp_path):
    """The Amaranth simulator's storage (an Amaranth Memory) exported, on Icarus: the same results as the
    Verilog storage, so the two storages are the same array."""
    run_exported("icarus", "memory", tmp_path)


# --- behind MIG's generated top-module port names ------------------------------------------------------------------

def test_mig_named_top_cocotb(simulator, tmp_path):
    """The model as MIG's generated top (``MEMCtrl``, its port names): a masked burst written and read back, the
    latency set per run by plusarg (no rebuild), and the simulation stopped by the model on an unaligned read
    with the table's message."""
    import json

    from board.export import export_verilog
    from sim.models.mig import LATENCY_PLUSARG, mig_top_verilog
    from sim.runners.cocotb import run_cocotb

    latency, addr = draw_latency(21, READ_LATENCY_RANGE), addr_of(bank=0, row=2, col=16)
    words, masks = [random.Random(9).getrandbits(128) for _ in range(2)], [0x00F0, 0]
    model = MIGModel(**{**SMALL, "window_base": 0}, storage="verilog")     # a window from 0, as a design's
    verilog = export_verilog(model, "mig_model_core") + STORAGE_VERILOG + mig_top_verilog(core="mig_model_core")
    result = tmp_path / "result.json"
    with pytest.raises(AssertionError) as stop:
        run_cocotb(verilog, name="MEMCtrl", test_module="cocotb_mig_top", simulator=simulator,
                   params=dict(addr=addr, words=words, masks=masks, result=str(result)),
                   plusargs=[f"+{LATENCY_PLUSARG}={latency}"])
    keep = [sum(0xFF << (8 * b) for b in range(16) if m >> b & 1) for m in masks]
    outcome = json.loads(result.read_text())
    assert outcome == dict(words=[w & ~k & MASK128 for w, k in zip(words, keep)], latency=latency + MIG.WTR_CLK)
    message = violation_message(Violation.UNALIGNED_ADDRESS, addr + 1, 0).rsplit(", clk0 cycle", 1)[0]
    assert message in str(stop.value)


def test_initial_contents_must_lie_in_the_window_of_the_memory_storage():
    from sim.models.mig import memory_words
    assert memory_words({8: 0x12, 9: 0x34, 17: 0xFF}) == {1: 0x3412, 2: 0xFF00}
    with pytest.raises(ValueError, match="outside the window"):
        MIGModel(window_base=64, window_words=64, init={128: 1})
    with pytest.raises(ValueError, match="memory"):
        MIGModel(window_base=64, window_words=64, init={64: 1}, storage="verilog")
