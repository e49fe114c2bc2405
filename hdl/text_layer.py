"""TextLayer: text boxes on the raster from a small font ROM (the depth display's labels and readout)."""

from amaranth import Cat, Module, Mux, Signal, unsigned
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from hdl.delay import delayed
from spec.font import FONT, FONT_CELL
from spec.layout import TextBox
from hdl.region_scanner import RegionScanner

__all__ = ["TextLayer", "FONT_ORDER", "char_codes", "LATENCY"]

#: The font's characters in ROM order: a character's code is its index here.
FONT_ORDER = tuple(FONT)
#: Clocks from a raster position to its ``in_text`` / ``lit``.
LATENCY = 4
CHAR_BITS = (len(FONT_ORDER) - 1).bit_length()


def char_codes(text):
    """The ROM codes of ``text``; ``ValueError`` for a character the font does not have."""
    missing = sorted(set(text) - set(FONT_ORDER))
    if missing:
        raise ValueError(f"the font has no glyph for {missing!r}")
    return [FONT_ORDER.index(c) for c in text]


class TextLayer(wiring.Component):
    """Draws ``boxes`` (constant :class:`spec.layout.TextBox` es) and named ``dynamic`` boxes whose characters come
    from ``chars``. A box covers ``len(text)`` cells of ``FONT_CELL`` font pixels, each ``scale`` x ``scale``
    display pixels; a font pixel is lit where its glyph (:data:`spec.font.FONT`) has ``#`` (the cell's last
    column and row never are). The boxes must not overlap: so at most one is drawn in a clock, and the dynamic
    boxes share one font ROM, addressed by the character and glyph row of the one drawn.

    Parameters
    ----------
    boxes : tuple of TextBox
    dynamic : dict of str to TextBox
        Boxes by name; a box's ``text`` gives only the length, ``chars.<name>`` the characters.
    v_active : int
        Active lines (the counters clear below them).

    Attributes
    ----------
    x, y : In
        The raster position.
    chars : In(StructLayout({name: ArrayLayout(CHAR_BITS, len(box.text))}))
        Character codes (:data:`FONT_ORDER` indices) of each dynamic box; sampled when its cells are drawn.
    in_text, lit : Out(1)
        :data:`LATENCY` clocks after ``x``, ``y``: the position is inside a box, and it is a lit font pixel.

    Clock domain: ``sync``.

    Raises
    ------
    ValueError
        A character the font lacks; boxes that overlap.
    """

    def __init__(self, boxes, dynamic=None, *, v_active, x_bits=12, y_bits=11):
        self.boxes = tuple(boxes)
        for box in self.boxes:
            char_codes(box.text)
        self.dynamic = dict(dynamic or {})
        every = list(self.boxes) + list(self.dynamic.values())
        for k, one in enumerate(every):
            for other in every[k + 1:]:
                if one.box.overlaps(other.box):
                    raise ValueError(f"text boxes {one.text!r} and {other.text!r} overlap")
        self.v_active = v_active
        layout = {name: data.ArrayLayout(CHAR_BITS, len(box.text)) for name, box in self.dynamic.items()}
        super().__init__({
            "x": In(x_bits),
            "y": In(y_bits),
            "chars": In(data.StructLayout(layout or {"none": 1})),
            "in_text": Out(1),
            "lit": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        clear = Signal()
        m.d.sync += clear.eq(self.y >= self.v_active)
        in_any_3, lit_any_4, in_any_4 = [], [], Signal()
        entries = [(box, None) for box in self.boxes]
        entries += [(box, getattr(self.chars, name)) for name, box in self.dynamic.items()]
        shared = []
        for i, (box, chars) in enumerate(entries):
            inside_3, lit_4 = self._box(m, i, box, chars, clear, shared)
            in_any_3.append(inside_3)
            if lit_4 is not None:
                lit_any_4.append(lit_4)
        if shared:
            lit_any_4.append(self._shared_glyphs(m, shared))
        m.d.sync += in_any_4.eq(_any(in_any_3))
        m.d.comb += [self.in_text.eq(in_any_4), self.lit.eq(_any(lit_any_4))]
        return m

    def _box(self, m, i, box, chars, clear, shared):
        """One box: flags (n + 1), the cell's character (n + 2), its glyph row from the ROM (n + 3), the font
        pixel (n + 4). Returns ``(inside_3, lit_4)``; a dynamic box (``chars``) appends ``(inside_2, code, row,
        column)`` (n + 2) to ``shared`` instead of reading a ROM of its own (``lit_4`` None)."""
        cw, ch = FONT_CELL
        b = box.box
        inside, eol = Signal(name=f"in_text{i}_1"), Signal(name=f"eol_text{i}_1")
        m.d.sync += [
            inside.eq((self.x >= b.x0) & (self.x < b.x1) & (self.y >= b.y0) & (self.y < b.y1)),
            eol.eq(self.x == b.x1 - 1),
        ]
        scan = RegionScanner(len(box.text) * cw, ch, box.scale, cell_width=cw)
        m.submodules[f"text_scan{i}"] = scan
        m.d.comb += [scan.active.eq(inside), scan.eol.eq(eol & inside), scan.clear.eq(clear)]
        # n + 1 -> n + 2: the cell's character code, the glyph row, the column within the cell.
        code = Signal(CHAR_BITS, name=f"char{i}_2")
        row, column = Signal(range(ch), name=f"glyph_row{i}_2"), Signal(range(cw), name=f"cell_column{i}_2")
        m.d.sync += row.eq(scan.yb)
        # The cell and the column within it from the scanner's cell counters, so no table of xb lies in front of
        # the character multiplexer.
        cell = scan.cell
        m.d.sync += column.eq(scan.column)
        if chars is None:
            with m.Switch(cell):
                for k, c in enumerate(box.text):
                    with m.Case(k):
                        m.d.sync += code.eq(char_codes(c)[0])
        else:
            m.d.sync += code.eq(chars[cell])
        inside_2 = delayed(m, inside, 1, f"in_text{i}")
        inside_3 = Signal(name=f"in_text{i}_d2")
        m.d.sync += inside_3.eq(inside_2)
        if chars is not None:
            shared.append((inside_2, code, row, column))
            return inside_3, None
        # n + 2 -> n + 3: the glyph row's bits from the font ROM.
        row_bits = Signal(cw - 1, name=f"glyph_bits{i}_3")
        m.d.sync += row_bits.eq(self._glyph_row(m, code, row, str(i)))
        column_3 = delayed(m, column, 1, f"cell_column{i}")
        # n + 3 -> n + 4: the font pixel (column cw - 1 is the blank spacing column).
        lit = Signal(name=f"lit_text{i}_4")
        m.d.sync += lit.eq(inside_3 & (column_3 < cw - 1) & row_bits.bit_select(column_3, 1))
        return inside_3, lit

    def _shared_glyphs(self, m, shared):
        """The dynamic boxes' font pixel (n + 4) from one ROM: the character, glyph row and column of the box drawn
        at n + 2 (at most one: the boxes do not overlap), an AND-OR under the boxes' flags."""
        cw, _ = FONT_CELL
        insides, codes, rows, columns = zip(*shared)
        code, row, column = (Signal.like(group[0], name=f"shared_{name}_2")
                             for group, name in ((codes, "char"), (rows, "glyph_row"), (columns, "cell_column")))
        m.d.comb += [code.eq(_any(Mux(f, c, 0) for f, c in zip(insides, codes))),
                     row.eq(_any(Mux(f, r, 0) for f, r in zip(insides, rows))),
                     column.eq(_any(Mux(f, c, 0) for f, c in zip(insides, columns)))]
        row_bits = Signal(cw - 1, name="shared_glyph_bits_3")
        m.d.sync += row_bits.eq(self._glyph_row(m, code, row, "_shared"))
        inside_2 = Signal(name="in_shared_text_2")
        m.d.comb += inside_2.eq(_any(insides))
        inside_3 = delayed(m, inside_2, 1, "in_shared_text")
        column_3 = delayed(m, column, 1, "shared_cell_column")
        lit = Signal(name="lit_shared_text_4")
        m.d.sync += lit.eq(inside_3 & (column_3 < cw - 1) & row_bits.bit_select(column_3, 1))
        return lit

    def _glyph_row(self, m, code, row, tag):
        """The ``cw - 1`` bits of glyph ``code``'s row ``row`` (bit c = column c; 0 below the glyph): an
        asynchronous ROM addressed by (code, row), every entry defined (unused codes and row 7 are 0)."""
        cw, ch = FONT_CELL
        row_bits = len(row)
        table = [0] * (2 ** (CHAR_BITS + row_bits))
        for index, c in enumerate(FONT_ORDER):
            for r in range(ch - 1):
                table[(index << row_bits) | r] = _row_value(FONT[c][r])
        rom = Memory(shape=unsigned(cw - 1), depth=len(table), init=table)
        m.submodules[f"font_rom{tag}"] = rom
        port = rom.read_port(domain="comb")
        m.d.comb += port.addr.eq(Cat(row, code))
        return port.data


def _row_value(pattern):
    """A glyph row ("#.#..") as an integer, bit c = column c (the leftmost pixel is bit 0)."""
    return int(pattern[::-1].replace("#", "1").replace(".", "0"), 2)


def _any(signals):
    out = 0
    for s in signals:
        out = out | s
    return out
