"""RegionScanner: the running coordinates of a scaled picture on the raster (no per-pixel multiplier)."""

from amaranth import Const, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

__all__ = ["RegionScanner"]


class RegionScanner(wiring.Component):
    """Running address of a ``width`` x ``height`` picture drawn with every pixel repeated ``scale_x`` times
    along a line and every row ``scale_y`` times, or (``stride`` > 1) at 1 / ``stride`` size: every ``stride``-th
    pixel of every ``stride``-th row from (0, 0); the address and coordinates of the current display pixel.

    Parameters
    ----------
    width, height : int
        The picture (before scaling).
    scale_x, scale_y : int
        Repetitions of a pixel along the line and of a row.
    stride : int
        Buffer pixels (and rows) from one display pixel (line) to the next; above 1 only with both scales 1, no
        ``wrap`` or ``cell_width``, and a picture a whole number of ``stride`` x ``stride`` blocks.
    wrap : int or None
        ``addr`` counts modulo ``wrap`` (a ring of rows: ``wrap`` = rows x ``width``); None: no wrap.
    cell_width : int or None
        Also count ``xb`` in cells of this many pixels (``cell``, ``column``); None: no cell counters.

    Attributes
    ----------
    active, eol, clear : In(1)
        Registered flags of the pixel at this clock: inside the picture, last pixel of a picture line, vertical
        blanking (clears the counters).
    addr, xb, yb : Out
        Valid while ``active``: ``addr`` = ``yb * width + xb`` (modulo ``wrap``), ``xb``, ``yb`` (buffer
        coordinates: multiples of ``stride``); all registers.
    row_done : Out(1)
        Combinational: this pixel ends the last copy of picture row ``yb``.
    cell, column : Out (with ``cell_width``)
        ``xb // cell_width`` and ``xb % cell_width``, registers updated with ``xb`` (no divider in front of them).

    Other attributes (state, not ports: what the formal harness's invariant reads,
    sim/formal/harnesses/compositor.py)
    row_start, x_phase, y_phase : Signal
        The address of (0, ``yb``), where a repeated row rewinds to; which copy of a pixel / row this is (0 at
        scale 1).

    Clock domain: ``sync``.

    Raises
    ------
    ValueError
        A ``stride`` above 1 with a scale above 1, ``wrap``, ``cell_width`` or a picture not a whole number of
        blocks.
    """

    def __init__(self, width, height, scale_x, scale_y=None, *, wrap=None, cell_width=None, stride=1):
        self.width, self.height = width, height
        self.scale_x, self.scale_y = scale_x, scale_x if scale_y is None else scale_y
        if stride != 1 and (stride < 1 or (self.scale_x, self.scale_y) != (1, 1) or wrap is not None
                            or cell_width is not None or width % stride or height % stride):
            raise ValueError(f"stride {stride} needs scale 1, no wrap or cells and a {width}x{height} picture of "
                             f"whole {stride}x{stride} blocks")
        self.stride = stride
        self.wrap = wrap
        self.cell_width = cell_width
        cells = {} if cell_width is None else {"cell": Out(range(max(2, -(-width // cell_width)))),
                                                 "column": Out(range(max(2, cell_width)))}
        super().__init__({
            "active": In(1),
            "eol": In(1),
            "clear": In(1),
            "addr": Out(range(max(2, wrap if wrap is not None else width * height))),
            "xb": Out(range(max(2, width))),           # (at least one bit: no zero-width vectors in Verilog)
            "yb": Out(range(max(2, height))),
            "row_done": Out(1),
            **cells,
        })
        self.row_start = Signal(range(max(2, wrap if wrap is not None else width * height)))
        self.x_phase = Signal(range(max(2, self.scale_x)))
        self.y_phase = Signal(range(max(2, self.scale_y)))

    @staticmethod
    def _phase(phase, scale):
        """(phase register or None at scale 1, is-last-copy condition)."""
        if scale == 1:
            return None, Const(1)
        return phase, phase == scale - 1

    def elaborate(self, platform):
        m = Module()
        x_phase, last_x_copy = self._phase(self.x_phase, self.scale_x)
        y_phase, last_y_copy = self._phase(self.y_phase, self.scale_y)
        row_start = self.row_start                  # address of (0, yb): where a repeated row rewinds to
        following = Signal.like(self.addr)          # the address after this one
        k = self.stride
        if k != 1:                                  # the next kept pixel; the next kept row's first pixel
            m.d.comb += following.eq(self.addr + k)
            next_row = row_start + k * self.width
        elif self.wrap is None:
            m.d.comb += following.eq(self.addr + 1)
        else:
            m.d.comb += following.eq(Mux(self.addr == self.wrap - 1, 0, self.addr + 1))
        m.d.comb += self.row_done.eq(self.active & self.eol & last_y_copy)
        cells = self.cell_width is not None
        with m.If(self.clear):
            m.d.sync += [self.addr.eq(0), row_start.eq(0), self.xb.eq(0), self.yb.eq(0)]
            if cells:
                m.d.sync += [self.cell.eq(0), self.column.eq(0)]
            m.d.sync += [p.eq(0) for p in (x_phase, y_phase) if p is not None]
        with m.Elif(self.active & self.eol):
            m.d.sync += self.xb.eq(0)
            if cells:
                m.d.sync += [self.cell.eq(0), self.column.eq(0)]
            if x_phase is not None:
                m.d.sync += x_phase.eq(0)
            with m.If(last_y_copy):                 # next picture row
                if k != 1:
                    m.d.sync += [self.addr.eq(next_row), row_start.eq(next_row), self.yb.eq(self.yb + k)]
                else:
                    m.d.sync += [self.addr.eq(following), row_start.eq(following), self.yb.eq(self.yb + 1)]
                if y_phase is not None:
                    m.d.sync += y_phase.eq(0)
            if y_phase is not None:
                with m.Else():                      # repeat this row
                    m.d.sync += [self.addr.eq(row_start), y_phase.eq(y_phase + 1)]
        with m.Elif(self.active):
            with m.If(last_x_copy):                 # next picture pixel
                m.d.sync += [self.addr.eq(following), self.xb.eq(self.xb + k)]
                if cells:
                    with m.If(self.column == self.cell_width - 1):
                        m.d.sync += [self.column.eq(0), self.cell.eq(self.cell + 1)]
                    with m.Else():
                        m.d.sync += self.column.eq(self.column + 1)
                if x_phase is not None:
                    m.d.sync += x_phase.eq(0)
            if x_phase is not None:
                with m.Else():                      # another copy of the same pixel
                    m.d.sync += x_phase.eq(x_phase + 1)
        return m
