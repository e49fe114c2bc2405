"""The disparity subtractor with two preloaded frame buffers, for Amaranth's simulator: the testbench the
subtractor's tests and the test bed's RTL cross-check (``sim/testbed/experiment.py``) both drive."""

from amaranth import Module
from amaranth.lib import wiring

from hdl.disparity import DisparitySubtractor
from hdl.frame_buffer import FrameBuffer

__all__ = ["subtractor_testbench", "set_pixel"]


def subtractor_testbench(geometry, thresholds, left_words, right_words):
    """``(module, subtractor)``: a :class:`hdl.disparity.DisparitySubtractor` whose ``left``/``right`` read ports
    are connected to :class:`hdl.frame_buffer.FrameBuffer` s initialised with ``left_words``/``right_words``
    (raster order; the rest 0). Everything in ``sync``."""
    m = Module()
    m.submodules.sub = sub = DisparitySubtractor(geometry, thresholds)
    m.submodules.left = left = FrameBuffer(geometry, init=list(left_words))
    m.submodules.right = right = FrameBuffer(geometry, init=list(right_words))
    wiring.connect(m, sub.left, left.read)
    wiring.connect(m, sub.right, right.read)
    return m, sub


def set_pixel(ctx, sub, pixel, width):
    """Present ``pixel`` (``(x, y)``, or None for an idle clock) at the subtractor's inputs. An idle clock carries
    junk coordinates (the last column of row 0), which must not matter."""
    if pixel is None:
        ctx.set(sub.valid, 0)
        x, y = width - 1, 0
    else:
        ctx.set(sub.valid, 1)
        x, y = pixel
    ctx.set(sub.x, x)
    ctx.set(sub.y, y)
    ctx.set(sub.addr, y * width + x)
