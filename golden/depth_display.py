"""Golden model of the depth panel and its overlays (docs/display.md, "Four panels"), written from the spec.

* :func:`depth_colours`: the colour of every code 0..2**F D (2**F D = invalid): the viridis anchors of
  ``spec.display.DEPTH_COLOURS`` interpolated linearly at u = min((n - 1) c / (2**F (D - 1)), n - 1), each
  channel rounded half up (exact integer arithmetic); the invalid code is ``DEPTH_INVALID_RGB``. The colour bar
  shows whole disparity d in the colour of code 2**F d.
* :func:`engine_left`: the left image as the engine reads it with the signed rectification r: row y is
  row min(max(y + r, 0), H - 1) (the first row repeats above the image, the last below it).
* :func:`centre_readout`: the median of the 3 x 3 codes around (W // 2, H // 2) and its readout text: the
  distance B f / (d p s) of the sub-pixel disparity d = code / 2**F in whole centimetres (half up),
  right-aligned in 4 characters, then "cm"; "----cm" for code 0, the invalid code, or a distance above 9999 cm.
* :func:`depth_picture`: the map in colour at buffer size with the crosshair (centre row and column, 2 ..
  ``arm`` pixels from the centre, ``CROSSHAIR_RGB``).
* :func:`draw_text`: a text box in the 5 x 7 font (glyph pixels ``TEXT_RGB``, the rest ``BACKGROUND_RGB``).
* :func:`draw_depth_display`: everything of the depth display on a frame of 0xRRGGBB values.

Only constants come from ``spec``; nothing is taken from the RTL.
"""

import numpy as np

from spec.depth import DEPTH
from spec.display import BACKGROUND_RGB, CROSSHAIR_RGB, DEPTH_COLOURS, DEPTH_INVALID_RGB, TEXT_RGB
from spec.font import FONT, FONT_CELL
from spec.sensor import SENSOR, VMODCAM_RIG

__all__ = ["depth_colours", "engine_left", "centre_readout", "depth_picture", "draw_text", "draw_depth_display",
           "distance_m"]


def depth_colours(config=DEPTH):
    """(2**F D + 1,) int64 0xRRGGBB: the colour of each code 0..2**F D; the last is the invalid colour."""
    anchors = np.asarray(DEPTH_COLOURS, dtype=np.int64)
    n = len(anchors)
    den = config.fraction * (config.disparities - 1)            # u = num / den
    num = np.minimum((n - 1) * np.arange(config.invalid, dtype=np.int64), (n - 1) * den)
    seg = np.minimum(num // den, n - 2)                          # the anchors seg, seg + 1 around u
    rest = num - seg * den                                       # u - seg = rest / den, 0 <= rest <= den
    lo, hi = anchors[seg], anchors[seg + 1]
    # round half up: floor(lo + (hi - lo) rest / den + 1/2) = floor((2 den lo + 2 (hi - lo) rest + den) / (2 den))
    channels = (2 * den * lo + 2 * (hi - lo) * rest[:, None] + den) // (2 * den)
    rgb = (channels[:, 0] << 16) | (channels[:, 1] << 8) | channels[:, 2]
    return np.append(rgb, DEPTH_INVALID_RGB)


def engine_left(left, rectification):
    """The left buffer with its rows moved up by ``rectification`` rows (signed; the first row repeats above the
    image, the last below it)."""
    left = np.asarray(left)
    rows = np.clip(np.arange(left.shape[0]) + int(rectification), 0, left.shape[0] - 1)
    return left[rows]


def distance_m(disparity, geometry=SENSOR):
    """Z = B f / (d p s) in metres for buffer disparities ``disparity`` (> 0)."""
    return VMODCAM_RIG.BASELINE_M * VMODCAM_RIG.FOCAL_M / (
        np.asarray(disparity, dtype=np.float64) * VMODCAM_RIG.PIXEL_M * geometry.scale)


def centre_readout(codes, geometry=SENSOR, config=DEPTH):
    """(median code, readout text) of the 3 x 3 window at the map's centre."""
    codes = np.asarray(codes)
    h, w = codes.shape
    yc, xc = h // 2, w // 2
    median = int(np.sort(codes[yc - 1:yc + 2, xc - 1:xc + 2], axis=None)[4])
    if median == 0 or median >= config.invalid:
        return median, "----cm"
    cm = int(np.floor(distance_m(median / config.fraction, geometry) * 100 + 0.5))
    if cm > 9999:
        return median, "----cm"
    return median, f"{cm:4d}cm"


def depth_picture(codes, config=DEPTH, arm=0):
    """(H, W) int64 0xRRGGBB: the codes' colours with the crosshair drawn over them."""
    codes = np.asarray(codes)
    picture = depth_colours(config)[codes]
    h, w = codes.shape
    yc, xc = h // 2, w // 2
    for offset in range(2, arm + 1):
        for dy, dx in ((0, -offset), (0, offset), (-offset, 0), (offset, 0)):
            picture[yc + dy, xc + dx] = CROSSHAIR_RGB
    return picture


def draw_text(frame, box, text):
    """Draw ``text`` in the font at ``box`` (a ``spec.layout.TextBox``: x0, y0, scale) onto ``frame``."""
    cw, ch = FONT_CELL
    cells = np.zeros((ch, cw * len(text)), dtype=bool)
    for i, char in enumerate(text):
        glyph = np.array([[p == "#" for p in row] for row in FONT[char]], dtype=bool)
        cells[:glyph.shape[0], i * cw:i * cw + glyph.shape[1]] = glyph
    s = box.scale
    lit = np.repeat(np.repeat(cells, s, axis=0), s, axis=1)
    area = frame[box.y0:box.y0 + lit.shape[0], box.x0:box.x0 + lit.shape[1]]
    area[...] = np.where(lit, TEXT_RGB, BACKGROUND_RGB)


def draw_depth_display(frame, codes, layout, geometry=SENSOR, config=DEPTH):
    """The depth panel, colour bar, ticks, labels and readout of ``layout`` drawn onto ``frame`` (int 0xRRGGBB,
    the active area); returns the readout text."""
    region = layout.region("depth")
    s = region.scale
    picture = depth_picture(codes, config, layout.crosshair_arm)
    frame[region.y0:region.y1, region.x0:region.x1] = np.repeat(np.repeat(picture, s, axis=0), s, axis=1)
    bar = layout.bar
    colours = depth_colours(config)
    for d in range(bar.codes):                                   # whole disparities: code 2**F d
        top = bar.y0 + (bar.codes - 1 - d) * bar.step
        frame[top:top + bar.step, bar.x0:bar.x0 + bar.width] = colours[d << config.fraction_bits]
    for tick in layout.ticks:
        frame[tick.y0:tick.y1, tick.x0:tick.x1] = TEXT_RGB
    for label in layout.labels:
        draw_text(frame, label, label.text)
    _, text = centre_readout(codes, geometry, config)
    draw_text(frame, layout.readout, text)
    return text
