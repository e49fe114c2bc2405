"""The depth engine's interface signatures and its pipeline token.

``SharedReadSignature`` is the frame buffer's read port (``hdl.frame_buffer.FrameBufferReadSignature``: ``addr``
out, ``data`` in, one clock of read latency) plus the request/grant pair with
which the engine shares that one port with another reader: the engine drives ``request`` and ``port.addr``;
in a clock where ``grant`` is high the arbiter passes ``port.addr`` to the buffer, and ``port.data`` holds that
word in the next clock. ``ResultReadSignature`` is the reader's view of the engine's output rows.
"""

from amaranth.lib import data
from amaranth.lib.wiring import In, Out

from hdl.frame_buffer import FrameBufferReadSignature
from spec.sensor import ROW_TAG_BITS, SENSOR
from hdl.signature import ParametricSignature

__all__ = ["SharedReadSignature", "ResultReadSignature", "RowTagReadSignature", "token_layout"]


class SharedReadSignature(ParametricSignature):
    """A read port shared through an arbiter: ``port`` plus ``request`` (out) and ``grant`` (in)."""

    def __init__(self, geometry=SENSOR):
        super().__init__({
            "port": Out(FrameBufferReadSignature(geometry)),
            "request": Out(1),
            "grant": In(1),
        }, geometry=geometry)


class ResultReadSignature(ParametricSignature):
    """The reader's side of the engine's ring of result rows: ``addr`` = (row mod rows) * width + x, ``data``
    (the code) one clock later; ``rows_ready`` (in) counts the rows of the current map in the ring,
    ``rows_released`` (out) the rows the reader no longer needs."""

    def __init__(self, addr_bits, code_bits, height):
        super().__init__({
            "addr": Out(addr_bits),
            "data": In(code_bits),
            "rows_ready": In(range(height + 1)),
            "rows_released": Out(range(height + 1)),
        }, addr_bits=addr_bits, code_bits=code_bits, height=height)


class RowTagReadSignature(ParametricSignature):
    """The reader's side of a frame buffer's row tags (docs/capture.md, "Consistency at the tear"): ``row`` (out)
    a buffer row 0..height-1; in the next clock ``tag`` (in) is the frame tag of the camera frame that last
    started writing that row (frame count mod 2**bits) and ``busy`` (in) says that the capture is writing that row
    now (or may be: the tag is not to be trusted). Both are 0 from a source that tracks nothing."""

    def __init__(self, height, bits=ROW_TAG_BITS):
        super().__init__({
            "row": Out(range(height)),
            "tag": In(bits),
            "busy": In(1),
        }, height=height, bits=bits)


def token_layout(groups, width):
    """The control token that travels with a group of disparities through the cost, path and winner stages:
    ``go`` (a group is in this stage), ``group`` (0..groups-1), ``last`` (the pixel's last group), ``first``
    (x = 0: the horizontal path starts), ``x`` (the right-image column, 0..width-1)."""
    return data.StructLayout({
        "go": 1,
        "group": range(groups),
        "last": 1,
        "first": 1,
        "x": range(width),
    })
