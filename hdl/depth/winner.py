"""Winner: winner-take-all over the summed path costs, the sub-pixel fit and the validity rule (docs/depth.md,
"winner")."""

from amaranth import Array, C, Module, Mux, Signal
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
    neighbours S(d* - 1) and S(d* + 1); the confidence S2 = the smallest S at |d - d*| >= 2; then
    :class:`hdl.depth.subpixel.Subpixel`: the code 2**F d* + q, or the invalid code when S(d*) is above
    ``max_cost``, d* = D - 1 or 64 S* > ``uniqueness`` x S2.

    Parameters
    ----------
    config : DepthConfig
        D, lanes, ``max_cost``, ``fraction_bits``.
    width : int
        Image width (the token's column range).
    vertical_bits : int or None
        Width of the ``vertical`` input (``path_bits`` when None): the engine's three-path mode brings there the
        sum of two paths (S2, docs/depth.md "The third path in the RTL") beside the right-to-left L.

    Ports
    -----
    token, horizontal, vertical : In
        A group's token and its two path costs (the same group of the same pixel; a pixel's groups in
        consecutive clocks; pixels at least G + 2 + ``tree_stages(lanes)`` clocks apart, as the engine's
        step is).
    code, x, d, valid : Out
        The pixel's code, column and integer winner d* (before the fit); ``valid`` pulses with them,
        :meth:`latency` clocks after its last group.
    sums_token, sums : Out
        Each group's token and its sums S(d) = horizontal + vertical, one clock after the input (the sums the
        winner takes: ``hdl.depth.left_winner.LeftWinner``'s input).

    Clock domain: ``sync``. Pipeline: sum; the group's minimum with each lane's neighbours
    (``tree_stages(lanes)`` clocks); fold into the pixel's running winner (a later group must be strictly
    smaller; S(d* + 1) of a winner in a group's last lane comes from the next group's first lane); the winner
    held; its sums replayed G + t clocks later (t = ``tree_stages(lanes)``), masked at d* - 1 .. d* + 1, a
    second tree into S2 (t clocks), folded; k S2; then the sub-pixel stage (``Subpixel.latency``): latency
    4 + G + 2 t + ``Subpixel.latency``.
    """

    def __init__(self, config=DEPTH, width=SENSOR.buf_width, vertical_bits=None):
        self.config = config
        self.groups = config.disparities // config.lanes
        self.width = width
        super().__init__({
            "token": In(token_layout(self.groups, width)),
            "horizontal": In(data.ArrayLayout(config.path_bits, config.lanes)),
            "vertical": In(data.ArrayLayout(vertical_bits or config.path_bits, config.lanes)),
            "code": Out(config.code_bits),
            "x": Out(range(width)),
            "d": Out(range(config.disparities)),
            "valid": Out(1),
            "sums_token": Out(token_layout(self.groups, width)),
            "sums": Out(data.ArrayLayout(config.sum_bits, config.lanes)),
        })

    @classmethod
    def latency(cls, config=DEPTH):
        """Clocks from a pixel's last group at the input to ``valid``."""
        return 4 + config.disparities // config.lanes + 2 * tree_stages(config.lanes) + Subpixel.latency(config)

    def elaborate(self, platform):
        m = Module()
        cfg, lanes, sb = self.config, self.config.lanes, self.config.sum_bits
        layout = token_layout(self.groups, self.width)
        tok = Signal(layout)
        total = Signal(data.ArrayLayout(sb, lanes), reset_less=True)
        m.d.sync += tok.eq(self.token)
        for k in range(lanes):
            m.d.sync += total[k].eq(self.horizontal[k] + self.vertical[k])
        m.d.comb += [self.sums_token.eq(tok), self.sums.eq(total)]
        # The previous group's last lane: S(d - 1) of this group's lane 0 (the pixel's groups are consecutive).
        prev_last = Signal(sb, reset_less=True)
        m.d.sync += prev_last.eq(total[lanes - 1])
        # The tree carries each lane's index only; the winner's neighbours S(d* - 1), S(d* + 1) are picked after
        # it from the group's sums, delayed as long as the tree takes: [S(d0 - 1), S(d0), .., S(d0 + lanes - 1)].
        lane_bits = max(1, (lanes - 1).bit_length())
        items = []
        for k in range(lanes):
            lane = Signal(lane_bits, name=f"winner_leaf{k}")
            m.d.comb += lane.eq(k)
            items.append((total[k], lane))
        value, found_lane = min_tree(m, items, "winner")
        sums = [prev_last] + [total[k] for k in range(lanes)]
        for s in range(tree_stages(lanes)):
            delayed = Signal(layout, name=f"winner_token{s}")
            late = [Signal(sb, name=f"winner_sums{s}_{i}", reset_less=True) for i in range(lanes + 1)]
            m.d.sync += [delayed.eq(tok)] + [late[i].eq(sums[i]) for i in range(lanes + 1)]
            tok, sums = delayed, late
        found_below = Array(sums[:lanes])[found_lane]                       # S(d - 1) of the winning lane
        found_above = Array(sums[2:] + [C(0, sb)])[found_lane]              # S(d + 1); none after the last lane
        first_lane = sums[1]

        # Data registers: read only behind a token whose ``go`` is set, so reset-less (the reset-tree fanout).
        best, below, above = (Signal(sb, reset_less=True) for _ in range(3))
        best_d = Signal(range(cfg.disparities), reset_less=True)
        pending = Signal()          # the winner sits in a group's last lane: S(d* + 1) is the next group's lane 0
        final = Signal()
        final_x = Signal(range(self.width), reset_less=True)
        take = (tok.group == 0) | (value < best)
        m.d.sync += [final.eq(tok.go & tok.last), final_x.eq(tok.x)]
        with m.If(tok.go & take):
            m.d.sync += [best.eq(value), best_d.eq(tok.group * lanes + found_lane), below.eq(found_below),
                         above.eq(found_above), pending.eq(found_lane == lanes - 1)]
        with m.Elif(tok.go & pending):
            m.d.sync += [above.eq(first_lane), pending.eq(0)]
        # Hold the winner while the second best is found (the next pixel's fold starts T clocks later).
        held = {name: Signal.like(sig, name=f"held_{name}", reset_less=True) for name, sig in
                (("best", best), ("d", best_d), ("below", below), ("above", above), ("x", final_x))}
        with m.If(final):
            m.d.sync += [held["best"].eq(best), held["d"].eq(best_d), held["below"].eq(below),
                         held["above"].eq(above), held["x"].eq(final_x)]
        ambiguous, ready = self._uniqueness(m, total, tok, best_d, held["best"])

        m.submodules.subpixel = subpixel = Subpixel(cfg, self.width)
        m.d.comb += [
            subpixel.valid.eq(ready), subpixel.x.eq(held["x"]), subpixel.d.eq(held["d"]),
            subpixel.below.eq(held["below"]), subpixel.best.eq(held["best"]), subpixel.above.eq(held["above"]),
            subpixel.ambiguous.eq(ambiguous),
            self.valid.eq(subpixel.out_valid), self.x.eq(subpixel.out_x), self.code.eq(subpixel.code),
            self.d.eq(subpixel.out_d),
        ]
        return m

    def _uniqueness(self, m, total, tok, best_d, held_best):
        """The confidence: the pixel's sums replayed once d* is known (delayed G + t clocks), the lanes 2 or
        more from d* through a second minimum tree into S2; then k S2 (k = ``uniqueness``) registered and
        compared with 64 S*. Returns (ambiguous, ready): ``ready`` pulses G + t + 2 clocks after the fold's
        ``final``, with ``ambiguous`` = 64 S* > k S2 in the same clock."""
        cfg, lanes, sb = self.config, self.config.lanes, self.config.sum_bits
        layout = token_layout(self.groups, self.width)
        replay, rtok = total, tok
        for s in range(self.groups + tree_stages(lanes)):
            delayed = Signal.like(replay, name=f"replay_total{s}")
            m.d.sync += delayed.eq(replay)
            replay = delayed
        for s in range(self.groups):
            delayed = Signal(layout, name=f"replay_token{s}")
            m.d.sync += delayed.eq(rtok)
            rtok = delayed
        none = (1 << sb) - 1                    # above every sum: "no such disparity"
        masked = Signal(data.ArrayLayout(sb, lanes), reset_less=True)
        mtok = Signal(layout)
        m.d.sync += mtok.eq(rtok)
        for k in range(lanes):
            d = rtok.group * lanes + k
            far = (d + 1 < best_d) | (d > best_d + 1)
            m.d.sync += masked[k].eq(Mux(far, replay[k], none))
        value, _ = min_tree(m, [(masked[k], None) for k in range(lanes)], "second")
        for s in range(tree_stages(lanes)):
            delayed = Signal(layout, name=f"second_token{s}")
            m.d.sync += delayed.eq(mtok)
            mtok = delayed
        second, done = Signal(sb, reset_less=True), Signal()
        with m.If(mtok.go):
            m.d.sync += second.eq(Mux((mtok.group == 0) | (value < second), value, second))
        m.d.sync += done.eq(mtok.go & mtok.last)
        scaled, ready = Signal(range(64 * none + 1), reset_less=True), Signal()
        m.d.sync += [scaled.eq(second * cfg.uniqueness), ready.eq(done)]
        return (held_best << 6) > scaled, ready
