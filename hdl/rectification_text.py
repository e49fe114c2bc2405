"""RectificationText: the rectification in use as screen characters (docs/display.md, "Rectification text")."""

from amaranth import Module, Mux, Signal, signed
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from hdl.delay import delayed
from hdl.switches import SWITCH_VALUE_BITS
from hdl.text_layer import CHAR_BITS, char_codes
from spec.display import RECTIFICATION_MODES, RECTIFICATION_TEXT

__all__ = ["RectificationText", "RectificationModeSignature", "LATENCY"]

#: The automatic rectification's state as its source drives it: ``auto`` (the automatic mode is selected) and
#: ``held`` (the estimate in use comes from a search without a clear minimum: the offset before it kept).
RectificationModeSignature = wiring.Signature({"auto": Out(1), "held": Out(1)})

#: Clocks from the ``frame_start`` edge that samples the inputs until ``chars`` holds their text.
LATENCY = 5
#: The tens digit's thresholds: tens = the number of them that ``|offset|`` reaches (``|offset|`` <= 64).
TENS_THRESHOLDS = tuple(10 * k for k in range(1, 7))


class RectificationText(wiring.Component):
    """``chars`` = "rect", the offset in use as ``f"{offset:+3d}"``, and the mode word ("hand", "auto" or "held":
    ``spec.display.RECTIFICATION_MODES``), as font codes (:func:`hdl.text_layer.char_codes`) of
    ``len(RECTIFICATION_TEXT)`` characters. The digits are computed, not looked up: tens = the number of the
    thresholds 10, 20, .., 60 that ``|offset|`` reaches, ones = ``|offset|`` - 10 tens; a single digit moves the
    sign next to it.

    The text changes once a frame, so it is computed in a pipeline of :data:`LATENCY` clocks, one small step
    each (the magnitude; the six threshold comparisons; their sum; the ones digit; the characters): no clock
    carries more than a few LUT levels.

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
        offset = Signal.like(self.offset, name="offset_0")
        auto, held = Signal(name="auto_0"), Signal(name="held_0")
        with m.If(self.frame_start):
            m.d.sync += [offset.eq(self.offset), auto.eq(self.mode.auto), held.eq(self.mode.held)]
        # Edge 1: the sign, the magnitude (at most 64), the mode.
        negative_1, magnitude_1 = Signal(name="negative_1"), Signal(SWITCH_VALUE_BITS, name="magnitude_1")
        mode_1 = Signal(range(len(RECTIFICATION_MODES)), name="mode_1")
        m.d.sync += [negative_1.eq(offset < 0), magnitude_1.eq(Mux(offset < 0, -offset, offset)),
                     mode_1.eq(Mux(auto, Mux(held, 2, 1), 0))]
        # Edge 2: the magnitude against each threshold of the tens digit.
        reached_2 = Signal(len(TENS_THRESHOLDS), name="reached_2")
        m.d.sync += [reached_2[k].eq(magnitude_1 >= t) for k, t in enumerate(TENS_THRESHOLDS)]
        magnitude_2 = delayed(m, magnitude_1, 1, "magnitude_1")
        # Edge 3: the tens digit, the number of thresholds reached.
        tens_3 = Signal(range(len(TENS_THRESHOLDS) + 1), name="tens_3")
        m.d.sync += tens_3.eq(sum(reached_2[k].as_unsigned() for k in range(len(TENS_THRESHOLDS))))
        magnitude_3 = delayed(m, magnitude_2, 1, "magnitude_2")
        # Edge 4: the ones digit.
        ones_4 = Signal(4, name="ones_4")
        m.d.sync += ones_4.eq(magnitude_3 - tens_3 * 10)
        tens_4 = delayed(m, tens_3, 1, "tens_3")
        negative_4, mode_4 = delayed(m, negative_1, 3, "negative_1"), delayed(m, mode_1, 3, "mode_1")
        # Edge 5: the characters.
        code = {c: char_codes(c)[0] for c in "+- 0123456789"}
        assert [code[str(k)] for k in range(10)] == list(range(code["0"], code["0"] + 10))   # the font's order
        digit = lambda value: code["0"] + value                                             # noqa: E731
        sign = Mux(negative_4, code["-"], code["+"])
        fixed = char_codes("rect ")
        words = [char_codes(" " + w) for w in RECTIFICATION_MODES]
        chars = self.chars
        updates = [chars[i].eq(c) for i, c in enumerate(fixed)]
        updates += [chars[5].eq(Mux(tens_4 == 0, code[" "], sign)),
                    chars[6].eq(Mux(tens_4 == 0, sign, digit(tens_4))),
                    chars[7].eq(digit(ones_4))]
        for i, (hand, auto_c, held_c) in enumerate(zip(*words)):      # the mode word, a multiplexer per character
            updates.append(chars[8 + i].eq(Mux(mode_4 == 0, hand, Mux(mode_4 == 1, auto_c, held_c))))
        m.d.sync += updates
        return m
