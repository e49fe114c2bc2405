"""SgmPath: semi-global aggregation along one path, a group of disparities per clock (docs/depth.md, "path")."""

from amaranth import Module, Mux, Signal, signed
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from spec.sensor import SENSOR
from hdl.depth.ports import token_layout
from hdl.depth.reduce import min_tree, tree_stages

__all__ = ["SgmPath"]


class SgmPath(wiring.Component):
    """L(d) = C(d) + min(L'(d), L'(d - 1) + P1, L'(d + 1) + P1, M' + P2) - M' for the ``lanes`` disparities of
    one group per clock, and M = min over all D of L once a pixel's last group is through.

    The previous pixel's vector L' and its minimum M' are, for the horizontal path (``recurrent=True``), the
    block's own result for the pixel before (zero where the token says ``first``); for the vertical path they
    are the ``prev``/``prev_min`` inputs (the row above, from the engine's line buffer): ``prev`` a group's word
    of L' in the clock before the group's input (so group g + 1's in group g's input clock: the pixel's groups
    come in consecutive clocks, in ascending order), ``prev_min`` held from the pixel's first group until one
    clock after its last.

    Parameters
    ----------
    config : DepthConfig
    recurrent : bool
        Horizontal path (feeds itself back) or vertical path (``prev`` inputs).
    width : int
        Image width (the token's column range).

    Ports
    -----
    token, cost : In
        A group: its control token and the ``lanes`` costs C(d), d = group * lanes + k.
    prev, prev_min : In (vertical path only)
        L' of one group (``lanes`` path costs) and M'.
    l, l_token : Out
        The group's path costs, 3 clocks after its input.
    m, m_valid : Out
        The pixel's minimum, registered; ``m_valid`` pulses with it, ``result_clocks`` clocks after the input
        of the pixel's first group.

    Clock domain: ``sync``.

    Pipeline (i = the group's input clock):

    ====== ==================================================================================
    i      L'(d .. d + lanes - 1), lane 0's L'(d - 1), the last lane's L'(d + 1) of the group (horizontal:
           the read bank's front group, shifted out, zero for ``first``; vertical: ``prev`` of the clock
           before, the last lane of the one before that, lane 0 of ``prev``); register C
    i + 1  min(L'(d - 1), L'(d + 1)) + P1 over the neighbours that exist, min(L'(d), M' + P2), C - M' (M'
           read here)
    i + 2  L = min of the two + (C - M'): ``l``; horizontal: pushed into the write bank
    i + 3  minimum tree (``tree_stages(lanes)`` clocks)
    then   fold into the minimum over the groups; last group: ``m``
    ====== ==================================================================================

    The horizontal path's banks (two shift registers of G group words; docs/depth.md, "The horizontal loop")
    swap after a pixel's last group, so a pixel's groups must come in consecutive order, all of them (a pixel
    cut short is overwritten whole by the next one's groups). The loop closes when a pixel's first group comes
    ``loop_clocks`` or more clocks after the previous pixel's first group.
    """

    LATENCY = 3     # clocks from a group's input to its ``l``

    def __init__(self, config=DEPTH, *, recurrent, width=SENSOR.buf_width):
        if config.disparities % config.lanes:
            raise ValueError(f"lanes ({config.lanes}) must divide D ({config.disparities})")
        self.config = config
        self.recurrent = recurrent
        self.groups = config.disparities // config.lanes
        self.width = width
        layout = token_layout(self.groups, width)
        members = {
            "token": In(layout),
            "cost": In(data.ArrayLayout(config.cost_bits, config.lanes)),
            "l": Out(data.ArrayLayout(config.path_bits, config.lanes)),
            "l_token": Out(layout),
            "m": Out(config.path_bits),
            "m_valid": Out(1),
        }
        if not recurrent:
            members["prev"] = In(data.ArrayLayout(config.path_bits, config.lanes))
            members["prev_min"] = In(config.path_bits)
        super().__init__(members)

    @classmethod
    def loop_clocks(cls, config=DEPTH):
        """The fewest clocks between two pixels for which the horizontal loop closes."""
        return config.disparities // config.lanes + 2 + tree_stages(config.lanes)

    @classmethod
    def result_clocks(cls, config=DEPTH):
        """Clocks from a pixel's first group at the input to its ``m``."""
        return config.disparities // config.lanes + 3 + tree_stages(config.lanes)

    def elaborate(self, platform):
        m = Module()
        cfg, groups, lanes = self.config, self.groups, self.config.lanes
        pbits = cfg.path_bits
        layout = token_layout(groups, self.width)

        if self.recurrent:
            prev_min = self.m
        else:
            prev, prev_min = self.prev, self.prev_min
        first = self.token.first if self.recurrent else 0

        # i: select the group's inputs.
        tok1 = Signal(layout)
        cost1 = Signal.like(self.cost, reset_less=True)
        # L'(d) of the group's lanes, and the two neighbours outside the group: L'(d - 1) of lane k is lane
        # k - 1's L'(d), so only lane 0's L'(d - 1) and the last lane's L'(d + 1) are selected on their own.
        mid = Signal(data.ArrayLayout(pbits, lanes), reset_less=True)
        edge_below = Signal(pbits, reset_less=True)     # L'(d - 1) of lane 0
        edge_above = Signal(pbits, reset_less=True)     # L'(d + 1) of the last lane
        has_below = Signal()                            # lane 0's d - 1 exists (not group 0)
        has_above = Signal()                            # the last lane's d + 1 exists (not the last group)
        m.d.sync += [tok1.eq(self.token), cost1.eq(self.cost)]
        if self.recurrent:
            written = self._banks(m, mid, edge_below, edge_above, first)
        else:
            # ``prev`` is a group ahead: the group's word came a clock before, the group before's a clock
            # before that, and ``prev`` is the next group's (read for the last lane only where it exists).
            word = Signal(data.ArrayLayout(pbits, lanes), reset_less=True)
            word_below = Signal(pbits, reset_less=True)
            m.d.sync += [word.eq(prev), word_below.eq(word[lanes - 1])]
            m.d.sync += [mid[k].eq(word[k]) for k in range(lanes)]
            m.d.sync += [edge_below.eq(word_below), edge_above.eq(prev[0])]
        # d - 1 exists for every lane but lane 0 and d + 1 for every lane but the last, whatever the group.
        m.d.sync += [has_below.eq(self.token.group != 0), has_above.eq(self.token.group != groups - 1)]
        below = [edge_below] + [mid[k] for k in range(lanes - 1)]          # L'(d - 1)
        above = [mid[k] for k in range(1, lanes)] + [edge_above]           # L'(d + 1)

        # i + 1: the two partial minimums and C - M': min(L'(d - 1), L'(d + 1)) + P1 (over the neighbours that
        # exist: D >= 2, so at least one) and min(L'(d), M' + P2); one P1 adder a lane.
        tok2 = Signal(layout)
        low = Signal(data.ArrayLayout(pbits + 1, lanes), reset_less=True)
        high = Signal(data.ArrayLayout(pbits + 1, lanes), reset_less=True)
        offset2 = Signal(data.ArrayLayout(signed(pbits + 1), lanes), reset_less=True)
        mprev1 = Mux(tok1.first, 0, prev_min) if self.recurrent else prev_min     # M', read here
        big = mprev1 + cfg.p2
        m.d.sync += tok2.eq(tok1)
        for k in range(lanes):
            near = Mux(below[k] < above[k], below[k], above[k])
            if k == lanes - 1:
                near = Mux(has_above, near, below[k])
            if k == 0:
                near = Mux(has_below, near, above[k])
            m.d.sync += [
                low[k].eq(near + cfg.p1),
                high[k].eq(Mux(mid[k] < big, mid[k], big)),
                offset2[k].eq(cost1[k] + ~mprev1),            # C - M' - 1 (mod 2**path_bits: see L)
            ]

        # i + 2: L.
        m.d.sync += self.l_token.eq(tok2)
        # L = (C - M' - 1) - ~min = C - M' + min, mod 2**path_bits (L's width): a subtraction keeps the register as
        # the carry chain's first operand (its DI), so the choice of min shares each bit's LUT with the sum.
        values = [offset2[k] - ~Mux(high[k] < low[k], high[k], low[k]) for k in range(lanes)]
        for k in range(lanes):
            m.d.sync += self.l[k].eq(values[k])
        if self.recurrent:
            written(tok2, values)

        self._minimum(m, layout)
        return m

    def _banks(self, m, mid, edge_below, edge_above, first):
        """The horizontal path's previous pixel: two banks of G group words, shift registers, one written by a
        pixel (each group pushed in at the back at i + 2) while the other, written by the pixel before, is read
        (its front group at i, shifted out), the two swapped after a pixel's last group. A pixel's groups
        are all written (i + 2 of its last group) before the next pixel reads its first (``loop_clocks`` later)
        and read before the pixel after writes the bank again, so no bank is written and read in one clock.
        Lane 0's L'(d - 1) is the last lane of the group read before, kept; the last lane's L'(d + 1) is lane 0
        of the second group word. So: no select by group, a 2:1 choice of bank per lane. The banks' registers are
        reset (to 0, a value never read: a row's first pixel reads zeros by ``first``) so that they stay flip-flops:
        a register with a reset cannot be a shift-register LUT (SRL16E has no reset pin), and the build is short of
        LUTs, not of flip-flops (docs/depth.md, "Where the LUTs are")."""
        lanes, groups, pbits = self.config.lanes, self.groups, self.config.path_bits
        word = data.ArrayLayout(pbits, lanes)
        banks = [[Signal(word, name=f"bank{b}_{j}") for j in range(groups)] for b in range(2)]
        write_bank = Signal()                   # the bank this pixel's groups go into; the other is read
        read = self.token.go
        front = Signal(word)
        m.d.comb += front.eq(Mux(write_bank, banks[0][0].as_value(), banks[1][0].as_value()))
        above = Mux(write_bank, banks[0][1][0], banks[1][1][0]) if groups > 1 else 0
        last_read = Signal(pbits, reset_less=True)      # the last lane of the group read before
        m.d.sync += [mid[k].eq(Mux(first, 0, front[k])) for k in range(lanes)]
        m.d.sync += [edge_below.eq(Mux(first, 0, last_read)), edge_above.eq(Mux(first, 0, above))]
        with m.If(read):
            m.d.sync += last_read.eq(front[lanes - 1])

        def written(tok, values):
            for b, bank in enumerate(banks):
                writing = tok.go & (write_bank == b)
                with m.If(writing | (read & (write_bank != b))):
                    for j in range(groups - 1):
                        m.d.sync += bank[j].eq(bank[j + 1])
                    m.d.sync += [bank[-1][k].eq(values[k]) for k in range(lanes)]
            with m.If(tok.go & tok.last):
                m.d.sync += write_bank.eq(~write_bank)
        return written

    def _minimum(self, m, layout):
        """i + 3 on: the minimum over the lanes, then over the groups."""
        lanes, pbits = self.config.lanes, self.config.path_bits
        # i + 3 ...: minimum over the lanes, then over the groups.
        stages = tree_stages(lanes)
        tree_value, _ = min_tree(m, [(self.l[k], None) for k in range(lanes)], "lanes_min")
        tok = self.l_token
        for s in range(stages):
            delayed = Signal(layout, name=f"min_token{s}")
            m.d.sync += delayed.eq(tok)
            tok = delayed
        running = Signal(pbits)
        folded = Mux((tok.group == 0) | (tree_value < running), tree_value, running)
        m.d.sync += self.m_valid.eq(tok.go & tok.last)
        with m.If(tok.go):
            m.d.sync += running.eq(folded)
            with m.If(tok.last):
                m.d.sync += self.m.eq(folded)
