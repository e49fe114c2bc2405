"""SeparableMedian5: the streaming separable 5 x 5 median of the raw codes, borders clamped (docs/depth.md,
"median")."""

from amaranth import Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from spec.sensor import SENSOR

__all__ = ["SeparableMedian5", "MEDIAN5_NETWORK"]

#: The median of 5 as a compare-exchange network, in layers (one clock each): after it, element 2 is the median
#: (the 0-1 principle: tests/test_depth_median5.py checks it on every 0/1/2 input).
MEDIAN5_NETWORK = (((0, 1), (3, 4)), ((0, 3), (1, 4)), ((1, 2),), ((2, 3),), ((1, 2),))


def _median5(m, values, v, x, name):
    """The registered median-of-5 network on ``values`` (five codes), with the valid bit ``v`` and the column ``x``
    carried alongside: returns (median, valid, x), ``len(MEDIAN5_NETWORK)`` clocks later."""
    shape = data.ArrayLayout(len(values[0]), 5)
    c = Signal(shape, name=f"{name}_in")
    m.d.comb += [c[i].eq(value) for i, value in enumerate(values)]
    for n, layer in enumerate(MEDIAN5_NETWORK):
        nc = Signal(shape, name=f"{name}{n}", reset_less=True)
        nv, nx = Signal(name=f"{name}{n}_v"), Signal.like(x, name=f"{name}{n}_x")
        m.d.sync += [nc.eq(c), nv.eq(v), nx.eq(x)]
        for i, j in layer:
            m.d.sync += [nc[i].eq(Mux(c[j] < c[i], c[j], c[i])), nc[j].eq(Mux(c[j] < c[i], c[i], c[j]))]
        c, v, x = nc, nv, nx
    return c[2], v, x


class SeparableMedian5(wiring.Component):
    """The separable 5 x 5 median of a stream of codes arriving row by row: the median of the five column medians
    at columns x - 2 .. x + 2, each the median of the column's five codes at rows y - 2 .. y + 2.

    In pass ``y`` the codes of row ``y`` arrive (``x`` = 0..width-1, then the end token ``x`` = width, whose
    ``code`` is ignored); the block outputs the medians of row ``y - ROW_LAG`` = ``y - 2`` (none in passes 0
    and 1). Passes ``height`` and ``height + 1`` bring no new row: they finish rows ``height - 2`` and
    ``height - 1``. A line buffer keeps the four rows before. Clamping: the rows above row 0 are row 0, the rows
    below the last row are the last row (``golden.depth.separable_median5``); the columns left of column 0 take
    column 0's median, those right of the last column the last column's.

    Parameters
    ----------
    config : DepthConfig
        Code width.
    geometry : SensorGeometry
        Image size.

    Ports
    -----
    y : In(range(height + 2))
        The pass; held while its codes and their results go through.
    valid, x, code : In
        One input pixel (or the end token).
    out_valid, out_x, out_code : Out
        One median of row ``y - 2``: that of column x - 2 ``LATENCY - 1`` clocks after input column x; the end
        token completes the last two columns, ``LATENCY - 1`` and ``LATENCY`` clocks after it.

    Clock domain: ``sync``. Inputs at most every other clock.
    """

    #: Rows the output trails the input.
    ROW_LAG = 2
    #: Clocks from the end token to the row's last output.
    LATENCY = 14

    def __init__(self, config=DEPTH, geometry=SENSOR):
        self.config = config
        self.width, self.height = geometry.buf_width, geometry.buf_height
        super().__init__({
            "y": In(range(self.height + self.ROW_LAG)),
            "valid": In(1),
            "x": In(range(self.width + 1)),
            "code": In(config.code_bits),
            "out_valid": Out(1),
            "out_x": Out(range(self.width)),
            "out_code": Out(config.code_bits),
        })

    def elaborate(self, platform):
        m = Module()
        bits, w, h = self.config.code_bits, self.width, self.height
        m.submodules.rows = rows = Memory(shape=data.ArrayLayout(bits, 4), depth=w, init=[])
        read = rows.read_port()
        write = rows.write_port()

        # q: read the four rows above (word x: [row y - 1, y - 2, y - 3, y - 4]).
        y = self.y
        m.d.comb += read.addr.eq(self.x)
        # Data registers are reset-less (read only behind a set valid bit); the valid bits keep the reset.
        v1, end1, w1 = Signal(), Signal(), Signal()
        x1, code1 = Signal(range(w + 1), reset_less=True), Signal(bits, reset_less=True)
        m.d.sync += [v1.eq(self.valid & (y >= 2)), end1.eq(self.x == w), x1.eq(self.x), code1.eq(self.code),
                     w1.eq(self.valid & (self.x < w))]
        # q + 1: the column of rows y - 4 .. y (clamped to 0 .. h - 1), and the rows written back.
        above = [read.data[k] for k in range(4)]            # rows y - 1, y - 2, y - 3, y - 4
        m.d.comb += [write.addr.eq(x1), write.en.eq(w1), write.data[0].eq(code1)]
        m.d.comb += [write.data[k + 1].eq(above[k]) for k in range(3)]
        column = [
            Mux(y == 2, above[1], Mux(y == 3, above[2], above[3])),    # row y - 4: row 0 above the image
            Mux(y == 2, above[1], above[2]),                            # row y - 3
            above[1],                                                   # row y - 2: the output row
            Mux(y == h + 1, above[1], above[0]),                        # row y - 1: row h - 1 below the image
            Mux(y == h + 1, above[1], Mux(y == h, above[0], code1)),    # row y
        ]
        col = [Signal(bits, name=f"column{k}", reset_less=True) for k in range(5)]
        v2, end2, x2 = Signal(), Signal(), Signal(range(w + 1), reset_less=True)
        m.d.sync += [v2.eq(v1), end2.eq(end1), x2.eq(x1)] + [c.eq(value) for c, value in zip(col, column)]
        # q + 2 .. q + 6: the column's median (end: carried through, its value unused).
        cend = end2                                         # the end token's flag, along the network
        for n in range(len(MEDIAN5_NETWORK)):
            delayed = Signal(name=f"column_median{n}_end")
            m.d.sync += delayed.eq(cend)
            cend = delayed
        col_median, cv, cx = _median5(m, col, v2, x2, "column_median")
        # q + 7: the window of the last five column medians (newest last) around column x - 2. Column 0's median
        # fills the window (the left clamp); the end token and the clock after it (column w + 1) repeat the last
        # column's (the right clamp). Inputs come at most every other clock, so the clock after the end token is
        # free.
        last = [Signal(bits, name=f"window_column{k}", reset_less=True) for k in range(4)]   # x - 1 .. x - 4
        second = Signal()
        m.d.sync += second.eq(cv & cend)
        newest = Mux(cend | second, last[0], col_median)
        window = [Signal(bits, name=f"window{k}", reset_less=True) for k in range(5)]
        wv, wx = Signal(), Signal(range(w), reset_less=True)
        m.d.sync += wv.eq((cv & (cx >= 2)) | second)
        with m.If(cv | second):
            with m.If(cv & (cx == 0)):
                m.d.sync += [reg.eq(newest) for reg in last]
            with m.Else():
                m.d.sync += [last[0].eq(newest)] + [last[k].eq(last[k - 1]) for k in range(1, 4)]
            m.d.sync += [window[k].eq(last[3 - k]) for k in range(4)] + [window[4].eq(newest)]
            m.d.sync += wx.eq(Mux(second, w - 1, cx - 2))
        # q + 8 .. q + 12: the median of the window.
        out, ov, ox = _median5(m, window, wv, wx, "window_median")
        m.d.comb += [self.out_valid.eq(ov), self.out_x.eq(ox), self.out_code.eq(out)]
        return m
