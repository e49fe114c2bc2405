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

__all__ = ["CentreDistance", "readout_table", "readout_symbols", "SETTLE_CLOCKS", "SYMBOLS"]

WINDOW = 9
#: Clocks after the last window capture until ``chars`` holds its readout.
SETTLE_CLOCKS = WINDOW + 6
#: The readout's digit characters (before the unit "cm").
DIGITS = len(READOUT_TEXT) - 2
#: The characters a digit position shows, in the readout ROM's symbol order: a symbol is its index here.
SYMBOLS = " -0123456789"
SYMBOL_BITS = (len(SYMBOLS) - 1).bit_length()


def readout_table(geometry=SENSOR, config=DEPTH):
    """The readout text of every code 0..invalid: the distance B f / (d p s) of the sub-pixel disparity
    d = code / 2**F in whole centimetres (rounded half up), right-aligned in four characters, then "cm";
    "----cm" for code 0 (infinitely far), the invalid code, and a distance that does not fit the four digits.
    Exact rational arithmetic (the rig's decimal constants as fractions)."""
    numerator = Fraction(str(VMODCAM_RIG.BASELINE_M)) * Fraction(str(VMODCAM_RIG.FOCAL_M)) * 100 * config.fraction
    denominator = Fraction(str(VMODCAM_RIG.PIXEL_M)) * geometry.scale
    table = []
    for code in range(config.invalid + 1):
        text = "-" * DIGITS
        if code not in (0, config.invalid):
            cm = int(numerator / (denominator * code) + Fraction(1, 2))
            if cm < 10 ** DIGITS:
                text = str(cm).rjust(DIGITS)
        table.append(text + READOUT_TEXT[DIGITS:])
    return table


def readout_symbols(table, depth):
    """The readout ROM's words: entry k holds the digit characters of ``table[k]`` as :data:`SYMBOLS` indices,
    :data:`SYMBOL_BITS` each, the first character in the lowest bits; ``depth`` words, the entries past the table
    dashes."""
    texts = [text[:DIGITS] for text in table[:depth]] + ["-" * DIGITS] * max(0, depth - len(table))
    return [sum(SYMBOLS.index(c) << (SYMBOL_BITS * pos) for pos, c in enumerate(text)) for text in texts]


class CentreDistance(wiring.Component):
    """Keeps the nine codes of the 3 x 3 window at the depth map's centre, takes their median (the fifth
    smallest; the invalid code sorts above every disparity) and gives the readout of that sub-pixel code
    (:func:`readout_table`) as font codes.

    The median is found by a free-running search: every clock one of the nine codes is the candidate; it is
    the median when at most four codes are smaller and at least five are not larger. So ``chars`` holds the
    window's readout :data:`SETTLE_CLOCKS` clocks after the window last changed.

    The readout is one synchronous ROM (block RAM, one word per code below the invalid one: 1K x 16 at D = 64,
    2K x 16 at D = 128; ``ROM_STYLE`` "block"
    for XST, whose ROM inference takes an array with a registered read as a block ROM) of the four digit
    characters as 4-bit :data:`SYMBOLS`, decoded into font codes in the next clock; the unit is constant.

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
        # The readout of the median (a window code, so at most the invalid code) in two registered clocks: one
        # synchronous ROM read (block RAM) of the four digit characters as symbols, then the symbols decoded into
        # font codes. The ROM holds the codes below 2**rom_bits, those from the invalid code on as dashes; a code
        # past the ROM (the invalid code when it is a power of two, 2**rom_bits) reads as dashes by a comparison,
        # registered beside the read.
        rom_bits = (self.config.invalid - 1).bit_length()
        rom = Memory(shape=unsigned(SYMBOL_BITS * DIGITS), depth=1 << rom_bits,
                     init=readout_symbols(self.table, 1 << rom_bits), attrs={"ROM_STYLE": "block"})
        m.submodules.readout_rom = rom
        port = rom.read_port(domain="sync")
        beyond = Signal()
        m.d.comb += port.addr.eq(self.median[:rom_bits])
        m.d.sync += beyond.eq(self.median[rom_bits:] != 0 if bits > rom_bits else 0)
        for pos in range(DIGITS):
            symbol = port.data[SYMBOL_BITS * pos:SYMBOL_BITS * (pos + 1)]
            with m.If(beyond):
                m.d.sync += self.chars[pos].eq(char_codes("-")[0])
            with m.Else():
                with m.Switch(symbol):
                    for k, c in enumerate(SYMBOLS):
                        with m.Case(k):
                            m.d.sync += self.chars[pos].eq(char_codes(c)[0])
                    with m.Default():                   # not in the ROM
                        m.d.sync += self.chars[pos].eq(char_codes(SYMBOLS[0])[0])
        for pos in range(DIGITS, len(READOUT_TEXT)):     # the unit: constant
            m.d.comb += self.chars[pos].eq(char_codes(READOUT_TEXT[pos])[0])
        return m
