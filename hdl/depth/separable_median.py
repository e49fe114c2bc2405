"""SeparableMedian: the streaming separable n x n median (n = 5 or 7) of the raw codes, borders clamped, each
median plain or over the valid codes only (docs/depth.md, "median")."""

import functools
import operator

from amaranth import Array, C, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory

from hdl.depth.median import median_signature
from spec.depth import DEPTH
from spec.sensor import SENSOR

__all__ = ["SeparableMedian", "separable_median"]


def _exactly(bits, r):
    """Exactly ``r`` of ``bits`` set, as and/or logic (a count would be an adder)."""
    if r < 0 or r > len(bits):
        return C(0, 1)
    if not bits:
        return C(1, 1)
    return (bits[0] & _exactly(bits[1:], r - 1)) | (~bits[0] & _exactly(bits[1:], r))


def _selected(m, values, below, count, v, x, name, invalid):
    """The registered median of ``values`` (n codes) from ``below``: ``below[i]`` is the list of the n - 1
    comparison bits that count for value i (value j < value i, or j < i and equal: a total order in which each
    value's rank is the count of its set bits). Plain (``count`` None): the value of rank n // 2. Over the valid
    codes (``count``: of the valid codes, which sort last): the value of rank (count - 1) // 2 if count > n // 2,
    else ``invalid``. Returns (median, valid, x) a clock later."""
    k = len(values)
    if count is None:
        chosen = [_exactly(bits, k // 2) for bits in below]
    else:
        chosen = [functools.reduce(operator.or_, [(count == c) & _exactly(bits, (c - 1) // 2)
                                                  for c in range(k // 2 + 1, k + 1)]) for bits in below]
    choice = functools.reduce(operator.or_, [Mux(sel, value, 0) for sel, value in zip(chosen, values)])
    if count is not None:
        choice = Mux(count > k // 2, choice, invalid)
    selected = Signal.like(values[0], name=f"{name}_selected", reset_less=True)
    sv, sx = Signal(name=f"{name}_selected_v"), Signal.like(x, name=f"{name}_selected_x")
    m.d.sync += [selected.eq(choice), sv.eq(v), sx.eq(x)]
    return selected, sv, sx


def _below(n, at_most):
    """For each of n values, the comparison bits below it (:func:`_selected`) from ``at_most[i, j]`` (i < j):
    value i <= value j."""
    return [[at_most[j, i] for j in range(i)] + [~at_most[i, j] for j in range(i + 1, n)] for i in range(n)]


def _median(m, values, v, x, name, valid_only, invalid):
    """The median of ``values`` (n codes), with the valid bit ``v`` and the column ``x`` carried alongside:
    returns (median, valid, x) 2 clocks later. Each pair's comparison registered (and with ``valid_only`` the
    count of valid codes, code != ``invalid``), then the value of the median's rank selected
    (:func:`_selected`)."""
    k = len(values)
    held = [Signal.like(value, name=f"{name}_in{i}", reset_less=True) for i, value in enumerate(values)]
    at_most = {}
    for i in range(k):
        for j in range(i + 1, k):
            at_most[i, j] = Signal(name=f"{name}_le{i}{j}", reset_less=True)
            m.d.sync += at_most[i, j].eq(values[i] <= values[j])
    hv, hx = Signal(name=f"{name}_in_v"), Signal.like(x, name=f"{name}_in_x")
    m.d.sync += [hv.eq(v), hx.eq(x)] + [h.eq(value) for h, value in zip(held, values)]
    count = None
    if valid_only:
        count = Signal(range(k + 1), name=f"{name}_count", reset_less=True)
        m.d.sync += count.eq(sum(value != invalid for value in values))
    return _selected(m, held, _below(k, at_most), count, hv, hx, name, invalid)


#: Clocks through :func:`_median`.
MEDIAN_CLOCKS = 2
#: Clocks ``LATENCY`` gives each of the two medians, by (n, valid only) (the engine's schedules use ``LATENCY``).
_SCHEDULED_CLOCKS = {(5, False): 5, (5, True): 6, (7, False): 6, (7, True): 7}


def _median_clocks(n, valid_only):
    """Clocks ``LATENCY`` gives each median (at least :data:`MEDIAN_CLOCKS`)."""
    return _SCHEDULED_CLOCKS[n, bool(valid_only)]


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

    def _row_picks(self, m, y):
        """The pass's clamp, registered beside the pixel (stage q + 1 reads no comparison of ``y``): ``below``,
        the pass is below the image (y >= height); ``picks[j]`` for the column's rows y - 2L + j, j < L, the
        offset o of the row taken: ``above[2L - 1 - j - o]``, o = 0 inside the image, o = 2L - j - y for
        a row above it (row 0 = ``above[y - 1]``, passes L .. 2L - j - 1; :meth:`_column`)."""
        lag = self.ROW_LAG
        below = Signal(name="row_below", reset_less=True)
        m.d.sync += below.eq(y >= self.height)
        picks = []
        for j in range(lag):
            pick = Signal(range(lag - j + 1), name=f"row_pick{j}", reset_less=True)
            offset = C(0, pick.shape())
            for yy in range(2 * lag - j - 1, lag - 1, -1):
                offset = Mux(y == yy, 2 * lag - j - yy, offset)
            m.d.sync += pick.eq(offset)
            picks.append(pick)
        return below, picks

    def _column(self, picks, above, code):
        """The codes of rows y - 2L .. y (the column around the output row y - L), clamped to 0 .. height - 1:
        ``above[k]`` is row y - 1 - k, ``code`` row y. A row above the image is row 0 = ``above[y - 1]``, picked
        by ``picks`` (:meth:`_row_picks`). A row below it is already row height - 1: from pass height on, the
        code taken for row y (and written back as it) is ``above[0]``, row y - 1 (:meth:`elaborate`)."""
        lag = self.ROW_LAG
        column = []
        for j in range(2 * lag + 1):                        # row y - 2L + j
            if j < lag:                                     # above the image in passes L .. 2L - j - 1
                options = [above[2 * lag - 1 - j - o] for o in range(lag - j + 1)]
                column.append(Array(options)[picks[j]])
            else:
                column.append(code if j == 2 * lag else above[2 * lag - 1 - j])
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
        below1, picks1 = self._row_picks(m, y)
        # q + 1: the column of rows y - 2L .. y (clamped to 0 .. h - 1), and the rows written back.
        above = [read.data[k] for k in range(2 * lag)]      # rows y - 1, ..., y - 2L
        # Below the image (passes height ..) row y is row y - 1: row height - 1, taken again and written again.
        code = Signal(bits, name="row_code")
        m.d.comb += code.eq(Mux(below1, above[0], code1))
        m.d.comb += [write.addr.eq(x1), write.en.eq(w1), write.data[0].eq(code)]
        m.d.comb += [write.data[k + 1].eq(above[k]) for k in range(2 * lag - 1)]
        col = [Signal(bits, name=f"column{k}", reset_less=True) for k in range(n)]
        v2, end2, x2 = Signal(), Signal(), Signal(range(w + 1), reset_less=True)
        m.d.sync += [v2.eq(v1), end2.eq(end1), x2.eq(x1)]
        m.d.sync += [c.eq(value) for c, value in zip(col, self._column(picks1, above, code))]
        # The column's median (end: carried through, its value unused).
        cend = end2                                         # the end token's flag, beside the median
        for k in range(MEDIAN_CLOCKS):
            delayed = Signal(name=f"column_median{k}_end")
            m.d.sync += delayed.eq(cend)
            cend = delayed
        col_median, cv, cx = _median(m, col, v2, x2, "column_median", self.VALID_ONLY, invalid)
        out, ov, ox = self._row_median(m, col_median, cv, cx, cend)
        # The output waits for the clocks LATENCY gives the two medians beyond theirs (MEDIAN_CLOCKS, and the row's
        # window one).
        for k in range(2 * (_median_clocks(n, self.VALID_ONLY) - MEDIAN_CLOCKS) + 1):
            out_k, ov_k = Signal.like(out, name=f"out{k}", reset_less=True), Signal(name=f"out{k}_v")
            ox_k = Signal.like(ox, name=f"out{k}_x", reset_less=True)
            m.d.sync += [out_k.eq(out), ov_k.eq(ov), ox_k.eq(ox)]
            out, ov, ox = out_k, ov_k, ox_k
        m.d.comb += [self.out_valid.eq(ov), self.out_x.eq(ox), self.out_code.eq(out)]
        return m

    def _row_median(self, m, col_median, cv, cx, cend):
        """The window of the last n column medians (newest last) around column x - L, registered with each pair's
        comparison, then its median (:func:`_selected`). The window slides a column a step: the comparisons among
        the 2L columns it keeps are carried along, the newest's with them made. Column 0's median fills the window
        (the left clamp: every pair equal); the end token and the L - 1 clocks after it (tails: columns w + 1 ..)
        repeat the last column's (the right clamp)."""
        bits, w, lag = self.config.code_bits, self.width, self.ROW_LAG
        n, invalid = 2 * lag + 1, self.config.invalid
        last = [Signal(bits, name=f"window_column{k}", reset_less=True) for k in range(2 * lag)]   # x - 1 ..
        kept = last[::-1]                                   # x - 2L .. x - 1: the window's first 2L
        kept_le = {(i, j): Signal(name=f"window_column_le{i}{j}", reset_less=True)
                   for i in range(2 * lag) for j in range(i + 1, 2 * lag)}
        tails, previous = [], cv & cend
        for k in range(1, lag):                             # tail k: output column w - L + k
            tail = Signal(name="second" if k == 1 else f"tail{k}")
            m.d.sync += tail.eq(previous)
            tails.append(tail)
            previous = tail
        any_tail = functools.reduce(operator.or_, tails)
        newest = Signal(bits, name="window_newest")
        m.d.comb += newest.eq(Mux(cend | any_tail, last[0], col_median))
        to_newest = [Signal(name=f"window_le{i}{2 * lag}") for i in range(2 * lag)]
        m.d.comb += [le.eq(value <= newest) for le, value in zip(to_newest, kept)]
        window = [Signal(bits, name=f"window{k}", reset_less=True) for k in range(n)]
        window_le = {(i, j): Signal(name=f"window_le{i}{j}", reset_less=True) for i in range(n) for j in range(i + 1, n)}
        wv, wx = Signal(), Signal(range(w), reset_less=True)
        # A tail's column w - L + k exists iff w - L + k >= 0.
        m.d.sync += wv.eq(functools.reduce(operator.or_, [cv & (cx >= lag)] +
                                           [t for k, t in enumerate(tails, 1) if w - lag + k >= 0]))
        column = cx - lag
        for k, tail in enumerate(tails, 1):
            column = Mux(tail, max(w - lag + k, 0), column)
        count = None
        if self.VALID_ONLY:
            count = Signal(range(n + 1), name="window_count", reset_less=True)
        with m.If(cv | any_tail):
            with m.If(cv & (cx == 0)):
                m.d.sync += [reg.eq(newest) for reg in last] + [le.eq(1) for le in kept_le.values()]
            with m.Else():
                m.d.sync += [last[0].eq(newest)] + [last[k].eq(last[k - 1]) for k in range(1, 2 * lag)]
                m.d.sync += [le.eq(kept_le[i + 1, j + 1] if j + 1 < 2 * lag else to_newest[i + 1])
                             for (i, j), le in kept_le.items()]
            m.d.sync += [window[k].eq(value) for k, value in enumerate(kept + [newest])]
            m.d.sync += [le.eq(kept_le[i, j] if j < 2 * lag else to_newest[i]) for (i, j), le in window_le.items()]
            if count is not None:
                m.d.sync += count.eq(sum(value != invalid for value in kept + [newest]))
            m.d.sync += wx.eq(column)
        return _selected(m, window, _below(n, window_le), count, wv, wx, "window_median", invalid)


@functools.cache
def separable_median(n, valid_only=False):
    """The :class:`SeparableMedian` class of side ``n`` (5 or 7), each median over the valid codes iff
    ``valid_only``: ``ROW_LAG`` = n // 2 and ``LATENCY`` its own.

    Raises
    ------
    ValueError
        For another n.
    """
    if n not in (5, 7):
        raise ValueError(f"the separable median is 5 x 5 or 7 x 7, not {n!r}")
    if (n, valid_only) == (SeparableMedian.SIZE, SeparableMedian.VALID_ONLY):
        return SeparableMedian
    lag = n // 2
    return type(f"SeparableMedian{n}{'Valid' if valid_only else ''}", (SeparableMedian,), {
        "SIZE": n, "VALID_ONLY": bool(valid_only), "ROW_LAG": lag,
        "LATENCY": 3 + 2 * _median_clocks(n, valid_only) + lag - 1, "__doc__": SeparableMedian.__doc__})
