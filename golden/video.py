"""Golden model of the display path's test pattern, written from the pattern's definition (not from the RTL).

The test pattern (the same definition is stated in ``hdl/pattern_gen.py``), for the active area
``W = timing.h_active`` x ``H = timing.v_active``, pixel column ``x`` in [0, W), row ``y`` in [0, H):

* Colour bars in the top ``B = (2 * H) // 3`` rows (``y < B``): eight vertical bars of equal width,
  bar ``i = (8 * x) // W``; with ``c = 7 - i``: green = 255 if bit 2 of ``c`` else 0, red = 255 if bit 1,
  blue = 255 if bit 0. Left to right: white, yellow, cyan, green, magenta, red, blue, black.
* Gradient in the remaining rows (``y >= B``): red = ``(256 * x) // W`` (a left-to-right ramp),
  green = ``(256 * (y - B)) // (H - B)`` (a top-to-bottom ramp), blue = ``(x + y) mod 256`` (a diagonal
  sawtooth that changes at every pixel, so a one-pixel shift or a swapped bit is visible everywhere).

All divisions are floor divisions of non-negative integers. 24-bit RGB is R[23:16] G[15:8] B[7:0]; the frame
is returned as ``uint8`` ``(H, W, 3)`` in R, G, B order. The pattern needs ``W >= 8`` and ``H >= 2``.
"""

import numpy as np

__all__ = ["pattern_frame"]

#: (R, G, B) of the eight bars, left to right.
BAR_COLOURS = (
    (255, 255, 255),  # white
    (255, 255, 0),    # yellow
    (0, 255, 255),    # cyan
    (0, 255, 0),      # green
    (255, 0, 255),    # magenta
    (255, 0, 0),      # red
    (0, 0, 255),      # blue
    (0, 0, 0),        # black
)


def pattern_bar_rows(timing):
    """Number of colour-bar rows at the top of the active area."""
    return (2 * timing.v_active) // 3


def pattern_frame(timing):
    """The expected active area of the test pattern for ``timing``: ``uint8`` array ``(v_active, h_active, 3)``."""
    w, h = timing.h_active, timing.v_active
    if w < 8 or h < 2:
        raise ValueError(f"the test pattern needs at least 8 x 2 active pixels, got {w} x {h}")
    bar_rows = pattern_bar_rows(timing)
    x = np.arange(w, dtype=np.int64)[np.newaxis, :]
    y = np.arange(h, dtype=np.int64)[:, np.newaxis]

    frame = np.zeros((h, w, 3), dtype=np.uint8)
    bars = np.array(BAR_COLOURS, dtype=np.uint8)[(8 * x[0]) // w]          # (w, 3)
    frame[:bar_rows] = bars[np.newaxis, :, :]

    gy = y[bar_rows:]                                                         # rows of the gradient
    frame[bar_rows:, :, 0] = np.broadcast_to((256 * x) // w, (h - bar_rows, w))
    frame[bar_rows:, :, 1] = np.broadcast_to((256 * (gy - bar_rows)) // (h - bar_rows), (h - bar_rows, w))
    frame[bar_rows:, :, 2] = (x + gy) % 256
    return frame
