"""SegmentBand: the depth-keyed segmentation view's pixel colour and its band's text (docs/display.md,
"Segmentation")."""

from fractions import Fraction

from amaranth import Cat, Module, Mux, Signal, unsigned
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from hdl.switches import SWITCH_VALUE_BITS
from hdl.text_layer import CHAR_BITS, char_codes
from spec.depth import DEPTH
from spec.display import SEGMENT_DIM_SHIFT, SEGMENT_HALF_WIDTH, SEGMENT_INVALID_RGB, SEGMENT_TEXT
from spec.sensor import SENSOR, VMODCAM_RIG

__all__ = ["SegmentBand", "band_table", "LATENCY"]

#: Clocks from ``code`` / ``grey`` in to ``rgb`` out.
LATENCY = 2


def _metres(numerator, disparity):
    """Z = numerator / d in whole centimetres (half up) as "NN.NN"; "--.--" for d <= 0 or more than 99.99 m."""
    if disparity <= 0:
        return "--.--"
    cm = int(numerator / disparity + Fraction(1, 2))
    return "--.--" if cm > 9999 else f"{cm // 100:2d}.{cm % 100:02d}"


def band_table(geometry=SENSOR):
    """The band text of every disparity register value: the distances B f / (d' p s) at d' = d + half width (near)
    and d - half width (far), exact rational arithmetic (the rig's decimal constants as fractions)."""
    numerator = Fraction(str(VMODCAM_RIG.BASELINE_M)) * Fraction(str(VMODCAM_RIG.FOCAL_M)) * 100 / (
        Fraction(str(VMODCAM_RIG.PIXEL_M)) * geometry.scale)
    hw = SEGMENT_HALF_WIDTH
    return [f"{_metres(numerator, d + hw)}-{_metres(numerator, d - hw)}m" for d in range(2 ** SWITCH_VALUE_BITS)]


class SegmentBand(wiring.Component):
    """One pixel of the segmentation view per clock: the 8-bit grey of ``grey`` (bit replication) when ``code``
    is inside the band around ``disparity`` (``|code - 2**F d| <= 2**F SEGMENT_HALF_WIDTH``, not the invalid code);
    outside it each channel ``grey8 >> SEGMENT_DIM_SHIFT``; an invalid code dimmed with ``SEGMENT_INVALID_RGB``
    OR-ed in. ``chars`` is the band's text (:func:`band_table`), or spaces while ``enable`` is low.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
        Grey bits and the buffer scale (for the distances).
    config : :class:`spec.depth.DepthConfig`
        Code width, fraction bits, the invalid code.

    Attributes
    ----------
    disparity : In(7)
        The disparity register (the band's centre, whole pixels); static through a frame.
    enable : In(1)
        The segmentation view is on (only ``chars`` depends on it).
    code : In(code_bits), grey : In(grey_bits)
        A depth code and the grey of the same pixel.
    rgb : Out(24)
        The pixel's colour, :data:`LATENCY` (2) clocks after ``code`` / ``grey``.
    chars : Out(ArrayLayout(CHAR_BITS, len(SEGMENT_TEXT)))
        The band text's font codes, registered (three clocks after ``disparity`` / ``enable``).

    Clock domain: ``sync``. The band's edges are registered from ``disparity`` (one clock); ``code`` and ``grey``
    are registered before any logic (they may come straight from block-RAM outputs), the colour in the second
    clock.

    Raises
    ------
    ValueError
        More than 8 bits of grey.
    """

    def __init__(self, geometry=SENSOR, config=DEPTH):
        if geometry.grey_bits > 8:
            raise ValueError(f"grey_bits = {geometry.grey_bits}: the view shows at most 8 bits of grey")
        self.geometry, self.config = geometry, config
        self.table = band_table(geometry)
        super().__init__({
            "disparity": In(SWITCH_VALUE_BITS),
            "enable": In(1),
            "code": In(config.code_bits),
            "grey": In(geometry.grey_bits),
            "rgb": Out(24),
            "chars": Out(data.ArrayLayout(CHAR_BITS, len(SEGMENT_TEXT))),
        })

    def elaborate(self, platform):
        m = Module()
        cfg, f, hw = self.config, self.config.fraction_bits, SEGMENT_HALF_WIDTH
        d = self.disparity
        low, high = Signal(SWITCH_VALUE_BITS + f + 1), Signal(SWITCH_VALUE_BITS + f + 1)
        m.d.sync += [low.eq(Mux(d >= hw, (d - hw) << f, 0)), high.eq((d + hw) << f)]
        # Stage 1: the code and the grey registered, nothing else (they come straight from block RAM outputs).
        code_1 = Signal.like(self.code, name="code_1")
        grey_1 = Signal.like(self.grey, name="grey_1")
        m.d.sync += [code_1.eq(self.code), grey_1.eq(self.grey)]
        # Stage 2: the code's class and the colour, registered.
        invalid = code_1 == cfg.invalid
        inside = (code_1 >= low) & (code_1 <= high) & ~invalid
        grey8 = _replicate_to_8_bits(grey_1)
        dim = Signal(8)
        m.d.comb += dim.eq(grey8 >> SEGMENT_DIM_SHIFT)
        shown = Mux(inside, grey8, dim)
        m.d.sync += self.rgb.eq(Cat(shown, shown, shown) | Mux(invalid, SEGMENT_INVALID_RGB, 0))
        self._text(m)
        return m

    def _text(self, m):
        """The band text ROM, read by the disparity register registered once more through the ROM's own read
        register (a synchronous read: no reset, so no logic can be folded into one), then spaces in its place while
        ``enable`` is low (three clocks)."""
        def word(text):
            return sum(c << (CHAR_BITS * pos) for pos, c in enumerate(char_codes(text)))
        shape = unsigned(len(self.chars.as_value()))
        rom = Memory(shape=shape, depth=len(self.table), init=[word(t) for t in self.table])
        m.submodules.band_rom = rom
        port = rom.read_port(domain="sync")
        disparity_1, enable_1 = Signal.like(self.disparity, name="text_disparity_1"), Signal(name="text_enable_1")
        m.d.sync += [disparity_1.eq(self.disparity), enable_1.eq(self.enable)]
        m.d.comb += port.addr.eq(disparity_1)
        enable_2 = Signal(name="text_enable_2")
        m.d.sync += enable_2.eq(enable_1)
        m.d.sync += self.chars.eq(Mux(enable_2, port.data, word(" " * len(SEGMENT_TEXT))))


def _replicate_to_8_bits(grey):
    """The 8-bit value whose bits are ``grey``'s bits repeated from the MSB down (5 bits: g4..g0 g4 g3 g2)."""
    bits = []
    while len(bits) < 8:
        bits.extend(grey[i] for i in reversed(range(len(grey))))   # MSB first
    return Cat(*reversed(bits[:8]))
