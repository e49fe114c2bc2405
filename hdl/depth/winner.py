"""Winner: winner-take-all over the summed path costs, and the validity rule (docs/depth.md, "winner")."""

from amaranth import C, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from spec.sensor import SENSOR
from hdl.depth.ports import token_layout
from hdl.depth.reduce import min_tree, tree_stages

__all__ = ["Winner"]


class Winner(wiring.Component):
    """S(d) = L_h(d) + L_v(d) a group at a time; the smallest d with the smallest S; the code d, or D when that
    S is above ``max_cost`` or d = D - 1.

    Parameters
    ----------
    config : DepthConfig
        D, lanes, ``max_cost``.
    width : int
        Image width (the token's column range).

    Ports
    -----
    token, horizontal, vertical : In
        A group's token and its two path costs (the same group of the same pixel).
    code, x, valid : Out
        The pixel's code and column; ``valid`` pulses with them, ``LATENCY`` clocks after its last group.

    Clock domain: ``sync``. Pipeline: sum; the group's minimum (``tree_stages(lanes)`` clocks); fold into the
    pixel's running winner (a later group must be strictly smaller); validity.
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
        return 3 + tree_stages(config.lanes)

    def elaborate(self, platform):
        m = Module()
        cfg, lanes = self.config, self.config.lanes
        layout = token_layout(self.groups, self.width)
        tok = Signal(layout)
        total = Signal(data.ArrayLayout(cfg.sum_bits, lanes), reset_less=True)
        m.d.sync += tok.eq(self.token)
        for k in range(lanes):
            m.d.sync += total[k].eq(self.horizontal[k] + self.vertical[k])
        lane_bits = max(1, (lanes - 1).bit_length())
        value, lane = min_tree(m, [(total[k], C(k, lane_bits)) for k in range(lanes)], "winner")
        for s in range(tree_stages(lanes)):
            delayed = Signal(layout, name=f"winner_token{s}")
            m.d.sync += delayed.eq(tok)
            tok = delayed

        best = Signal(cfg.sum_bits)
        best_d = Signal(range(cfg.disparities))
        final = Signal()
        final_x = Signal(range(self.width))
        d = tok.group * lanes + lane
        take = (tok.group == 0) | (value < best)
        m.d.sync += [final.eq(tok.go & tok.last), final_x.eq(tok.x)]
        with m.If(tok.go & take):
            m.d.sync += [best.eq(value), best_d.eq(d)]

        invalid = (best > cfg.max_cost) | (best_d == cfg.disparities - 1)
        m.d.sync += [
            self.valid.eq(final),
            self.x.eq(final_x),
            self.code.eq(Mux(invalid, cfg.invalid, best_d)),
        ]
        return m
