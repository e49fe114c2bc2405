"""1/``scale``^2 downscaler with the frame-buffer address (thesis figure 4.4 and equation 4.1).

Keeps the pixel at (``scale*i``, ``scale*j``) of every ``scale`` x ``scale`` block and turns its sensor
position into the frame-buffer address ``A = y * buf_width + x`` with ``x = column / scale``,
``y = row / scale``. A pixel is written only when its column and row are multiples of ``scale`` and
``x < buf_width`` and ``y < buf_height``: anything past the configured size is discarded, never wrapped,
so ``write.addr`` is always below ``buf_depth`` whenever ``write.en`` is high.

Inputs: ``valid``, ``grey`` (the pixel's grey value), ``column`` and ``row`` (its sensor position).
Output: the frame-buffer write port ``write``.

``scale`` must be a power of two (the default 4 is), so the block needs no divider. ``y * buf_width`` is a
constant multiplication, written as shift-adds (:func:`hdl.shift_add.times`), no DSP48E.

Clock domain: one (``sync``; placed in a camera's PCLK domain by the parent). Latency: one clock (the write
port is registered).
"""

from amaranth import Module, unsigned
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.frame_buffer import FrameBufferWriteSignature
from hdl.shift_add import times
from spec.sensor import SENSOR

__all__ = ["Downscaler", "check_geometry"]


def check_geometry(geometry):
    """``ValueError`` unless ``geometry`` can be downscaled: ``scale`` a power of two, the sensor at least one
    ``scale`` x ``scale`` block."""
    scale = geometry.scale
    if scale < 1 or scale & (scale - 1):
        raise ValueError(f"scale must be a power of two, got {scale}")
    if geometry.buf_width < 1 or geometry.buf_height < 1:
        raise ValueError(f"sensor {geometry.width}x{geometry.height} is smaller than one {scale}x{scale} "
                         f"block")


class Downscaler(wiring.Component):
    """Keeps one pixel of each ``scale`` x ``scale`` block and addresses it in the buffer; see the module docstring.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
        Sensor size, ``scale`` (a power of two) and buffer size.
    column_bits, row_bits : int
        Widths of the ``column`` and ``row`` inputs (default: enough for the sensor's width and height).

    Attributes
    ----------
    write : ``Out(FrameBufferWriteSignature(geometry))``
        ``write.addr`` is below ``buf_depth`` whenever ``write.en`` is high.

    Raises
    ------
    ValueError
        ``scale`` not a power of two, or a sensor smaller than one block.
    """

    def __init__(self, geometry=SENSOR, *, column_bits=None, row_bits=None):
        check_geometry(geometry)
        self.geometry = geometry
        column_bits = column_bits or geometry.width.bit_length()
        row_bits = row_bits or geometry.height.bit_length()
        super().__init__({
            "valid": In(1),
            "grey": In(geometry.grey_bits),
            "column": In(unsigned(column_bits)),
            "row": In(unsigned(row_bits)),
            "write": Out(FrameBufferWriteSignature(geometry)),
        })

    def elaborate(self, platform):
        m = Module()
        g = self.geometry
        shift = g.scale.bit_length() - 1
        x = self.column >> shift
        y = self.row >> shift
        aligned = (self.column[:shift] == 0) & (self.row[:shift] == 0) if shift else 1
        keep = self.valid & aligned & (x < g.buf_width) & (y < g.buf_height)

        m.d.sync += self.write.en.eq(keep)
        with m.If(keep):
            m.d.sync += [
                self.write.addr.eq(times(y, g.buf_width) + x),
                self.write.data.eq(self.grey),
            ]
        return m
