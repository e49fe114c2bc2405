# amaranth: UnusedElaboratable=no
"""ReversePath: the right-to-left path starts at x = W - 1 and nowhere else, its sums never wrap, and the row
store is addressed inside itself at the word of the pixel and group.

The environment is free inside the block's interface contract (its docstring's Ports): tokens in the row (x < W,
group < G), a pixel's groups in consecutive clocks from group 0 with ``last`` on the last, costs at most
``cost_max`` (census distance + AD term), carries at most ``other_paths`` x (``cost_max`` + P2), the stored carry
read at least a clock after its write, pixels at least ``loop_clocks`` apart (the path's banks hold the previous
pixel's vector whole only then, and the sums' bounds need that vector to be the one its minimum M' is of). The
pixels' order, ``first`` (the block ignores it) and the values on clocks without ``go`` are free.

D = 6 with 2 lanes: 3 groups behind a 2-bit group field (so the contract matters); W = 7: the row store's 21 words
behind a 5-bit address; a 3 x 3 census (N = 8), P1 = 2, P2 = 5: L at most 13 in 4 bits, the carry at most 26 in 5,
the sum at most 39 in 6. ``reverse_path_ad`` (:data:`AD_CONFIG`): the same with the AD term, costs up to 10, L up
to 15 (the top of its 4 bits), the carry up to 30, the sum up to 45.
"""

from amaranth import Mux, Signal

from hdl.depth.reverse_path import ReversePath
from spec.depth import DepthConfig
from sim.formal.runner import FormalHarness

CONFIG = DepthConfig(disparities=6, lanes=2, census_width=3, census_height=3, p1=2, p2=5)
#: CONFIG with the AD term (min(|dI|, 4) >> 1 <= 2): costs up to cost_max = 10, L up to path_max = 15, the top of
#: its 4 bits (``reverse_path_ad``).
AD_CONFIG = DepthConfig(disparities=6, lanes=2, census_width=3, census_height=3, p1=2, p2=5, ad_clip=4, ad_shift=1)
WIDTH = 7
OTHER_PATHS = 2


class ReversePathHarness(FormalHarness):
    name = "reverse_path"
    block = "ReversePath"

    def __init__(self, config=CONFIG, width=WIDTH, other_paths=OTHER_PATHS):
        super().__init__()
        self.config, self.width, self.other_paths = config, width, other_paths

    def dut(self):
        return ReversePath(self.config, width=self.width, other_paths=self.other_paths)

    def build(self, m):
        cfg, w = self.config, self.width
        groups, lanes = cfg.disparities // cfg.lanes, cfg.lanes
        dut = self.dut()
        module = self.open(m, "dut", dut)
        # The block's ports and its row store's (the one place to adapt when the signature changes).
        store = module.submodules.row_store
        write, read = store.write_ports[0], store.read_ports[0]
        store_token, token = dut.store_token, dut.token
        m.d.comb += [store_token.eq(self.free("store_token", len(store_token.as_value()))),
                     dut.carry.eq(self.free("carry", len(dut.carry.as_value()))),
                     token.eq(self.free("token", len(token.as_value()))),
                     dut.cost.eq(self.free("cost", len(dut.cost.as_value())))]

        carry_max = self.other_paths * cfg.path_max
        self._contract(m, dut, groups, carry_max)

        # The row store: word x G + g for group g of pixel x, inside the store.
        self.prove(m, "store_write_at_pixel_and_group",
                   ~write.en | (write.addr == store_token.x * groups + store_token.group), group="store")
        self.prove(m, "store_write_in_row_store", ~write.en | (write.addr < w * groups), group="store")
        self.prove(m, "store_read_at_pixel_and_group",
                   ~token.go | (read.addr == token.x * groups + token.group), group="store")
        self.prove(m, "store_read_only_for_a_token", ~read.en | token.go, group="store")
        self.prove(m, "store_read_in_row_store", ~read.en | (read.addr < w * groups), group="store")

        # The path starts at x = W - 1 (L_rl = C there) whatever the token's ``first`` says, and nowhere else.
        out = dut.out_token
        self.prove(m, "first_exactly_at_the_last_column", ~out.go | (out.first == (out.x == w - 1)), group="start")
        late_cost = self.past(m, dut.cost.as_value(), ReversePath.LATENCY, name="late_cost")
        at_last = out.go & (out.x == w - 1)
        self.prove(m, "starts_with_the_cost_at_the_last_column",
                   ~at_last | (dut.l.as_value() == late_cost), group="start")

        # The sums: L_rl <= N + P2, the carry as stored, S = carry + L_rl without wrapping.
        for k in range(lanes):
            l, carry, total = dut.l[k], dut.carry_out[k], dut.total[k]
            self.prove(m, f"l_within_path_max_{k}", ~out.go | (l <= cfg.path_max), group="sums")
            self.prove(m, f"carry_within_other_paths_{k}", ~out.go | (carry <= carry_max), group="sums")
            self.prove(m, f"total_is_carry_plus_l_{k}", ~out.go | (total == carry + l), group="sums")
            self.prove(m, f"total_within_sum_max_{k}", ~out.go | (total <= carry_max + cfg.path_max), group="sums")
        self._watched_word(m, dut, write, read, groups)

        self.cover(m, "starts_at_the_last_column", at_last)
        self.cover(m, "largest_sum", out.go & (dut.total[0] == carry_max + cfg.path_max))

    def _contract(self, m, dut, groups, carry_max):
        cfg, w, lanes = self.config, self.width, self.config.lanes
        store_token, token = dut.store_token, dut.token
        # token_layout: x in the row, group < G.
        self.assume(m, "store_token_in_row", ~store_token.go | ((store_token.x < w) & (store_token.group < groups)))
        self.assume(m, "token_in_row", ~token.go | ((token.x < w) & (token.group < groups)))
        # carry: the other paths' sum, each at most cost_max + P2; cost: a matching cost, at most cost_max.
        for k in range(lanes):
            self.assume(m, f"carry_within_other_paths_in_{k}", ~store_token.go | (dut.carry[k] <= carry_max))
            self.assume(m, f"cost_is_a_matching_cost_{k}", ~token.go | (dut.cost[k] <= cfg.cost_max))
        # A pixel's groups in consecutive clocks, from group 0, ``last`` on the last, one x.
        self.assume_pixel_groups(m, token, groups)
        # Pixels at least ``loop_clocks`` apart (first group to first group), the contract: the path's banks hold
        # the previous pixel's vector whole only then, and its minimum M' is that vector's.
        loop = ReversePath.loop_clocks(cfg)
        since = Signal(range(loop + 1), init=loop, name="clocks_since_first_group")
        m.d.sync += since.eq(Mux(token.go & (token.group == 0), 1, Mux(since == loop, loop, since + 1)))
        self.assume(m, "pixels_loop_clocks_apart", ~(token.go & (token.group == 0)) | (since == loop))

    def _watched_word(self, m, dut, write, read, groups):
        """carry_out is the carry last stored at the token's word before its read (one fixed, arbitrary word)."""
        lanes = self.config.lanes
        word = self.free("watched_word", len(read.addr))
        self.hold(m, "watched_word_fixed", word)
        # The store keeps its words across a reset, and so does the reference.
        stored = Signal(dut.carry.shape(), name="watched_carry", reset_less=True)
        with m.If(write.en & (write.addr == word)):
            m.d.sync += stored.eq(dut.carry)
        # The carry must be stored at least a clock before its read: no write of the word in the read's clock.
        self.assume(m, "stored_before_read",
                    ~(dut.token.go & (read.addr == word) & write.en & (write.addr == word)))
        reads_word = dut.token.go & (read.addr == word)
        late_reads = self.past(m, reads_word, ReversePath.LATENCY, name="late_reads_word")
        late_stored = self.past(m, stored.as_value(), ReversePath.LATENCY, name="late_stored")
        self.cover(m, "watched_word_read_not_word_0", late_reads & dut.out_token.go & (word != 0))
        for k in range(lanes):
            self.prove(m, f"carry_out_is_the_stored_carry_{k}",
                       ~(late_reads & dut.out_token.go) | (dut.carry_out[k] == late_stored.word_select(k, dut.carry_bits)), group="store")
