"""Median3x3: the streaming 3 x 3 median of the raw codes, borders clamped (docs/depth.md, "median")."""

from amaranth import Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from spec.sensor import SENSOR

__all__ = ["Median3x3", "median_signature"]


def _lo(a, b):
    return Mux(b < a, b, a)


def _hi(a, b):
    return Mux(b < a, a, b)


def median_signature(config, width, height, row_lag):
    """The ports of a streaming median with ``row_lag`` (:class:`Median3x3`'s, the separable medians'): the pass
    ``y`` (0 .. height + row_lag - 1), one input code or end token, one output median."""
    return wiring.Signature({
        "y": In(range(height + row_lag)),
        "valid": In(1),
        "x": In(range(width + 1)),
        "code": In(config.code_bits),
        "out_valid": Out(1),
        "out_x": Out(range(width)),
        "out_code": Out(config.code_bits),
    })


class Median3x3(wiring.Component):
    """Median of every 3 x 3 neighbourhood of a stream of codes arriving row by row.

    In pass ``y`` the codes of row ``y`` arrive (``x`` = 0..width-1, then the end token ``x`` = width, whose
    ``code`` is ignored); the block outputs the medians of row ``y - 1`` (none in pass 0). Pass ``height``
    brings no new row: it finishes row ``height - 1``. A line buffer keeps the two rows before. Clamping: the row
    above row 0 is row 0, the row below the last row is the last row, and the same for the columns.

    Parameters
    ----------
    config : DepthConfig
        Code width.
    geometry : SensorGeometry
        Image size.

    Ports
    -----
    y : In(range(height + 1))
        The pass; held while its codes and their results go through.
    valid, x, code : In
        One input pixel (or the end token).
    out_valid, out_x, out_code : Out
        One median of row ``y - 1``, ``LATENCY`` clocks after the input that completes its neighbourhood.

    Clock domain: ``sync``. Inputs at most every other clock.
    """

    #: Rows the output trails the input.
    ROW_LAG = 1
    #: Clocks from an input (the end token too) to the output it completes.
    LATENCY = 12

    def __init__(self, config=DEPTH, geometry=SENSOR):
        self.config = config
        self.width, self.height = geometry.buf_width, geometry.buf_height
        super().__init__(median_signature(config, self.width, self.height, self.ROW_LAG))

    def elaborate(self, platform):
        m = Module()
        bits, w = self.config.code_bits, self.width
        column = data.ArrayLayout(bits, 3)      # top, middle, bottom (unsorted), or low, mid, high (sorted)
        m.submodules.rows = rows = Memory(shape=data.ArrayLayout(bits, 2), depth=w, init=[])
        read = rows.read_port()
        write = rows.write_port()

        # q: read the two rows above (word x: [row y - 1, row y - 2]).
        inside = self.valid & (self.x < w)
        m.d.comb += read.addr.eq(self.x)
        # Data registers are reset-less (read only behind a set valid bit); the valid bits keep the reset.
        v1, end1 = Signal(), Signal()
        x1, code1 = Signal(range(w + 1), reset_less=True), Signal(bits, reset_less=True)
        m.d.sync += [v1.eq(self.valid & (self.y != 0)), end1.eq(self.x == w), x1.eq(self.x),
                     code1.eq(self.code)]
        w1 = Signal()
        m.d.sync += w1.eq(inside)
        # q + 1: the column (clamped), and the rows written back.
        above, middle = read.data[1], read.data[0]
        m.d.comb += [write.addr.eq(x1), write.en.eq(w1)]
        m.d.comb += [write.data[0].eq(code1), write.data[1].eq(middle)]
        col = Signal(column, reset_less=True)
        v2, end2, x2 = Signal(), Signal(), Signal(range(w + 1), reset_less=True)
        m.d.sync += [
            v2.eq(v1), end2.eq(end1), x2.eq(x1),
            col[0].eq(Mux(self.y == 1, middle, above)),
            col[1].eq(middle),
            col[2].eq(Mux(self.y == self.height, middle, code1)),
        ]
        # q + 2 .. q + 4: sort the column (three compare-exchanges, one per clock).
        v, end, x, c = v2, end2, x2, col
        for step, (i, j) in enumerate(((0, 1), (1, 2), (0, 1))):
            nv, nend, nx, nc = Signal(name=f"sort_v{step}"), Signal(name=f"sort_end{step}"), \
                Signal(range(w + 1), name=f"sort_x{step}", reset_less=True), \
                Signal(column, name=f"sort_col{step}", reset_less=True)
            m.d.sync += [nv.eq(v), nend.eq(end), nx.eq(x), nc.eq(c)]
            m.d.sync += [nc[i].eq(_lo(c[i], c[j])), nc[j].eq(_hi(c[i], c[j]))]
            v, end, x, c = nv, nend, nx, nc
        # q + 5: the window of three sorted columns around x - 1.
        newest, previous = Signal(column, reset_less=True), Signal(column, reset_less=True)
        window = [Signal(column, name=f"window{i}", reset_less=True) for i in range(3)]
        wv, wx = Signal(), Signal(range(w), reset_less=True)
        m.d.sync += wv.eq(v & (x != 0))
        with m.If(v):
            with m.If(~end):
                m.d.sync += [newest.eq(c), previous.eq(newest)]
            m.d.sync += [
                wx.eq(x - 1),
                window[0].eq(Mux(x == 1, newest, previous)),
                window[1].eq(newest),
                window[2].eq(Mux(end, newest, c)),
            ]
        # q + 6 .. q + 11: max of the lows, median of the middles, min of the highs, then their median.
        lows, mids, highs = [[window[i][k] for i in range(3)] for k in range(3)]
        stages = [
            lambda s: {"lo": _hi(lows[0], lows[1]), "l2": lows[2], "ma": _lo(mids[0], mids[1]),
                       "mb": _hi(mids[0], mids[1]), "m2": mids[2], "hi": _lo(highs[0], highs[1]),
                       "h2": highs[2]},
            lambda s: {"lo": _hi(s["lo"], s["l2"]), "ma": s["ma"], "mt": _lo(s["mb"], s["m2"]),
                       "hi": _lo(s["hi"], s["h2"])},
            lambda s: {"lo": s["lo"], "mid": _hi(s["ma"], s["mt"]), "hi": s["hi"]},
            lambda s: {"p": _lo(s["lo"], s["mid"]), "q": _hi(s["lo"], s["mid"]), "hi": s["hi"]},
            lambda s: {"p": s["p"], "r": _lo(s["q"], s["hi"])},
            lambda s: {"out": _hi(s["p"], s["r"])},
        ]
        state, sv, sx = {}, wv, wx
        for n, stage in enumerate(stages):
            values = stage(state)
            state = {}
            for key, value in values.items():
                reg = Signal(bits, name=f"median{n}_{key}", reset_less=True)
                m.d.sync += reg.eq(value)
                state[key] = reg
            nv, nx = Signal(name=f"median{n}_v"), Signal(range(w), name=f"median{n}_x", reset_less=True)
            m.d.sync += [nv.eq(sv), nx.eq(sx)]
            sv, sx = nv, nx
        m.d.comb += [self.out_valid.eq(sv), self.out_x.eq(sx), self.out_code.eq(state["out"])]
        return m
