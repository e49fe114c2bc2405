"""CentreDistance: the distance at the depth map's centre as readout characters (docs/display.md)."""

from fractions import Fraction

from amaranth import Module, Mux, Signal, unsigned
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from spec.display import READOUT_TEXT
from spec.sensor import SENSOR, VMODCAM_RIG
from hdl.text_layer import CHAR_BITS, char_codes

__all__ = ["CentreDistance", "readout_table", "SETTLE_CLOCKS"]

WINDOW = 9
#: Clocks after the last window capture until ``chars`` holds its readout.
SETTLE_CLOCKS = WINDOW + 6
#: Address bits of one part of the readout ROM (a 64-word ROM is one LUT6 per bit).
ROM_PART_BITS = 6


def readout_table(geometry=SENSOR, config=DEPTH):
    """The readout text of every code 0..invalid: the distance B f / (d p s) of the sub-pixel disparity
    d = code / 2**F in whole centimetres (rounded half up), right-aligned in four characters, then "cm";
    "----cm" for code 0 (infinitely far), the invalid code, and a distance that does not fit the four digits.
    Exact rational arithmetic (the rig's decimal constants as fractions)."""
    numerator = Fraction(str(VMODCAM_RIG.BASELINE_M)) * Fraction(str(VMODCAM_RIG.FOCAL_M)) * 100 * config.fraction
    denominator = Fraction(str(VMODCAM_RIG.PIXEL_M)) * geometry.scale
    digits = len(READOUT_TEXT) - 2
    table = []
    for code in range(config.invalid + 1):
        text = "-" * digits
        if code not in (0, config.invalid):
            cm = int(numerator / (denominator * code) + Fraction(1, 2))
            if cm < 10 ** digits:
                text = str(cm).rjust(digits)
        table.append(text + READOUT_TEXT[digits:])
    return table


class CentreDistance(wiring.Component):
    """Keeps the nine codes of the 3 x 3 window at the depth map's centre, takes their median (the fifth
    smallest; the invalid code sorts above every disparity) and gives the readout of that sub-pixel code
    (:func:`readout_table`) as font codes.

    The median is found by a free-running search: every clock one of the nine codes is the candidate; it is
    the median when at most four codes are smaller and at least five are not larger. So ``chars`` holds the
    window's readout :data:`SETTLE_CLOCKS` clocks after the window last changed.

    Parameters
    ----------
    geometry, config
        Buffer scale (for the distance) and D.

    Attributes
    ----------
    capture : In(9)
        One-hot: ``code`` is window position k (raster order, k = 3 (dy + 1) + dx + 1) this clock.
    code : In(code_bits)
    median : Out(code_bits)
    chars : Out(ArrayLayout(CHAR_BITS, len(READOUT_TEXT)))

    Clock domain: ``sync``.
    """

    def __init__(self, geometry=SENSOR, config=DEPTH):
        self.geometry, self.config = geometry, config
        self.table = readout_table(geometry, config)
        super().__init__({
            "capture": In(WINDOW),
            "code": In(config.code_bits),
            "median": Out(config.code_bits),
            "chars": Out(data.ArrayLayout(CHAR_BITS, len(READOUT_TEXT))),
        })

    def elaborate(self, platform):
        m = Module()
        bits = self.config.code_bits
        window = [Signal(bits, name=f"window{k}") for k in range(WINDOW)]
        for k in range(WINDOW):
            with m.If(self.capture[k]):
                m.d.sync += window[k].eq(self.code)
        # The search: candidate i, registered; its comparisons registered; the counts decide.
        i = Signal(range(WINDOW))
        m.d.sync += i.eq(Mux(i == WINDOW - 1, 0, i + 1))
        candidate = Signal(bits)                # registered: the selection and the comparisons in two clocks
        with m.Switch(i):
            for k in range(WINDOW):
                with m.Case(k):
                    m.d.sync += candidate.eq(window[k])
        less, not_more = Signal(WINDOW), Signal(WINDOW)
        value = Signal(bits)
        m.d.sync += [less[k].eq(window[k] < candidate) for k in range(WINDOW)]
        m.d.sync += [not_more[k].eq(window[k] <= candidate) for k in range(WINDOW)]
        m.d.sync += value.eq(candidate)
        half = WINDOW // 2
        with m.If((sum(less) <= half) & (sum(not_more) > half)):
            m.d.sync += self.median.eq(value)
        # The readout of the median (a window code, so at most the invalid code): invalid + 1 entries, looked up
        # in two registered clocks so that no path is deeper than a 64-entry ROM (one LUT6 per bit): the ROM split
        # into 64-word parts read by the low 6 address bits, then the part the high bits select.
        words = [sum(c << (CHAR_BITS * pos) for pos, c in enumerate(char_codes(text))) for text in self.table]
        shape = unsigned(len(self.chars.as_value()))
        low_bits = min(bits, ROM_PART_BITS)
        parts, high = [], Signal(max(1, bits - low_bits))
        m.d.sync += high.eq(self.median[low_bits:] if bits > low_bits else 0)
        for i in range(0, len(words), 1 << low_bits):
            part_words = words[i:i + (1 << low_bits)]
            part_words += part_words[-1:] * (2 - len(part_words))      # at least 2 words: no zero-width address
            rom = Memory(shape=shape, depth=len(part_words), init=part_words)
            m.submodules[f"readout_rom{i >> low_bits}"] = rom
            port = rom.read_port(domain="comb")
            part = Signal(shape, name=f"readout_part{i >> low_bits}")
            m.d.comb += port.addr.eq(self.median[:low_bits])
            m.d.sync += part.eq(port.data)
            parts.append(part)
        with m.Switch(high):
            for i, part in enumerate(parts):
                with m.Case(i):
                    m.d.sync += self.chars.eq(part)
        return m
