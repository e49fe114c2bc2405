"""Averaging downscaler: each buffer pixel the 8-bit mean grey of its ``scale`` x ``scale`` sensor block, with the
frame-buffer address (docs/capture.md, "The averaging capture").

For the RGB565 fields R5, G6, B5 of each block pixel, ``g = 2 R5 + G6 + 2 B5`` (0..187); the block sum ``T`` of
``g`` over the ``s^2`` pixels (``s`` = ``scale``, 0..187 s^2) becomes

    ``grey8 = floor((510 T + 187 s^2) / (374 s^2))``,

the mean ``g`` scaled from 0..187 to 0..255 and rounded half up. The buffer pixel (x, y) is written at
``A = y * buf_width + x`` when the last pixel of its block arrives: the pixel at column ``s x + s - 1`` of sensor
row ``s y + s - 1``.

How: a horizontal accumulator sums the ``s`` pixels of a block's row (it restarts at every column that is a
multiple of ``s``); in the block's first ``s - 1`` sensor rows each row's sum is added into a line buffer of
partial block sums at ``x`` (the first row writes it, the others read, add and write back), and in its last row the
partial sum read back plus the row's sum is ``T``. The division by the constant ``374 s^2`` is a multiplication by
a constant and a shift: ``grey8 = (T * multiplier + offset) >> shift`` (:func:`rounding_reciprocal`, which finds
the constants and checks them against the formula for every ``T`` in 0..187 s^2), the multiplication written as
shift-adds (:func:`hdl.shift_add.times`), as is ``y * buf_width``: no DSP48E, no divider.

The line buffer (``amaranth.lib.memory.Memory``, one write port and one read port with a registered read, both in
this block's domain) holds ``buf_width`` words of :func:`line_sum_bits` bits: for the 800 x 600 build
(``spec.sensor.SENSOR_800``, ``s`` = 2) 800 x 9 bits = 7,200 bits, one RAMB18 in its 2K x 9 aspect ratio. ``s`` = 1
needs none.

Anything past the configured size is discarded, never wrapped: a pixel counts only when ``x = column / s <
buf_width`` and ``y = row / s < buf_height`` (the capture's column and row counters saturate at the sensor's width
and height, which lie past the buffer), so ``write.addr`` is below ``buf_depth`` whenever ``write.en`` is high,
whatever the stream. A malformed stream can only put wrong values at valid addresses: a block whose first rows
were cut short adds the line buffer's older partial sums; a block's last row cut short writes nothing for the
blocks it did not reach; a short frame leaves the blocks it did not finish unwritten (the buffer keeps the older
frame's pixels there, as with the thesis's capture).

Inputs: ``valid``, ``pixel`` (RGB565: R in bits 15:11, G 10:5, B 4:0), ``column`` and ``row`` (its sensor
position; consecutive pixels of a row have consecutive columns, as the capture's assembler gives them).
Output: the frame-buffer write port ``write`` (``grey_bits`` = 8).

``scale`` must be a power of two (shifts and masks, no divider).

Clock domain: one (``sync``; placed in a camera's PCLK domain by the parent). Latency: :data:`LATENCY` (3) clocks
from a block's last pixel on the inputs to its ``write.en`` (the pixel's grey and position registered; the line
buffer read, the sums and the address registered; the scaled grey registered on the write port).
"""

from functools import lru_cache

from amaranth import Module, Mux, Signal, unsigned
from amaranth.lib import wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from hdl.downscaler import check_geometry as check_blocks
from hdl.frame_buffer import FrameBufferWriteSignature
from hdl.shift_add import times
from spec.sensor import SENSOR_800

__all__ = ["AveragingDownscaler", "LATENCY", "PIXEL_MAX", "check_geometry", "grey8", "line_sum_bits",
           "rounding_reciprocal"]

#: Clocks from a block's last pixel on the inputs to its write on ``write``.
LATENCY = 3

#: The largest per-pixel weight sum ``g = 2 R5 + G6 + 2 B5`` (white: 2 * 31 + 63 + 2 * 31).
PIXEL_MAX = 2 * 31 + 63 + 2 * 31


def check_geometry(geometry):
    """``ValueError`` unless ``geometry`` can be averaged: 8 bits of grey, ``scale`` a power of two, the sensor at
    least one block (:func:`hdl.downscaler.check_geometry`)."""
    if geometry.grey_bits != 8:
        raise ValueError(f"the averaging capture gives 8-bit grey; geometry.grey_bits must be 8, "
                         f"not {geometry.grey_bits}")
    check_blocks(geometry)


def grey8(total, scale):
    """The formula, ``floor((510 T + 187 s^2) / (374 s^2))`` of a block sum ``total`` (plain integers), that the
    constants of :func:`rounding_reciprocal` are checked against."""
    block = scale * scale
    return (510 * total + PIXEL_MAX * block) // (2 * PIXEL_MAX * block)


@lru_cache(maxsize=None)
def rounding_reciprocal(scale):
    """``(multiplier, offset, shift)`` with ``(T * multiplier + offset) >> shift == grey8(T, scale)`` for every
    block sum ``T`` in 0..187 ``scale``^2, the smallest ``shift`` that has one (then the fewest set bits).

    For each ``shift`` and the two multipliers next to ``255 * 2**shift / (187 s^2)`` the offsets that work for
    every ``T`` form an interval, ``max(q(T) 2^shift - m T) <= offset < min((q(T) + 1) 2^shift - m T)``; the
    search computes it over all ``T``, so the constants it returns are exact by construction (for ``s`` = 2:
    ``(T * 5585 + 8522) >> 14``, 7 shifted terms).
    """
    block = scale * scale
    top = PIXEL_MAX * block
    targets = [grey8(t, scale) for t in range(top + 1)]
    for shift in range(1, 64):
        centre = (510 << shift) // (2 * PIXEL_MAX * block)
        found = []
        for multiplier in (centre, centre + 1):
            low = max(q * (1 << shift) - multiplier * t for t, q in enumerate(targets))
            high = min((q + 1) * (1 << shift) - multiplier * t for t, q in enumerate(targets))
            offset = max(low, 0)
            if offset < high:
                found.append((bin(multiplier).count("1") + bin(offset).count("1"), multiplier, offset))
        if found:
            _, multiplier, offset = min(found)
            return multiplier, offset, shift
    raise AssertionError(f"no reciprocal for scale {scale}")      # pragma: no cover (shift 64 always has one)


def line_sum_bits(scale):
    """Bits of a line-buffer word: a partial block sum of the first ``scale - 1`` rows, 0..187 s (s - 1)."""
    return max(1, (PIXEL_MAX * scale * (scale - 1)).bit_length())


class AveragingDownscaler(wiring.Component):
    """Each buffer pixel the rounded 8-bit mean grey of its sensor block, with its address; see the module
    docstring.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
        Sensor size, ``scale`` (a power of two), buffer size; ``grey_bits`` must be 8.
    column_bits, row_bits : int
        Widths of the ``column`` and ``row`` inputs (default: enough for the sensor's width and height).

    Attributes
    ----------
    valid : ``In(1)``
    pixel : ``In(16)``
    column, row : ``In(column_bits)``, ``In(row_bits)``
    write : ``Out(FrameBufferWriteSignature(geometry))``
        ``write.addr`` is below ``buf_depth`` whenever ``write.en`` is high.

    Clock domain: ``sync``. Latency: :data:`LATENCY` clocks.

    Raises
    ------
    ValueError
        ``grey_bits`` other than 8, ``scale`` not a power of two, or a sensor smaller than one block.
    """

    def __init__(self, geometry=SENSOR_800, *, column_bits=None, row_bits=None):
        check_geometry(geometry)
        self.geometry = geometry
        column_bits = column_bits or geometry.width.bit_length()
        row_bits = row_bits or geometry.height.bit_length()
        super().__init__({
            "valid": In(1),
            "pixel": In(16),
            "column": In(unsigned(column_bits)),
            "row": In(unsigned(row_bits)),
            "write": Out(FrameBufferWriteSignature(geometry)),
        })

    def elaborate(self, platform):
        m = Module()
        g = self.geometry
        s = g.scale
        shift = s.bit_length() - 1
        last = s - 1

        # Stage 0 (the inputs): the pixel's weight sum and its block, registered.
        r5, g6, b5 = self.pixel[11:16], self.pixel[5:11], self.pixel[0:5]
        x, y = self.column >> shift, self.row >> shift
        weight = Signal(range(PIXEL_MAX + 1))
        m.d.comb += weight.eq(((r5 + b5) << 1) + g6)
        inside = (x < g.buf_width) & (y < g.buf_height)

        valid_1 = Signal()
        weight_1 = Signal.like(weight)
        x_1 = Signal(range(g.buf_width))
        y_1 = Signal(range(g.buf_height))
        column_phase_1 = Signal(max(shift, 1))
        row_phase_1 = Signal(max(shift, 1))
        m.d.sync += valid_1.eq(self.valid & inside)
        with m.If(self.valid & inside):
            m.d.sync += [weight_1.eq(weight), x_1.eq(x), y_1.eq(y)]
            if shift:
                m.d.sync += [column_phase_1.eq(self.column[:shift]), row_phase_1.eq(self.row[:shift])]

        # Stage 1: the row's sum of the block so far, the line buffer's partial sum, the block's address.
        row_sum = Signal(range(PIXEL_MAX * s + 1))
        if shift:
            across = Signal(range(PIXEL_MAX * s + 1))        # the block's pixels of this row before this one
            m.d.comb += row_sum.eq(Mux(column_phase_1 == 0, 0, across) + weight_1)
            with m.If(valid_1):
                m.d.sync += across.eq(row_sum)
            block_row_done = valid_1 & (column_phase_1 == last)
            block_last_row = row_phase_1 == last
        else:
            m.d.comb += row_sum.eq(weight_1)
            block_row_done = valid_1
            block_last_row = 1

        total = Signal(range(PIXEL_MAX * s * s + 1))
        if shift:
            m.submodules.line = line = Memory(shape=line_sum_bits(s), depth=g.buf_width, init=[])
            read = line.read_port()                  # registered: the word at stage 0's x, in stage 1
            write = line.write_port()
            m.d.comb += [
                read.addr.eq(x),
                total.eq(Mux(row_phase_1 == 0, 0, read.data) + row_sum),
                write.addr.eq(x_1),
                write.data.eq(total),
                write.en.eq(block_row_done & ~block_last_row),
            ]
        else:
            m.d.comb += total.eq(row_sum)

        total_2 = Signal.like(total)
        en_2 = Signal()
        addr_2 = Signal.like(self.write.addr)
        m.d.sync += en_2.eq(block_row_done & block_last_row)
        with m.If(block_row_done & block_last_row):
            m.d.sync += [total_2.eq(total), addr_2.eq(times(y_1, g.buf_width) + x_1)]

        # Stage 2: the scaled, rounded grey onto the write port.
        multiplier, offset, scaled_shift = rounding_reciprocal(s)
        m.d.sync += self.write.en.eq(en_2)
        with m.If(en_2):
            m.d.sync += [
                self.write.addr.eq(addr_2),
                self.write.data.eq((times(total_2, multiplier) + offset) >> scaled_shift),
            ]
        return m
