"""The depth colour map (docs/display.md, "Depth panel"): its contents and the block that looks a code up."""

from fractions import Fraction

from amaranth import Module, Mux, Signal, unsigned
from amaranth.lib import wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from spec.display import DEPTH_COLOURS, DEPTH_INVALID_RGB

__all__ = ["ColourMap", "colour_table", "LATENCY"]

#: Clocks from ``code`` in to ``rgb`` out.
LATENCY = 2


def colour_table(config=DEPTH):
    """24-bit RGB (R in bits 23:16) of every code c = 0..2**F D: u = min((n - 1) c / (2**F (D - 1)), n - 1)
    along the ``n`` anchors of :data:`spec.display.DEPTH_COLOURS`, linear between the two anchors around it, each
    channel rounded half up (exact fractions); the invalid code 2**F D is ``DEPTH_INVALID_RGB``."""
    anchors = DEPTH_COLOURS
    last = len(anchors) - 1
    table = []
    for code in range(config.invalid):
        u = min(Fraction(last * code, config.fraction * (config.disparities - 1)), Fraction(last))
        i = min(int(u), last - 1)
        f = u - i
        rgb = 0
        for a, b in zip(anchors[i], anchors[i + 1]):
            rgb = (rgb << 8) | int(a + f * (b - a) + Fraction(1, 2))
        table.append(rgb)
    return table + [DEPTH_INVALID_RGB]


class ColourMap(wiring.Component):
    """The colour of a depth code (:func:`colour_table`): the 2**F D codes below the invalid one in a ROM read
    synchronously (block RAM: 1024 x 24 bits for D = 64), the invalid code's colour chosen in the output
    register.

    Parameters
    ----------
    config : :class:`spec.depth.DepthConfig`
        D and the fraction bits (codes 0..2**F D, 2**F D invalid).

    Attributes
    ----------
    code : In(code_bits)
        A code 0..2**F D (larger values are not allowed).
    rgb : Out(24)
        Its colour, R in bits 23:16.

    Clock domain: ``sync``. Latency: :data:`LATENCY` (2) clocks, ``rgb`` registered.
    """

    def __init__(self, config=DEPTH):
        self.config = config
        self.table = colour_table(config)
        super().__init__({"code": In(config.code_bits), "rgb": Out(24)})

    def elaborate(self, platform):
        m = Module()
        cfg = self.config
        m.submodules.colour_rom = rom = Memory(shape=unsigned(24), depth=cfg.invalid, init=self.table[:-1])
        word = rom.read_port(domain="sync")
        invalid = Signal()
        m.d.comb += word.addr.eq(self.code)             # the invalid code's low bits read any word
        m.d.sync += [invalid.eq(self.code == cfg.invalid),
                     self.rgb.eq(Mux(invalid, self.table[-1], word.data))]
        return m
