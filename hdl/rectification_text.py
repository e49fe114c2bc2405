"""RectificationText: the rectification in use as screen characters (docs/display.md, "Rectification text")."""

from amaranth import Module, Mux, Signal, signed
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from hdl.switches import SWITCH_VALUE_BITS
from hdl.text_layer import CHAR_BITS, char_codes
from spec.display import RECTIFICATION_MODES, RECTIFICATION_TEXT

__all__ = ["RectificationText", "RectificationModeSignature", "LATENCY"]

#: The automatic rectification's state as its source drives it: ``auto`` (the automatic mode is selected) and
#: ``held`` (the estimate in use comes from a search without a clear minimum: the offset before it kept).
RectificationModeSignature = wiring.Signature({"auto": Out(1), "held": Out(1)})

#: Clocks from the ``frame_start`` edge that samples the inputs until ``chars`` holds their text.
LATENCY = 2


class RectificationText(wiring.Component):
    """``chars`` = "rect", the offset in use as ``f"{offset:+3d}"``, and the mode word ("hand", "auto" or "held":
    ``spec.display.RECTIFICATION_MODES``), as font codes (:func:`hdl.text_layer.char_codes`) of
    ``len(RECTIFICATION_TEXT)`` characters. The digits are computed, not looked up: tens = the number of the
    thresholds 10, 20, .., 60 that ``|offset|`` reaches, ones = ``|offset|`` - 10 tens; a single digit moves the
    sign next to it.

    Ports
    -----
    frame_start : In(1)
        The inputs are sampled on the clock edge that ends a ``frame_start`` cycle, so one frame shows one text.
    offset : In(signed(SWITCH_VALUE_BITS))
        The rectification in use (-64..63 buffer rows).
    mode : In(RectificationModeSignature)
        ``held`` is shown only in automatic mode.
    chars : Out(ArrayLayout(CHAR_BITS, len(RECTIFICATION_TEXT)))

    Clock domain: ``sync`` (the display places it in ``pix``). Latency: :data:`LATENCY` clocks after the sampling
    edge; ``chars`` then holds until the same time after the next ``frame_start``.
    """

    def __init__(self):
        super().__init__({
            "frame_start": In(1),
            "offset": In(signed(SWITCH_VALUE_BITS)),
            "mode": In(RectificationModeSignature),
            "chars": Out(data.ArrayLayout(CHAR_BITS, len(RECTIFICATION_TEXT))),
        })

    def elaborate(self, platform):
        m = Module()
        # The sampling edge: the inputs at frame_start.
        offset, auto, held = Signal.like(self.offset), Signal(), Signal()
        with m.If(self.frame_start):
            m.d.sync += [offset.eq(self.offset), auto.eq(self.mode.auto), held.eq(self.mode.held)]
        # Edge 1: sign, magnitude and its tens digit (the magnitude is at most 64), the mode.
        negative, magnitude, tens = Signal(), Signal(SWITCH_VALUE_BITS), Signal(range(7))
        absolute = Mux(offset < 0, -offset, offset)
        m.d.sync += [negative.eq(offset < 0), magnitude.eq(absolute),
                     tens.eq(sum((absolute >= 10 * k).as_unsigned() for k in range(1, 7)))]
        mode = Signal(range(len(RECTIFICATION_MODES)))
        m.d.sync += mode.eq(Mux(auto, Mux(held, 2, 1), 0))
        # Edge 2: the characters.
        code = {c: char_codes(c)[0] for c in "+- 0123456789"}
        assert [code[str(k)] for k in range(10)] == list(range(code["0"], code["0"] + 10))   # the font's order
        digit = lambda value: code["0"] + value                                             # noqa: E731
        ones = Signal(4)
        m.d.comb += ones.eq(magnitude - tens * 10)
        sign = Mux(negative, code["-"], code["+"])
        fixed = char_codes("rect ")
        words = [char_codes(" " + w) for w in RECTIFICATION_MODES]
        chars = self.chars
        updates = [chars[i].eq(c) for i, c in enumerate(fixed)]
        updates += [chars[5].eq(Mux(tens == 0, code[" "], sign)),
                    chars[6].eq(Mux(tens == 0, sign, digit(tens))),
                    chars[7].eq(digit(ones))]
        for i, (hand, auto_c, held_c) in enumerate(zip(*words)):      # the mode word, a multiplexer per character
            updates.append(chars[8 + i].eq(Mux(mode == 0, hand, Mux(mode == 1, auto_c, held_c))))
        m.d.sync += updates
        return m
