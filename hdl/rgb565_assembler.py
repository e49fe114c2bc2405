"""RGB565 byte assembler: pairs the camera's bytes into 16-bit pixels and counts columns (thesis 4.2).

The MT9D112 sends an RGB565 pixel as two bytes, one per PCLK rising edge while LV is high: the "R byte"
R[4:0] G[5:3] and the "G byte" G[2:0] B[4:0]. ``r_byte_first`` (a sensor setting, spec "Camera driver")
says which comes first; the default is the R byte first.

Inputs (sampled on each rising clock edge): ``data[8]`` and ``lv``, where ``lv`` is the line-valid already
gated by the frame (the caller drops LV outside a frame). Byte ``k`` (from 0) of an LV-high run is the first
byte of pixel ``k // 2`` when ``k`` is even and completes it when odd, so column = byte count / 2. An odd
trailing byte is dropped when LV falls.

Outputs:

* ``pixel[16]`` (R in bits 15:11, G 10:5, B 4:0), ``valid``, ``column``: a completed pixel and its column
  within the line. ``column`` saturates at ``width``: every pixel past the configured width reports
  ``width`` (so it can never wrap onto a valid column).
* ``line_end``: high for the one cycle in which LV is seen low after being high (combinational from ``lv``
  and the registered state); ``line_ok`` with it: the line had exactly ``2 * width`` bytes.

Clock domain: one (``sync``; the parent places it in a camera's PCLK domain with ``DomainRenamer``).
Latency: ``valid``/``pixel``/``column`` are registered: they appear one clock after the edge that sampled
the pixel's second byte. ``line_end``/``line_ok`` are combinational in the cycle ``lv`` is low.
"""

from amaranth import Module, Signal, unsigned
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec.sensor import SENSOR

__all__ = ["RGB565Assembler", "check_width"]


def check_width(width):
    """``ValueError`` unless ``width`` (pixels per line) is positive."""
    if width < 1:
        raise ValueError(f"width must be positive, got {width}")


class RGB565Assembler(wiring.Component):
    """Byte pairs to RGB565 pixels with their column; see the module docstring for the ports and the latency.

    Parameters
    ----------
    width : int
        Pixels per line: ``column`` saturates there.
    r_byte_first : bool
        The R byte (R[4:0] G[5:3]) comes first in each pair.

    Raises
    ------
    ValueError
        ``width`` below 1.
    """

    def __init__(self, width=SENSOR.width, *, r_byte_first=True):
        check_width(width)
        self.width = width
        self.r_byte_first = r_byte_first
        column_shape = unsigned(width.bit_length())     # 0 .. width inclusive
        super().__init__({
            "data": In(8),
            "lv": In(1),
            "pixel": Out(16),
            "valid": Out(1),
            "column": Out(column_shape),
            "line_end": Out(1),
            "line_ok": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        width = self.width

        first = Signal(8)                          # first byte of the pixel being assembled
        odd = Signal()                             # the next byte completes a pixel
        count = Signal(self.column.shape())        # pixels completed in this line, saturating at width
        overflow = Signal()                        # a pixel arrived after `width` pixels in this line
        lv_prev = Signal()

        m.d.sync += lv_prev.eq(self.lv)
        m.d.comb += [
            self.line_end.eq(lv_prev & ~self.lv),
            self.line_ok.eq(~odd & (count == width) & ~overflow),
        ]

        m.d.sync += self.valid.eq(0)
        with m.If(self.lv):
            with m.If(~odd):
                m.d.sync += [first.eq(self.data), odd.eq(1)]
            with m.Else():
                if self.r_byte_first:
                    m.d.sync += self.pixel.eq((first << 8) | self.data)
                else:
                    m.d.sync += self.pixel.eq((self.data << 8) | first)
                m.d.sync += [
                    odd.eq(0),
                    self.valid.eq(1),
                    self.column.eq(count),
                ]
                with m.If(count == width):
                    m.d.sync += overflow.eq(1)
                with m.Else():
                    m.d.sync += count.eq(count + 1)
        with m.Else():
            m.d.sync += [odd.eq(0), count.eq(0), overflow.eq(0)]
        return m
