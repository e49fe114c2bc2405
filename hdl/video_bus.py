"""Signatures shared by the display-side blocks (all in the pixel-clock domain).

* :data:`TimingSignature` is what the sync generator drives: where the raster is (``x``, ``y``, counting
  through blanking too), whether the pixel is active (``de``) and the sync pulses at their final polarity.
* :data:`VideoSignature` is a pixel stream ready for the transmitter: ``rgb`` is R[23:16] G[15:8] B[7:0],
  valid while ``de`` is high, with ``hsync``/``vsync`` aligned to it.
"""

from amaranth.lib import wiring
from amaranth.lib.wiring import Out

__all__ = ["X_BITS", "Y_BITS", "TimingSignature", "VideoSignature"]

X_BITS = 12   # enough for h_total = 2200
Y_BITS = 11   # enough for v_total = 1125

TimingSignature = wiring.Signature({
    "x": Out(X_BITS),
    "y": Out(Y_BITS),
    "de": Out(1),
    "hsync": Out(1),
    "vsync": Out(1),
    "frame_start": Out(1),   # one-cycle strobe at x == 0, y == 0
})

VideoSignature = wiring.Signature({
    "rgb": Out(24),
    "de": Out(1),
    "hsync": Out(1),
    "vsync": Out(1),
})
