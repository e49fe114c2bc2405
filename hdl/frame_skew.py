"""FrameSkewMeter: the time between the two cameras' frame starts, measured in ``sync`` clocks.

Each capture's ``frame_start`` strobe (its own PCLK domain) is carried into ``sync`` by a
:class:`amaranth.lib.cdc.PulseSynchronizer` (the same latency for both, so the difference survives to within one
``sync`` clock of each side's sampling). When one camera's frame starts, a counter runs until the other camera's
frame starts: ``skew`` = (camera B's start - camera A's start) in ``sync`` clocks, positive when B starts later.
If the other start does not come within ``max_clocks`` (half a frame period by default) the measurement is
abandoned (the cameras are not running together) and the next start begins a new one. ``aligned`` says that the
last measurement was at most ``line_clocks`` (one sensor line) either way.
"""

from amaranth import Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.cdc import PulseSynchronizer
from amaranth.lib.wiring import Out


__all__ = ["FrameSkewMeter", "FrameSkewSignature", "skew_bits"]


def FrameSkewSignature(bits):
    """``skew`` (signed ``bits``), ``valid`` (a measurement has completed), ``aligned`` (\\|skew\\| <= one line),
    ``count`` (measurements completed, wrapping)."""
    return wiring.Signature({"skew": Out(signed(bits)), "valid": Out(1), "aligned": Out(1), "count": Out(8)})


def skew_bits(line_clocks, max_clocks):
    """The width of a :class:`FrameSkewMeter`'s skew (signed) for a measurement of up to ``max_clocks``;
    ``ValueError`` unless 0 < ``line_clocks`` <= ``max_clocks``."""
    if not 0 < line_clocks <= max_clocks:
        raise ValueError(f"need 0 < line_clocks <= max_clocks, got {line_clocks} and {max_clocks}")
    return max_clocks.bit_length() + 1


class FrameSkewMeter(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    line_clocks : int
        One sensor line in ``sync`` clocks: the ``aligned`` limit.
    max_clocks : int
        The longest skew measured (half a frame period in ``sync`` clocks is the natural choice).
    cam_domains : tuple of str
        The domains of camera A's and camera B's ``frame_start`` strobes.

    Attributes
    ----------
    start_a, start_b : ``In(1)``
        Camera A's / B's frame-start strobe, in its own domain.
    status : ``Out(FrameSkewSignature)``, ``sync``
        The last measurement. Latency: the synchronisers' 2-3 ``sync`` clocks after the later start.

    Raises
    ------
    ValueError
        ``line_clocks`` or ``max_clocks`` not positive, or ``max_clocks`` below ``line_clocks``.
    """

    def __init__(self, *, line_clocks=4320, max_clocks=2_600_000, cam_domains=("cam_a", "cam_b")):
        self.bits = skew_bits(line_clocks, max_clocks)
        self.line_clocks, self.max_clocks = line_clocks, max_clocks
        self.cam_domains = tuple(cam_domains)
        super().__init__({"start_a": wiring.In(1), "start_b": wiring.In(1),
                          "status": Out(FrameSkewSignature(self.bits))})

    def elaborate(self, platform):
        m = Module()
        starts = []
        for name, domain, pin in zip("ab", self.cam_domains, (self.start_a, self.start_b)):
            m.submodules[f"sync_{name}"] = ps = PulseSynchronizer(i_domain=domain, o_domain="sync")
            m.d.comb += ps.i.eq(pin)
            starts.append(ps.o)
        a, b = starts
        count = Signal(range(self.max_clocks + 1))
        running, b_first = Signal(), Signal()
        status = self.status

        def finish(value):
            return [status.skew.eq(value), status.valid.eq(1), status.count.eq(status.count + 1),
                    status.aligned.eq((value <= self.line_clocks) & (value >= -self.line_clocks)), running.eq(0)]

        with m.If(~running):
            with m.If(a & b):
                m.d.sync += finish(0)
            with m.Elif(a | b):
                m.d.sync += [running.eq(1), b_first.eq(b), count.eq(1)]
        with m.Else():
            other = Signal()
            m.d.comb += other.eq(Mux(b_first, a, b))
            with m.If(other):
                value = Signal(signed(self.bits))
                m.d.comb += value.eq(count)
                with m.If(b_first):
                    m.d.sync += finish(-value)
                with m.Else():
                    m.d.sync += finish(value)
            with m.Elif(count == self.max_clocks):
                m.d.sync += running.eq(0)
            with m.Else():
                m.d.sync += count.eq(count + 1)
        return m

