"""board.memory_report: each memory's template and block RAM cost, read from RTLIL Amaranth writes, against
memories whose form the test builds on purpose (and the Virtex-5 aspect ratios of UG190 worked by hand)."""

import pytest
from amaranth import Cat, ClockDomain, Module, Signal
from amaranth.back import rtlil
from amaranth.lib.memory import Memory

from board.memory_report import PROBLEMS, block_cost, lines, mapped_blocks, memories
from board.resources import reset_fanout


def _rtlil(build):
    m = Module()
    m.domains.other = ClockDomain()
    ports = build(m)
    return rtlil.convert(m, ports=ports)


def _one(depth, width, *, granularity=None, write_domain="sync", read_domain="sync", rom=False):
    def build(m):
        mem = Memory(shape=width, depth=depth, init=[1] if rom else [])
        m.submodules.mem = mem
        addr, out = Signal(range(depth)), Signal(width)
        ports = [addr, out]
        if not rom:
            w = mem.write_port(domain=write_domain, granularity=granularity)
            lanes = Signal(len(w.en))
            data = Signal(width)
            m.d.comb += [w.addr.eq(addr), w.data.eq(data), w.en.eq(lanes)]
            ports += [lanes, data]
        r = mem.read_port(domain=read_domain)
        m.d.comb += [r.addr.eq(addr), out.eq(r.data)]
        return ports
    (info,) = memories(_rtlil(build))
    return info


def test_simple_dual_port():
    info = _one(400, 40)
    assert (info.name, info.depth, info.width, info.template) == ("mem", 400, 40, "simple dual-port")
    assert info.blocks36 == 1                     # 512 x 72 simple dual-port (two 512 x 36 RAMB18 also 1)


def test_two_clocks():
    assert _one(4096, 1, write_domain="other").template == "dual-port, two clocks"


def test_lane_write_enables_are_a_problem():
    info = _one(400, 64, granularity=8)
    assert info.lanes == 8 and info.template == "lane write enables" and info.template in PROBLEMS


def test_one_enable_for_a_wide_word_is_not_lanes():
    assert _one(400, 64, granularity=64).template == "simple dual-port"


def test_asynchronous_read():
    assert _one(400, 8, read_domain="comb").template == "asynchronous read"
    assert _one(128, 24, read_domain="comb", rom=True).template == "ROM, asynchronous read"
    assert _one(128, 24, rom=True).template == "ROM, synchronous read"


def test_small_memory():
    info = _one(16, 8)
    assert info.template == "small" and info.blocks36 == 0


@pytest.mark.parametrize("depth, width, blocks", [
    (120000, 1, 4),          # 32K x 1 RAMB36, four deep
    (400, 5, 0.5),           # one RAMB18 (2K x 9 or 512 x 36)
    (400, 128, 2),           # 512 x 72 twice
    (1600, 7, 0.5),          # 2K x 9 RAMB18
    (400, 512, 7.5),         # 512 x 72 seven times + one 512 x 36 RAMB18
    (42, 77, 1.5),           # 512 x 36 RAMB18 three times
])
def test_block_cost(depth, width, blocks):
    assert block_cost(depth, width) == blocks


def test_listing_and_mapped_counts():
    info = _one(400, 40)
    netlist = {"modules": {"top": {"cells": {
        "mem.ram0": {"type": "RAMB36_EXP"}, "mem.ram1": {"type": "RAMB18"}, "memory.x": {"type": "RAMB36"}}}}}
    mapped = mapped_blocks(netlist, [info])
    assert mapped == {"mem": 1.5}
    text = "\n".join(lines([info], mapped))
    assert "simple dual-port" in text and "not block RAM by construction: none" in text


def test_reset_fanout_counts_inputs_on_the_reset_synchronisers_output():
    def ff(d, q, r=None):
        conn = {"D": [d], "Q": [q]} | ({"R": [r]} if r is not None else {})
        return {"type": "FDRE", "port_directions": {"D": "input", "Q": "output", "R": "input"},
                "connections": conn}
    netlist = {"modules": {"top": {"attributes": {"top": 1}, "netnames": {}, "cells": {
        "clocking.rst_sync_pix.stage1": ff(3, 5),
        "clocking.rst_sync_pix.stage0": ff(2, 3),
        "clocking.rst_sync_pix90.stage1": ff(2, 6),
        "a": ff(9, 10, r=5), "b": ff(10, 11, r=5), "c": ff(11, 12, r=5), "d": ff(12, 13, r=6)}}}}
    assert reset_fanout(netlist, ("pix", "pix90")) == {"pix": 3, "pix90": 1}


def test_style_attribute_marks_a_memory_distributed():
    def build(m):
        rom = Memory(shape=8, depth=128, init=[1], attrs={"ROM_STYLE": "distributed"})
        other = Memory(shape=8, depth=128, init=[1])
        m.submodules.rom, m.submodules.other = rom, other
        addr, out = Signal(7), Signal(8)
        r1, r2 = rom.read_port(), other.read_port()
        m.d.comb += [r1.addr.eq(addr), r2.addr.eq(addr), out.eq(r1.data ^ r2.data)]
        return [addr, out]
    infos = {i.name: i for i in memories(_rtlil(build))}
    assert infos["rom"].template == "distributed (ROM_STYLE/RAM_STYLE)" and infos["rom"].blocks36 == 0
    assert infos["other"].template == "ROM, synchronous read"
