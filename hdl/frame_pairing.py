"""FramePairing: one frame tag for the two cameras' frames that belong together (docs/capture.md, "Frame
pairs"), so that the depth engine can compare a left row's tag with a right row's.

Each camera's :class:`hdl.row_tags.RowTagTracker` reports its frame starts (``started``, a ``pix`` pulse) and
takes the tag of the frame that starts (``tag``, in the same clock). The rule, applied to camera A's start first
and then to camera B's when both come in one clock:

* a start *joins* the open pair, taking its tag, when the other camera has started in this pair and this camera
  has not;
* otherwise it *opens* a new pair: the pair tag counts up (wrapping at ``2**bits``) and only this camera has
  started in it.

Synchronised sensors (frame starts a line or so apart, in either order) so give frame k of A and frame k of B the
same tag. A camera that drops a frame opens no pair; the other camera's next frame opens one alone, and the
dropped camera's buffer keeps the previous tag, so its rows differ from the other's until its next frame, which
joins the open pair. A camera that stops leaves its tags behind the other's for good. The golden model is
:func:`golden.frame_pairing.pair_tags`.
"""

from amaranth import Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.signature import ParametricSignature
from spec.sensor import ROW_TAG_BITS

__all__ = ["FramePairSignature", "FramePairing"]


class FramePairSignature(ParametricSignature):
    """One camera's link to the pairing, as the camera's tracker drives it: ``started`` (Out, a one-clock pulse
    at the camera's frame start) and ``tag`` (In, the tag of a frame that starts in this clock, combinational).

    Parameters
    ----------
    bits : int
        Tag width.
    """

    def __init__(self, bits=ROW_TAG_BITS):
        super().__init__({"started": Out(1), "tag": In(bits)}, bits=bits)


class FramePairing(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    bits : int
        Tag width (the pair count mod ``2**bits``).

    Attributes
    ----------
    a, b : ``In(FramePairSignature(bits))``
        Camera A's and camera B's trackers. ``tag`` is combinational from ``started`` (both cameras' when they
        start in one clock) and the state.
    pair : ``Out(bits)``
        The tag of the open pair (registered: after the last clock's starts).

    Clock domain: ``sync`` (the system renames it to ``pix``). Latency: ``tag`` in the clock of the start.

    Raises
    ------
    ValueError
        ``bits`` below 1.
    """

    def __init__(self, bits=ROW_TAG_BITS):
        if bits < 1:
            raise ValueError(f"bits must be at least 1, got {bits}")
        self.bits = bits
        super().__init__({"a": In(FramePairSignature(bits)), "b": In(FramePairSignature(bits)), "pair": Out(bits)})

    def elaborate(self, platform):
        m = Module()
        pair = self.pair
        in_a, in_b = Signal(), Signal()             # camera A / B has started in the open pair
        # Camera A's start first, then camera B's on the state A's left.
        opens_a = self.a.started & ~(in_b & ~in_a)
        pair_a = Signal(self.bits)
        started_a, started_b = Signal(), Signal()   # the state after camera A's start
        m.d.comb += [
            pair_a.eq(Mux(opens_a, pair + 1, pair)),
            started_a.eq(in_a | self.a.started),
            started_b.eq(in_b & ~opens_a),
        ]
        opens_b = self.b.started & ~(started_a & ~started_b)
        pair_b = Signal(self.bits)
        m.d.comb += [
            pair_b.eq(Mux(opens_b, pair_a + 1, pair_a)),
            self.a.tag.eq(pair_a),
            self.b.tag.eq(pair_b),
        ]
        m.d.sync += [
            pair.eq(pair_b),
            in_a.eq(started_a & ~opens_b),
            in_b.eq(started_b | self.b.started),
        ]
        return m
