"""SeparableMedian: the streaming separable n x n median (n = 5 or 7) of the raw codes, borders clamped, each
median plain or over the valid codes only (docs/depth.md, "median")."""

import functools
import operator

from amaranth import Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory

from hdl.depth.median import median_signature
from spec.depth import DEPTH
from spec.sensor import SENSOR

__all__ = ["SeparableMedian", "separable_median", "MEDIAN_NETWORKS", "SORT_NETWORKS"]

#: The median of n as a compare-exchange network, in layers (one clock each): after it, element n // 2 is the
#: median (the 0-1 principle: tests/test_depth_separable_median.py checks it on every 0/1 input). 7: the optimal
#: 16-exchange sort of 7 in 6 layers without the exchanges that do not reach element 3.
MEDIAN_NETWORKS = {
    5: (((0, 1), (3, 4)), ((0, 3), (1, 4)), ((1, 2),), ((2, 3),), ((1, 2),)),
    7: (((0, 6), (2, 3), (4, 5)), ((0, 2), (1, 4), (3, 6)), ((0, 1), (2, 5), (3, 4)), ((1, 2), (4, 6)),
        ((2, 3), (4, 5)), ((3, 4),)),
}
#: Sorting networks of n (optimal in exchanges and layers), in layers: the median over the valid codes reads
#: ranks 1 .. (n - 1) // 2 of the sorted codes (the invalid code sorts last).
SORT_NETWORKS = {
    5: (((0, 3), (1, 4)), ((0, 2), (1, 3)), ((0, 1), (2, 4)), ((1, 2), (3, 4)), ((2, 3),)),
    7: (((0, 6), (2, 3), (4, 5)), ((0, 2), (1, 4), (3, 6)), ((0, 1), (2, 5), (3, 4)), ((1, 2), (4, 6)),
        ((2, 3), (4, 5)), ((1, 2), (3, 4), (5, 6))),
}


def _median(m, values, v, x, name, valid_only, invalid):
    """The registered median of ``values`` (n codes), with the valid bit ``v`` and the column ``x`` carried
    alongside: returns (median, valid, x) :func:`_median_clocks` clocks later. Plain: element n // 2 after
    ``MEDIAN_NETWORKS[n]``. ``valid_only``: the count of valid codes (code != ``invalid``) registered beside the
    first layer of ``SORT_NETWORKS[n]``, then one clock selecting rank (count - 1) // 2 if count > n // 2, else
    ``invalid``."""
    k = len(values)
    shape = data.ArrayLayout(len(values[0]), k)
    c = Signal(shape, name=f"{name}_in")
    m.d.comb += [c[i].eq(value) for i, value in enumerate(values)]
    if valid_only:
        count = Signal(range(k + 1), name=f"{name}_count", reset_less=True)
        m.d.sync += count.eq(sum(value != invalid for value in values))
    network = SORT_NETWORKS[k] if valid_only else MEDIAN_NETWORKS[k]
    for n, layer in enumerate(network):
        nc = Signal(shape, name=f"{name}{n}", reset_less=True)
        nv, nx = Signal(name=f"{name}{n}_v"), Signal.like(x, name=f"{name}{n}_x")
        m.d.sync += [nc.eq(c), nv.eq(v), nx.eq(x)]
        for i, j in layer:
            m.d.sync += [nc[i].eq(Mux(c[j] < c[i], c[j], c[i])), nc[j].eq(Mux(c[j] < c[i], c[i], c[j]))]
        c, v, x = nc, nv, nx
    if not valid_only:
        return c[k // 2], v, x
    for n in range(1, len(network)):        # the count, registered beside the first layer, along the others
        carried = Signal.like(count, name=f"{name}{n}_count")
        m.d.sync += carried.eq(count)
        count = carried
    selected = Signal.like(c[0], name=f"{name}_selected", reset_less=True)
    sv, sx = Signal(name=f"{name}_selected_v"), Signal.like(x, name=f"{name}_selected_x")
    choice = invalid
    for valid in range(k // 2 + 1, k + 1):
        choice = Mux(count == valid, c[(valid - 1) // 2], choice)
    m.d.sync += [selected.eq(choice), sv.eq(v), sx.eq(x)]
    return selected, sv, sx


def _median_clocks(n, valid_only):
    """Clocks through :func:`_median`."""
    return len(SORT_NETWORKS[n]) + 1 if valid_only else len(MEDIAN_NETWORKS[n])


class SeparableMedian(wiring.Component):
    """The separable n x n median (n = ``SIZE``, 5 or 7, L = ``ROW_LAG`` = n // 2) of a stream of codes arriving
    row by row: the median of the n column medians at columns x - L .. x + L, each the median of the column's n
    codes at rows y - L .. y + L; with ``VALID_ONLY`` each median is over its valid codes (docs/depth.md,
    "median"). This class is the plain 5 x 5; :func:`separable_median` gives the class of any n and option.

    In pass ``y`` the codes of row ``y`` arrive (``x`` = 0..width-1, then the end token ``x`` = width, whose
    ``code`` is ignored); the block outputs the medians of row ``y - L`` (none in passes 0 .. L - 1). Passes
    ``height`` .. ``height + L - 1`` bring no new row: they finish rows ``height - L`` .. ``height - 1``. A line
    buffer keeps the 2L rows before. Clamping: the rows above row 0 are row 0, the rows below the last row are the
    last row (``golden.depth.separable_median``); the columns left of column 0 take column 0's median, those right
    of the last column the last column's.

    Parameters
    ----------
    config : DepthConfig
        Code width and the invalid code (``SIZE`` and ``VALID_ONLY`` are the class's, not ``config.median``'s).
    geometry : SensorGeometry
        Image size.

    Ports
    -----
    y : In(range(height + L))
        The pass; held while its codes and their results go through.
    valid, x, code : In
        One input pixel (or the end token).
    out_valid, out_x, out_code : Out
        One median of row ``y - L``: that of column x - L ``LATENCY - L + 1`` clocks after input column x; the
        end token completes the last L columns, on the L clocks ending ``LATENCY`` clocks after it.

    Clock domain: ``sync``. Inputs at most every other clock; the L - 1 clocks after an end token free.
    """

    #: The window's side.
    SIZE = 5
    #: Each median over the valid codes only.
    VALID_ONLY = False
    #: Rows the output trails the input.
    ROW_LAG = SIZE // 2
    #: Clocks from the end token to the row's last output.
    LATENCY = 3 + 2 * _median_clocks(SIZE, VALID_ONLY) + ROW_LAG - 1

    def __init__(self, config=DEPTH, geometry=SENSOR):
        self.config = config
        self.width, self.height = geometry.buf_width, geometry.buf_height
        super().__init__(median_signature(config, self.width, self.height, self.ROW_LAG))

    def _column(self, y, above, code):
        """The codes of rows y - 2L .. y (the column around the output row y - L), clamped to 0 .. height - 1:
        ``above[k]`` is row y - 1 - k, ``code`` row y. A row above the image is row 0 = ``above[y - 1]``; a row
        below it is row height - 1 = ``above[y - height]``."""
        lag, h = self.ROW_LAG, self.height
        column = []
        for j in range(2 * lag + 1):                        # row y - 2L + j
            value = code if j == 2 * lag else above[2 * lag - 1 - j]
            if j < lag:                                     # above the image in passes L .. 2L - j - 1
                for yy in range(2 * lag - j - 1, lag - 1, -1):
                    value = Mux(y == yy, above[yy - 1], value)
            for yy in range(h + 2 * lag - j, h + lag):      # below the image in passes h + 2L - j .. h + L - 1
                value = Mux(y == yy, above[yy - h], value)
            column.append(value)
        return column

    def elaborate(self, platform):
        m = Module()
        bits, w, lag = self.config.code_bits, self.width, self.ROW_LAG
        n, invalid = 2 * lag + 1, self.config.invalid
        m.submodules.rows = rows = Memory(shape=data.ArrayLayout(bits, 2 * lag), depth=w, init=[])
        read = rows.read_port()
        write = rows.write_port()

        # q: read the 2L rows above (word x: [row y - 1, y - 2, ..., y - 2L]).
        y = self.y
        m.d.comb += read.addr.eq(self.x)
        # Data registers are reset-less (read only behind a set valid bit); the valid bits keep the reset.
        v1, end1, w1 = Signal(), Signal(), Signal()
        x1, code1 = Signal(range(w + 1), reset_less=True), Signal(bits, reset_less=True)
        m.d.sync += [v1.eq(self.valid & (y >= lag)), end1.eq(self.x == w), x1.eq(self.x), code1.eq(self.code),
                     w1.eq(self.valid & (self.x < w))]
        # q + 1: the column of rows y - 2L .. y (clamped to 0 .. h - 1), and the rows written back.
        above = [read.data[k] for k in range(2 * lag)]      # rows y - 1, ..., y - 2L
        m.d.comb += [write.addr.eq(x1), write.en.eq(w1), write.data[0].eq(code1)]
        m.d.comb += [write.data[k + 1].eq(above[k]) for k in range(2 * lag - 1)]
        col = [Signal(bits, name=f"column{k}", reset_less=True) for k in range(n)]
        v2, end2, x2 = Signal(), Signal(), Signal(range(w + 1), reset_less=True)
        m.d.sync += [v2.eq(v1), end2.eq(end1), x2.eq(x1)]
        m.d.sync += [c.eq(value) for c, value in zip(col, self._column(y, above, code1))]
        # The column's median (end: carried through, its value unused).
        cend = end2                                         # the end token's flag, along the network
        for k in range(_median_clocks(n, self.VALID_ONLY)):
            delayed = Signal(name=f"column_median{k}_end")
            m.d.sync += delayed.eq(cend)
            cend = delayed
        col_median, cv, cx = _median(m, col, v2, x2, "column_median", self.VALID_ONLY, invalid)
        out, ov, ox = self._row_median(m, col_median, cv, cx, cend)
        m.d.comb += [self.out_valid.eq(ov), self.out_x.eq(ox), self.out_code.eq(out)]
        return m

    def _row_median(self, m, col_median, cv, cx, cend):
        """The window of the last n column medians (newest last) around column x - L, registered, then its
        median. Column 0's median fills the window (the left clamp); the end token and the L - 1 clocks after it
        (tails: columns w + 1 ..) repeat the last column's (the right clamp)."""
        bits, w, lag = self.config.code_bits, self.width, self.ROW_LAG
        last = [Signal(bits, name=f"window_column{k}", reset_less=True) for k in range(2 * lag)]   # x - 1 ..
        tails, previous = [], cv & cend
        for k in range(1, lag):                             # tail k: output column w - L + k
            tail = Signal(name="second" if k == 1 else f"tail{k}")
            m.d.sync += tail.eq(previous)
            tails.append(tail)
            previous = tail
        any_tail = functools.reduce(operator.or_, tails)
        newest = Mux(cend | any_tail, last[0], col_median)
        window = [Signal(bits, name=f"window{k}", reset_less=True) for k in range(2 * lag + 1)]
        wv, wx = Signal(), Signal(range(w), reset_less=True)
        # A tail's column w - L + k exists iff w - L + k >= 0.
        m.d.sync += wv.eq(functools.reduce(operator.or_, [cv & (cx >= lag)] +
                                           [t for k, t in enumerate(tails, 1) if w - lag + k >= 0]))
        column = cx - lag
        for k, tail in enumerate(tails, 1):
            column = Mux(tail, max(w - lag + k, 0), column)
        with m.If(cv | any_tail):
            with m.If(cv & (cx == 0)):
                m.d.sync += [reg.eq(newest) for reg in last]
            with m.Else():
                m.d.sync += [last[0].eq(newest)] + [last[k].eq(last[k - 1]) for k in range(1, 2 * lag)]
            m.d.sync += [window[k].eq(last[2 * lag - 1 - k]) for k in range(2 * lag)] + [window[-1].eq(newest)]
            m.d.sync += wx.eq(column)
        return _median(m, window, wv, wx, "window_median", self.VALID_ONLY, self.config.invalid)


@functools.cache
def separable_median(n, valid_only=False):
    """The :class:`SeparableMedian` class of side ``n`` (5 or 7), each median over the valid codes iff
    ``valid_only``: ``ROW_LAG`` = n // 2 and ``LATENCY`` its own.

    Raises
    ------
    ValueError
        For another n.
    """
    if n not in MEDIAN_NETWORKS:
        raise ValueError(f"the separable median is 5 x 5 or 7 x 7, not {n!r}")
    if (n, valid_only) == (SeparableMedian.SIZE, SeparableMedian.VALID_ONLY):
        return SeparableMedian
    lag = n // 2
    return type(f"SeparableMedian{n}{'Valid' if valid_only else ''}", (SeparableMedian,), {
        "SIZE": n, "VALID_ONLY": bool(valid_only), "ROW_LAG": lag,
        "LATENCY": 3 + 2 * _median_clocks(n, valid_only) + lag - 1, "__doc__": SeparableMedian.__doc__})
