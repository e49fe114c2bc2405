"""Test-pattern generator: colour bars over a gradient, computed from the sync generator's raster position."""

from amaranth.hdl import Module, Signal, Mux, Cat, Const
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec.video import CEA_1080P60
from hdl.video_bus import TimingSignature, VideoSignature, Y_BITS

__all__ = ["PatternGenerator", "check_active"]


class ReciprocalDivider:
    """``floor(v * num / den)`` for every integer ``0 <= v <= v_max`` as ``(v * mul) >> shift``.

    The constant ``mul`` is chosen at elaboration time and the identity is checked exhaustively over the
    whole input range (a few thousand values), so the hardware needs a constant multiplier, no divider.
    """

    def __init__(self, num, den, v_max):
        self.num, self.den, self.v_max = num, den, v_max
        for shift in range(8, 64):
            mul = -((-num << shift) // den)            # ceil(num * 2**shift / den)
            if all((v * mul) >> shift == (v * num) // den for v in range(v_max + 1)):
                self.mul, self.shift = mul, shift
                return
        raise ValueError(f"no reciprocal found for {num}/{den} up to {v_max}")  # pragma: no cover

    def __call__(self, value):
        return (value * Const(self.mul)) >> self.shift


def check_active(timing):
    """``ValueError`` unless ``timing``'s active area has room for the test pattern (8 x 2 pixels)."""
    if timing.h_active < 8 or timing.v_active < 2:
        raise ValueError(f"the test pattern needs at least 8 x 2 active pixels, got "
                         f"{timing.h_active} x {timing.v_active}")


class PatternGenerator(wiring.Component):
    """Colour bars + gradient test pattern as a :data:`hdl.video_bus.VideoSignature` stream.

    Pattern definition (the golden model ``golden/video.py`` implements the same definition independently),
    for the active area ``W = timing.h_active`` x ``H = timing.v_active``, column ``x``, row ``y``:

    * Colour bars in the top ``B = (2 * H) // 3`` rows (``y < B``): eight vertical bars of equal width,
      bar ``i = (8 * x) // W``; with ``c = 7 - i``: green = 255 if bit 2 of ``c`` else 0, red = 255 if bit 1,
      blue = 255 if bit 0. Left to right: white, yellow, cyan, green, magenta, red, blue, black.
    * Gradient in the remaining rows (``y >= B``): red = ``(256 * x) // W``, green =
      ``(256 * (y - B)) // (H - B)``, blue = ``(x + y) mod 256``.

    All divisions are floor divisions. Outside the active area ``rgb`` is 0.

    Parameters
    ----------
    timing : :class:`spec.video.VideoTiming`

    Attributes
    ----------
    timing : ``In(TimingSignature)``
        From :class:`hdl.sync_gen.SyncGenerator` (the video mode is ``mode``).
    video : ``Out(VideoSignature)``

    Clock domain: ``sync`` (placed in ``pix`` by the parent). Latency: 1 clock. ``video.rgb``/``de``/``hsync``/
    ``vsync`` are registers holding the pixel whose position was on ``timing`` one clock earlier, so they stay
    mutually aligned. The colour is a pure function of ``(x, y)`` (no state), so the pattern is right from the
    first clock whatever the raster does.

    Raises
    ------
    ValueError
        An active area smaller than 8 x 2 pixels.
    """

    def __init__(self, timing=CEA_1080P60):
        check_active(timing)
        self.mode = timing
        super().__init__({
            "timing": In(TimingSignature),
            "video": Out(VideoSignature),
        })

    def elaborate(self, platform):
        m = Module()
        t = self.mode
        w, h = t.h_active, t.v_active
        bar_rows = (2 * h) // 3
        grad_rows = h - bar_rows

        x, y = self.timing.x, self.timing.y
        bar_index = Signal(3)
        ramp_r = Signal(8)
        ramp_g = Signal(8)
        gy = Signal(Y_BITS)
        m.d.comb += [
            bar_index.eq(ReciprocalDivider(8, w, w - 1)(x)),
            ramp_r.eq(ReciprocalDivider(256, w, w - 1)(x)),
            gy.eq(y - bar_rows),
            ramp_g.eq(ReciprocalDivider(256, grad_rows, grad_rows - 1)(gy)),
        ]
        colour = Signal(3)                 # c = 7 - i: bit 2 green, bit 1 red, bit 0 blue
        m.d.comb += colour.eq(7 - bar_index)
        bar_rgb = Cat(Mux(colour[0], 0xFF, 0),     # B[7:0]
                      Mux(colour[2], 0xFF, 0),     # G[15:8]
                      Mux(colour[1], 0xFF, 0))     # R[23:16]
        grad_rgb = Cat((x + y)[:8], ramp_g, ramp_r)

        # Output registers; after reset they hold a blank pixel with the syncs at their inactive level.
        rgb = Signal(24)
        de = Signal()
        hsync = Signal(init=0 if t.hsync_positive else 1)
        vsync = Signal(init=0 if t.vsync_positive else 1)
        active = self.timing.de
        m.d.sync += [
            rgb.eq(Mux(active, Mux(y < bar_rows, bar_rgb, grad_rgb), 0)),
            de.eq(active),
            hsync.eq(self.timing.hsync),
            vsync.eq(self.timing.vsync),
        ]
        m.d.comb += [self.video.rgb.eq(rgb), self.video.de.eq(de), self.video.hsync.eq(hsync),
                     self.video.vsync.eq(vsync)]
        return m
