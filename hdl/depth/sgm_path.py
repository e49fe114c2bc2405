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
    are the ``prev``/``prev_min`` inputs (the row above, from the engine's line buffer), which must hold from
    the pixel's first group until one clock after its last.

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
    l, l_token : Out
        The group's path costs, 3 clocks after its input.
    m, m_valid : Out
        The pixel's minimum, registered; ``m_valid`` pulses with it, ``result_clocks`` clocks after the input
        of the pixel's first group.

    Clock domain: ``sync``.

    Pipeline (i = the group's input clock):

    ====== ==================================================================================
    i      select L'(d - 1 .. d + lanes) of the group (zero for ``first``); register C
    i + 1  min(L'(d), L'(d - 1) + P1), min(L'(d + 1) + P1, M' + P2), C - M' (M' read here)
    i + 2  L = min of the two + (C - M'): ``l``; horizontal: into the next-vector bank
    i + 3  horizontal, last group: current bank <- next bank; minimum tree (``tree_stages(lanes)`` clocks)
    then   fold into the minimum over the groups; last group: ``m``
    ====== ==================================================================================

    The loop closes when a pixel's first group comes ``loop_clocks`` or more clocks after the previous
    pixel's first group.
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
            members["prev"] = In(data.ArrayLayout(config.path_bits, config.disparities))
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
            current = Signal(data.ArrayLayout(pbits, cfg.disparities), reset_less=True)
            following = Signal(data.ArrayLayout(pbits, cfg.disparities), reset_less=True)
            prev, prev_min = current, self.m
        else:
            prev, prev_min = self.prev, self.prev_min
        first = self.token.first if self.recurrent else 0

        # i: select the group's inputs.
        tok1 = Signal(layout)
        cost1 = Signal.like(self.cost, reset_less=True)
        mid = Signal(data.ArrayLayout(pbits, lanes), reset_less=True)
        below = Signal(data.ArrayLayout(pbits, lanes), reset_less=True)      # L'(d - 1)
        above = Signal(data.ArrayLayout(pbits, lanes), reset_less=True)      # L'(d + 1)
        has_below = Signal(lanes)
        has_above = Signal(lanes)
        m.d.sync += [tok1.eq(self.token), cost1.eq(self.cost)]
        for k in range(lanes):
            for offset, target in ((0, mid), (-1, below), (1, above)):
                with m.Switch(self.token.group):
                    for g in range(groups):
                        d = g * lanes + k + offset
                        if 0 <= d < cfg.disparities:
                            with m.Case(g):
                                m.d.sync += target[k].eq(Mux(first, 0, prev[d]))
            m.d.sync += [
                has_below[k].eq(self.token.group * lanes + k >= 1),
                has_above[k].eq(self.token.group * lanes + k + 1 < cfg.disparities),
            ]

        # i + 1: the two partial minimums and C - M'.
        tok2 = Signal(layout)
        low = Signal(data.ArrayLayout(pbits + 1, lanes), reset_less=True)
        high = Signal(data.ArrayLayout(pbits + 1, lanes), reset_less=True)
        offset2 = Signal(data.ArrayLayout(signed(pbits + 1), lanes), reset_less=True)
        mprev1 = Mux(tok1.first, 0, prev_min) if self.recurrent else prev_min     # M', read here
        big = mprev1 + cfg.p2
        m.d.sync += tok2.eq(tok1)
        for k in range(lanes):
            cand_below = Mux(has_below[k], below[k] + cfg.p1, big)
            cand_above = Mux(has_above[k], above[k] + cfg.p1, big)
            m.d.sync += [
                low[k].eq(Mux(cand_below < mid[k], cand_below, mid[k])),
                high[k].eq(Mux(cand_above < big, cand_above, big)),
                offset2[k].eq(cost1[k] - mprev1),
            ]

        # i + 2: L.
        m.d.sync += self.l_token.eq(tok2)
        for k in range(lanes):
            value = Mux(high[k] < low[k], high[k], low[k]) + offset2[k]
            m.d.sync += self.l[k].eq(value)
            if self.recurrent:
                with m.Switch(tok2.group):
                    for g in range(groups):
                        with m.Case(g):
                            m.d.sync += following[g * lanes + k].eq(value)

        self._minimum(m, layout, following if self.recurrent else None, current if self.recurrent else None)
        return m

    def _minimum(self, m, layout, following, current):
        """i + 3 on: the minimum over the lanes, then over the groups; the horizontal banks' copy."""
        lanes, pbits = self.config.lanes, self.config.path_bits
        # i + 3 ...: minimum over the lanes, then over the groups.
        if self.recurrent:
            with m.If(self.l_token.go & self.l_token.last):
                m.d.sync += current.eq(following)
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
