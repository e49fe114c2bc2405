# amaranth: UnusedElaboratable=no
"""LeftWinner: the left view's winner d_L of a left pixel is the smallest d with the smallest sum among the offers
made to it (right pixel x offers S(d, x) to left pixel x + d), since the row's start.

The environment is free inside the block's interface contract (its docstring's Ports): tokens in the row (x < W,
group < G), a pixel's groups in consecutive clocks from group 0 with ``last`` on the last, ``first`` exactly at x
= 0, pixels in ascending x from x = 0 (a new row may start at any pixel; after a reset it must), pixels at least G +
1 clocks apart. The sums (any values, the top one too) and the values on clocks without ``go`` are free.

One left pixel X, fixed and arbitrary, is watched: the harness keeps the minimum of the offers made to it
(the smallest sum, then the smallest d) since the last ``first``, and the block's d_L for X must be that one's d.
D = 4 with 2 lanes (2 groups, the lane carry between words exercised), W = 6, a 3 x 3 census and P2 = 5: sums of
5 bits.
"""

from amaranth import Mux, Signal

from hdl.depth.left_winner import LeftWinner
from spec.depth import DepthConfig
from sim.formal.runner import FormalHarness

CONFIG = DepthConfig(disparities=4, lanes=2, census_width=3, census_height=3, p1=2, p2=5)
WIDTH = 6


class LeftWinnerHarness(FormalHarness):
    name = "left_winner"
    block = "LeftWinner"

    def __init__(self, config=CONFIG, width=WIDTH):
        super().__init__()
        self.config, self.width = config, width

    def build(self, m):
        cfg, w = self.config, self.width
        groups, lanes = cfg.disparities // cfg.lanes, cfg.lanes
        dut = LeftWinner(cfg, w)
        self.open(m, "dut", dut)
        token = dut.token
        m.d.comb += [token.eq(self.free("token", len(token.as_value()))),
                     dut.sums.eq(self.free("sums", len(dut.sums.as_value())))]
        self._contract(m, token, groups, w)

        watched = self.free("watched", range(w))
        # Fixed from the first clock after a reset on (a register's initial value would pin it to 0).
        self.assume(m, "watched_fixed", ~self.past_valid(m) | (watched == self.past(m, watched, name="past_watched")))
        # The reference: the best offer to the watched left pixel since the row's start (x = 0, group 0).
        best_s, best_d = Signal(cfg.sum_bits, name="ref_s"), Signal(range(cfg.disparities), name="ref_d")
        offered = Signal(name="ref_offered")
        s, d, seen = best_s, best_d, offered & ~(token.go & token.first & (token.group == 0))
        for k in range(lanes):
            lane_d = token.group * lanes + k
            offer = token.go & (token.x + lane_d == watched)
            take = offer & (~seen | (dut.sums[k] < s) | ((dut.sums[k] == s) & (lane_d < d)))
            s, d, seen = Mux(take, dut.sums[k], s), Mux(take, lane_d, d), seen | offer
        m.d.sync += [best_s.eq(s), best_d.eq(d), offered.eq(seen)]

        out = dut.valid & (dut.x == watched)
        self.prove(m, "left_winner_is_the_best_offer", ~out | (offered & (dut.d == best_d)))
        self.cover(m, "a_later_offer_wins", out & (best_d != 0) & (watched >= cfg.disparities - 1))
        self.cover(m, "the_last_column", out & (watched == w - 1) & (best_d == cfg.disparities - 1))

    def _contract(self, m, token, groups, w):
        self.assume(m, "token_in_row", ~token.go | ((token.x < w) & (token.group < groups)))
        self.assume(m, "first_at_column_0", ~token.go | (token.first == (token.x == 0)))
        self.assume_pixel_groups(m, token, groups)
        # Pixels in ascending x: the next one is x + 1 or a new row (x = 0); after a reset a new row.
        next_x = Signal(range(w + 1), name="next_pixel_x")
        new_pixel = token.go & (token.group == 0)
        with m.If(new_pixel):
            m.d.sync += next_x.eq(token.x + 1)
        self.assume(m, "pixels_in_ascending_x", ~new_pixel | (token.x == 0) | (token.x == next_x))
        # A clock without a group between pixels (the last group's word is written in it).
        self.assume(m, "a_gap_between_pixels", ~new_pixel | ~self.past(m, token.go, name="past_go"))
