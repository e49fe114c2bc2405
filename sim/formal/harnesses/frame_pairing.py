# amaranth: UnusedElaboratable=no
"""FramePairing: every frame start gets the tag the rule of docs/capture.md ("Frame pairs") gives, for any starts
of the two cameras in any clocks (both in one clock too).

Both cameras' starts are free on every clock. The reference keeps the open pair's tag and, per camera, whether it
has started in the open pair, and applies the rule camera A first; it is written from the docs, not from the block
(which keeps its state after each clock, not per start). Two properties state consequences without the reference:
a camera's next frame, with no start of the other camera in between, takes the next tag (so a camera that drops or
repeats a frame is told apart), and a camera that joins takes the other camera's latest tag.
"""

from amaranth import Mux, Signal

from hdl.frame_pairing import FramePairing
from sim.formal.runner import FormalHarness

BITS = 2


class FramePairingHarness(FormalHarness):
    name = "frame_pairing"
    block = "FramePairing"

    def dut(self):
        return FramePairing(BITS)

    def connect(self, m, dut, start_a, start_b):
        """The block's ports (the one place to adapt when the signature changes): the two tags and the pair."""
        m.d.comb += [dut.a.started.eq(start_a), dut.b.started.eq(start_b)]
        return dut.a.tag, dut.b.tag, dut.pair

    def build(self, m):
        start_a, start_b = self.free("start_a"), self.free("start_b")
        m.submodules.dut = dut = self.dut()
        tag_a, tag_b, pair = self.connect(m, dut, start_a, start_b)

        # The reference: the open pair's tag and who has started in it.
        ref_pair = Signal(BITS, name="ref_pair")
        in_a, in_b = Signal(name="ref_in_a"), Signal(name="ref_in_b")
        joins_a = in_b & ~in_a
        after_a = Mux(start_a & ~joins_a, ref_pair + 1, ref_pair)[:BITS]
        in_a_after = in_a | start_a
        in_b_after = Mux(start_a & ~joins_a, 0, in_b)
        joins_b = in_a_after & ~in_b_after
        after_b = Mux(start_b & ~joins_b, after_a + 1, after_a)[:BITS]
        m.d.sync += [ref_pair.eq(after_b),
                     in_a.eq(Mux(start_b & ~joins_b, 0, in_a_after)),
                     in_b.eq(in_b_after | start_b)]
        self.prove(m, "a_tag_by_the_rule", ~start_a | (tag_a == after_a))
        self.prove(m, "b_tag_by_the_rule", ~start_b | (tag_b == after_b))
        self.prove(m, "pair_is_the_open_pairs_tag", pair == ref_pair)

        # Consequences: each camera's latest tag, and whether the other camera started since its last start.
        last_a, last_b = Signal(BITS, name="last_a"), Signal(BITS, name="last_b")
        other_since_a, other_since_b = Signal(name="b_since_a"), Signal(name="a_since_b")
        with m.If(start_a):
            m.d.sync += [last_a.eq(tag_a), other_since_a.eq(0)]
        with m.Elif(start_b):
            m.d.sync += other_since_a.eq(1)
        with m.If(start_b):
            m.d.sync += [last_b.eq(tag_b), other_since_b.eq(0)]
        with m.Elif(start_a):
            m.d.sync += other_since_b.eq(1)
        self.prove(m, "a_alone_again_takes_the_next_tag",
                   ~(start_a & ~start_b & ~other_since_a) | (tag_a == (last_a + 1)[:BITS]))
        self.prove(m, "b_alone_again_takes_the_next_tag",
                   ~(start_b & ~start_a & ~other_since_b) | (tag_b == (last_b + 1)[:BITS]))
        self.prove(m, "a_join_takes_b_s_tag", ~(start_a & joins_a) | (tag_a == last_b))
        self.prove(m, "b_join_takes_a_s_tag", ~(start_b & ~start_a & joins_b) | (tag_b == last_a))
        self.cover(m, "b_joins_a_pair", start_b & ~start_a & joins_b & (tag_b == 3))
        self.cover(m, "both_in_one_clock_share", start_a & start_b & (tag_a == tag_b) & (tag_a == 2))
