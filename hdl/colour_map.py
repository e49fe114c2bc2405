"""The depth colour map ROM's contents (docs/display.md, "Depth panel")."""

from fractions import Fraction

from spec.depth import DEPTH
from spec.display import DEPTH_COLOURS, DEPTH_INVALID_RGB

__all__ = ["colour_table"]


def colour_table(config=DEPTH):
    """24-bit RGB (R in bits 23:16) of every code 0..D: disparity d at u = (n - 1) d / (D - 1) along the
    ``n`` anchors of :data:`spec.display.DEPTH_COLOURS`, linear between the two anchors around it, each channel
    rounded half up (exact fractions); the invalid code D is ``DEPTH_INVALID_RGB``."""
    anchors, top = DEPTH_COLOURS, config.disparities - 1
    table = []
    for d in range(config.disparities):
        u = Fraction((len(anchors) - 1) * d, top)
        i = min(int(u), len(anchors) - 2)
        f = u - i
        rgb = 0
        for a, b in zip(anchors[i], anchors[i + 1]):
            rgb = (rgb << 8) | int(a + f * (b - a) + Fraction(1, 2))
        table.append(rgb)
    return table + [DEPTH_INVALID_RGB]
