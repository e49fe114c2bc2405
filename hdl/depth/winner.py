"""Winner: winner-take-all over the summed path costs, the sub-pixel fit and the validity rule (docs/depth.md,
"winner")."""

from amaranth import Module, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from spec.sensor import SENSOR
from hdl.depth.ports import token_layout
from hdl.depth.reduce import min_tree, tree_stages
from hdl.depth.subpixel import Subpixel

__all__ = ["Winner"]


class Winner(wiring.Component):
    """S(d) = L_h(d) + L_v(d) a group at a time; d* = the smallest d with the smallest S, tracked with its
    neighbours S(d* - 1) and S(d* + 1); then :class:`hdl.depth.subpixel.Subpixel`: the code 2**F d* + q, or
    the invalid code when S(d*) is above ``max_cost`` or d* = D - 1.

    Parameters
    ----------
    config : DepthConfig
        D, lanes, ``max_cost``, ``fraction_bits``.
    width : int
        Image width (the token's column range).

    Ports
    -----
    token, horizontal, vertical : In
        A group's token and its two path costs (the same group of the same pixel; a pixel's groups in
        consecutive clocks).
    code, x, valid : Out
        The pixel's code and column; ``valid`` pulses with them, :meth:`latency` clocks after its last group.

    Clock domain: ``sync``. Pipeline: sum; the group's minimum with each lane's neighbours
    (``tree_stages(lanes)`` clocks); fold into the pixel's running winner (a later group must be strictly
    smaller; S(d* + 1) of a winner in a group's last lane comes from the next group's first lane); then the
    sub-pixel stage (``Subpixel.latency``).
    """

    def __init__(self, config=DEPTH, width=SENSOR.buf_width):
        self.config = config
        self.groups = config.disparities // config.lanes
        self.width = width
        super().__init__({
            "token": In(token_layout(self.groups, width)),
            "horizontal": In(data.ArrayLayout(config.path_bits, config.lanes)),
            "vertical": In(data.ArrayLayout(config.path_bits, config.lanes)),
            "code": Out(config.code_bits),
            "x": Out(range(width)),
            "valid": Out(1),
        })

    @classmethod
    def latency(cls, config=DEPTH):
        """Clocks from a pixel's last group at the input to ``valid``."""
        return 2 + tree_stages(config.lanes) + Subpixel.latency(config)

    def elaborate(self, platform):
        m = Module()
        cfg, lanes, sb = self.config, self.config.lanes, self.config.sum_bits
        layout = token_layout(self.groups, self.width)
        tok = Signal(layout)
        total = Signal(data.ArrayLayout(sb, lanes))
        m.d.sync += tok.eq(self.token)
        for k in range(lanes):
            m.d.sync += total[k].eq(self.horizontal[k] + self.vertical[k])
        # The previous group's last lane: S(d - 1) of this group's lane 0 (the pixel's groups are consecutive).
        prev_last = Signal(sb)
        m.d.sync += prev_last.eq(total[lanes - 1])
        lane_bits = max(1, (lanes - 1).bit_length())
        payload = data.StructLayout({"lane": lane_bits, "below": sb, "above": sb})
        items = []
        for k in range(lanes):
            leaf = Signal(payload, name=f"winner_leaf{k}")
            m.d.comb += [leaf.lane.eq(k), leaf.below.eq(total[k - 1] if k else prev_last),
                         leaf.above.eq(total[k + 1] if k + 1 < lanes else 0)]
            items.append((total[k], leaf.as_value()))
        value, packed = min_tree(m, items, "winner")
        found = payload(packed)
        first_lane = total[0]
        for s in range(tree_stages(lanes)):
            delayed = Signal(layout, name=f"winner_token{s}")
            lane0 = Signal(sb, name=f"winner_lane0_{s}")
            m.d.sync += [delayed.eq(tok), lane0.eq(first_lane)]
            tok, first_lane = delayed, lane0

        best, below, above = Signal(sb), Signal(sb), Signal(sb)
        best_d = Signal(range(cfg.disparities))
        pending = Signal()          # the winner sits in a group's last lane: S(d* + 1) is the next group's lane 0
        final = Signal()
        final_x = Signal(range(self.width))
        take = (tok.group == 0) | (value < best)
        m.d.sync += [final.eq(tok.go & tok.last), final_x.eq(tok.x)]
        with m.If(tok.go & take):
            m.d.sync += [best.eq(value), best_d.eq(tok.group * lanes + found.lane), below.eq(found.below),
                         above.eq(found.above), pending.eq(found.lane == lanes - 1)]
        with m.Elif(tok.go & pending):
            m.d.sync += [above.eq(first_lane), pending.eq(0)]

        m.submodules.subpixel = subpixel = Subpixel(cfg, self.width)
        m.d.comb += [
            subpixel.valid.eq(final), subpixel.x.eq(final_x), subpixel.d.eq(best_d),
            subpixel.below.eq(below), subpixel.best.eq(best), subpixel.above.eq(above),
            self.valid.eq(subpixel.out_valid), self.x.eq(subpixel.out_x), self.code.eq(subpixel.code),
        ]
        return m
