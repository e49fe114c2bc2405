"""What the screen shows: grey and difference-map levels (thesis 4.3; spec "Disparity map generator"), the depth
panel's colours, labels, crosshair and readout (docs/display.md, "Four panels")."""

__all__ = [
    "DIFF_THRESHOLDS", "diff_thresholds", "DIFF_LEVEL_GREY", "NO_DATA_RGB", "BACKGROUND_RGB", "grey_to_rgb24",
    "DEPTH_COLOURS", "DEPTH_INVALID_RGB", "DEPTH_NOT_READY_RGB", "CROSSHAIR_RGB", "TEXT_RGB", "DEPTH_LABELS_M",
    "CROSSHAIR_ARM", "READOUT_TEXT", "SEGMENT_HALF_WIDTH", "SEGMENT_DIM_SHIFT", "SEGMENT_INVALID_RGB",
    "SEGMENT_TEXT", "RECTIFICATION_MODES", "RECTIFICATION_TEXT",
]


#: |L - R| (0..31 for 5-bit grey) is quantised to a display level: level = number of thresholds t with
#: |L - R| >= t. Differences below the first threshold are sensor noise and show black, so a matched
#: object "disappears" (thesis 4.6). Default: 5 levels.
DIFF_THRESHOLDS = (2, 4, 8, 16)


def diff_thresholds(grey_bits):
    """The threshold table for ``grey_bits`` (>= 5) of grey: :data:`DIFF_THRESHOLDS` (5-bit) times
    2**(grey_bits - 5), the same steps of brightness (8-bit grey: 16, 32, 64, 128)."""
    if grey_bits < 5:
        raise ValueError(f"the difference thresholds need at least 5 bits of grey, not {grey_bits}")
    return tuple(t << (grey_bits - 5) for t in DIFF_THRESHOLDS)

#: The 8-bit grey shown for each level (len(DIFF_THRESHOLDS) + 1 entries).
DIFF_LEVEL_GREY = (0, 64, 128, 192, 255)
#: Colour of disparity pixels whose shifted left read falls outside the 400 x 300 image ("no data").
NO_DATA_RGB = 0x2040C0
#: Colour of the screen outside the images (and of a text box's unlit pixels).
BACKGROUND_RGB = 0x303030


def grey_to_rgb24(grey, grey_bits=5):
    """The 24-bit RGB (R in bits 23:16) shown for a ``grey_bits`` grey value: bit replication to 8 bits."""
    g8 = (grey << (8 - grey_bits)) | (grey >> (2 * grey_bits - 8)) if grey_bits < 8 else grey
    return (g8 << 16) | (g8 << 8) | g8


#: piecewise-linear colour at u = 8 d / (D - 1), each channel rounded to nearest (docs/display.md).
DEPTH_COLOURS = (
    (68, 1, 84), (71, 45, 123), (59, 82, 139), (44, 114, 142), (33, 145, 140),
    (40, 174, 128), (94, 201, 98), (173, 220, 48), (253, 231, 37),
)
#: Colour of an invalid depth pixel (code D).
DEPTH_INVALID_RGB = 0x000000
#: Colour of a depth row the engine has not finished when the display reaches it (never in a working system).
DEPTH_NOT_READY_RGB = NO_DATA_RGB
#: Crosshair, tick marks and text.
CROSSHAIR_RGB = 0xFFFFFF
TEXT_RGB = 0xFFFFFF
#: Distances (metres) marked on the colour bar (each where its disparity lies inside 0 < d < D).
DEPTH_LABELS_M = (0.5, 1, 2, 3, 5)
#: Buffer pixels of each crosshair arm; the arms leave the 3 x 3 window the distance is measured in free.
CROSSHAIR_ARM = 8
#: The centre distance readout: four digits (centimetres, leading zeros blank; "----" when invalid) and "cm".
READOUT_TEXT = "0000cm"

#: Depth-keyed segmentation (docs/display.md, "Segmentation"): a depth pixel is inside the band when its sub-pixel
#: disparity is within SEGMENT_HALF_WIDTH pixels of the disparity register (|code / 2**F - d| <= half width).
SEGMENT_HALF_WIDTH = 2
#: Outside the band each channel of the 8-bit grey is shifted right by this many bits (a quarter of its value).
SEGMENT_DIM_SHIFT = 2
#: Bits OR-ed into a dimmed invalid depth pixel (bit 7 of blue: a dark blue tint).
SEGMENT_INVALID_RGB = 0x000080
#: The band's text: its near and far distance in metres (two decimals; "--.--" for no finite distance), then "m".
SEGMENT_TEXT = "00.00-00.00m"

#: The rectification in use on screen (docs/display.md, "Rectification text"): "rect", the signed offset in
#: buffer rows as Python's ``f"{r:+3d}"`` ("+3", "-12", "+0", sign next to the digits), then the mode word.
RECTIFICATION_TEXT = "rect +00 auto"
#: The mode words, in this order: by hand (the switches' value), automatic (the estimator's offset; its last search
#: had a clear minimum), held (automatic, the last search had none: the offset before it is kept).
RECTIFICATION_MODES = ("hand", "auto", "held")
