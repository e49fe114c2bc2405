"""Golden model of the camera capture path, written from docs/capture.md, never from the RTL.

Two levels:

* **Image level** -- :func:`capture_frame`: what a well-formed frame leaves in a frame buffer. RGB 8:8:8 is
  packed to RGB565 by truncation (:func:`rgb888_to_rgb565`), the pixel at (``scale*i``, ``scale*j``) of every
  ``scale`` x ``scale`` block is kept (:func:`downscale`), and converted to grey with
  ``grey5 = (R5 + (G6 >> 1) + B5) // 3`` (:func:`grey5`), exact integer division. With
  ``geometry.downscale == "average"`` (the 800 x 600 build, docs/capture.md "The averaging capture") the buffer
  pixel is instead the mean of the whole block, 8-bit: ``T`` = the sum of ``2 R5 + G6 + 2 B5`` over the block,
  ``grey8 = floor((510 T + 187 s^2) / (374 s^2))`` (:func:`average_downscale`, :func:`grey8_of_sum`), rounded half
  up.
* **Stream level** -- :func:`capture_stream`: the spec's counting rules applied sample by sample to a
  camera's (FV, LV, D[7:0]) samples, one per PCLK rising edge, malformed streams included. It returns every
  frame-buffer write in order (address, grey), the status of every frame, and the resulting buffer. The RTL's
  write port must produce exactly this write sequence.

The counting rules (docs/capture.md "Counting rules"):

1. Before the first sample FV counts as high, so a frame already in progress at reset is ignored.
2. A frame starts at a FV rising edge (a sample with FV = 1 after one with FV = 0) and ends at the first
   sample with FV = 0. Outside a frame every sample is ignored (LV without FV is ignored).
3. Inside a frame, LV = 1 samples are bytes. Byte ``k`` (from 0) of an LV-high run is the first byte of
   pixel ``k // 2`` when ``k`` is even and completes it when odd: column = byte count / 2. An odd trailing
   byte is dropped.
4. The row is the number of LV falling edges since the frame started (an LV-high run cut by the end of the
   frame also ends there).
5. A pixel at (column, row) is written iff column and row are multiples of ``scale`` and
   ``x = column / scale < buf_width`` and ``y = row / scale < buf_height``; it goes to ``A = y * buf_width + x``.
   Pixels beyond the configured size are discarded, never wrapped.
6. A frame is "ok" iff it had exactly ``height`` lines of exactly ``2 * width`` bytes each.
7. A *kept* row is a row ``r`` with ``r % scale == 0`` and ``r // scale < buf_height``: buffer row ``r // scale``.
   Its LV-high run *starts* at its first byte and *ends* at the first sample after it with LV (gated by the frame)
   low, the end of the frame included; these are the capture's ``row_start`` / ``row_end`` events.
"""

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

__all__ = [
    "rgb888_to_rgb565", "rgb565_to_bytes", "grey5", "to_rgb565", "downscale", "grey8_of_sum", "average_downscale",
    "capture_frame", "assemble_line",
    "FrameStatus", "StreamCapture", "capture_stream"
]


# --- Per-pixel helpers -------------------------------------------------------------------------------------

def rgb888_to_rgb565(rgb):
    """RGB 8:8:8 (``(..., 3)`` uint8) -> RGB565 words (uint16, R in bits 15:11, G 10:5, B 4:0), by truncation:
    R5 = R8 >> 3, G6 = G8 >> 2, B5 = B8 >> 3."""
    rgb = np.asarray(rgb)
    if rgb.shape[-1:] != (3,):
        raise ValueError(f"expected an RGB array with a last axis of 3, got shape {rgb.shape}")
    rgb = rgb.astype(np.uint16)
    return ((rgb[..., 0] >> 3) << 11) | ((rgb[..., 1] >> 2) << 5) | (rgb[..., 2] >> 3)


def rgb565_fields(word):
    """(R5, G6, B5) of RGB565 words (ints or arrays)."""
    word = np.asarray(word).astype(np.uint32) if not isinstance(word, int) else word
    return (word >> 11) & 0x1F, (word >> 5) & 0x3F, word & 0x1F


def rgb565_to_bytes(word, r_byte_first=True):
    """The two bus bytes of an RGB565 word in transmission order.

    The R byte is R[4:0] G[5:3] (the word's high byte), the G byte is G[2:0] B[4:0] (the low byte)."""
    r_byte, g_byte = (word >> 8) & 0xFF, word & 0xFF
    return (r_byte, g_byte) if r_byte_first else (g_byte, r_byte)


def bytes_to_rgb565(first, second, r_byte_first=True):
    """Inverse of :func:`rgb565_to_bytes`."""
    return ((first << 8) | second) if r_byte_first else ((second << 8) | first)


def grey5(word):
    """``(R5 + (G6 >> 1) + B5) // 3`` of RGB565 words: exact integer division, 0..31 (spec "Grey")."""
    r, g, b = rgb565_fields(word)
    result = (r + (g >> 1) + b) // 3
    return result if isinstance(result, int) else np.asarray(result, dtype=np.uint8)


def to_rgb565(image):
    """An image as RGB565 words: a ``(H, W)`` uint16 array is taken as RGB565 already, a ``(H, W, 3)`` uint8
    array is packed by truncation; a path is read by :func:`golden.image_file.read_image`."""
    if isinstance(image, (str, Path)):
        from .image_file import read_image
        image = read_image(image)
    image = np.asarray(image)
    if image.ndim == 2 and image.dtype == np.uint16:
        return image
    if image.ndim == 3 and image.shape[2] == 3 and image.dtype == np.uint8:
        return rgb888_to_rgb565(image)
    raise ValueError(f"expected an (H, W, 3) uint8 RGB image or an (H, W) uint16 RGB565 image, "
                     f"got {image.dtype} {image.shape}")


def downscale(array, geometry):
    """Keep the pixel at (``scale*i``, ``scale*j``) of every block (thesis figure 4.4): a
    ``(buf_height, buf_width)`` array from a ``(height, width)`` one."""
    array = np.asarray(array)
    if array.shape[:2] != (geometry.height, geometry.width):
        raise ValueError(f"image is {array.shape[1]}x{array.shape[0]}, sensor is "
                         f"{geometry.width}x{geometry.height}")
    s = geometry.scale
    return array[::s, ::s][:geometry.buf_height, :geometry.buf_width]


def grey8_of_sum(total, scale):
    """The averaging capture's 8-bit grey of a block sum ``total`` = the sum of ``2 R5 + G6 + 2 B5`` over a
    ``scale`` x ``scale`` block: ``floor((510 T + 187 s^2) / (374 s^2))``, i.e. 255 T / (187 s^2) (the block's
    mean grey, 0..187 per pixel, scaled to 0..255) rounded half up (docs/capture.md, "The averaging capture")."""
    total = np.asarray(total).astype(np.int64)
    block = scale * scale
    if total.size and (total.min() < 0 or total.max() > 187 * block):
        raise ValueError(f"a {scale} x {scale} block sum lies in 0..{187 * block}")
    return ((510 * total + 187 * block) // (374 * block)).astype(np.uint8)


def average_downscale(words, geometry):
    """The averaging capture of RGB565 ``words`` (``(height, width)``): each buffer pixel the 8-bit mean grey of
    its ``scale`` x ``scale`` block (:func:`grey8_of_sum`); ``(buf_height, buf_width)`` uint8."""
    words = np.asarray(words)
    if words.shape[:2] != (geometry.height, geometry.width):
        raise ValueError(f"image is {words.shape[1]}x{words.shape[0]}, sensor is "
                         f"{geometry.width}x{geometry.height}")
    s, bh, bw = geometry.scale, geometry.buf_height, geometry.buf_width
    r, g, b = rgb565_fields(words[:s * bh, :s * bw])
    per_pixel = 2 * r.astype(np.int64) + g + 2 * b
    total = per_pixel.reshape(bh, s, bw, s).sum(axis=(1, 3))
    return grey8_of_sum(total, s)


def capture_frame(image, geometry):
    """What one well-formed frame of ``image`` leaves in a frame buffer: uint8 ``(buf_height, buf_width)``
    grey values of ``geometry.grey_bits`` bits: 5 for the thesis's capture (``downscale = "keep"``), 8 for the
    averaging one (``downscale = "average"``)."""
    if geometry.downscale == "average":
        if geometry.grey_bits != 8:
            raise ValueError("the averaging capture gives 8-bit grey; geometry.grey_bits must be 8")
        return average_downscale(to_rgb565(image), geometry)
    if geometry.grey_bits != 5:
        raise ValueError("the spec's grey conversion gives 5 bits; geometry.grey_bits must be 5")
    return grey5(downscale(to_rgb565(image), geometry)).astype(np.uint8)


def assemble_line(line_bytes, r_byte_first=True):
    """The RGB565 pixels of one LV-high run of bytes (rule 3): pairs in order, an odd trailing byte dropped."""
    line_bytes = list(line_bytes)
    return [bytes_to_rgb565(line_bytes[i], line_bytes[i + 1], r_byte_first)
            for i in range(0, len(line_bytes) - 1, 2)]


# --- Stream level ------------------------------------------------------------------------------------------

@dataclass
class FrameStatus:
    """One frame: where it started/ended (sample indices), its line count, whether it was well formed."""
    start: int
    end: int
    lines: int
    ok: bool


@dataclass
class StreamCapture:
    writes: list = field(default_factory=list)     # (sample index, address, grey) in order
    frames: list = field(default_factory=list)     # FrameStatus of every completed frame
    rows: list = field(default_factory=list)       # ("start" | "end", sample index, buffer row) in order (rule 7)
    buffer: np.ndarray = None                      # the frame buffer after the stream


def capture_stream(fv, lv, data, geometry, *, r_byte_first=True, initial=None):
    """Apply the counting rules (module docstring) to per-PCLK samples ``fv``, ``lv``, ``data``.

    ``initial`` is the buffer before the stream (zeros by default, the power-up content). Returns a
    :class:`StreamCapture`; ``writes`` holds ``(i, address, grey)`` where ``i`` is the index of the sample
    carrying the pixel's second byte; ``rows`` the kept rows' start and end events (rule 7) with the index of the
    run's first sample and of the sample that ends it.
    """
    fv = np.asarray(fv, dtype=np.uint8).tolist()
    lv = np.asarray(lv, dtype=np.uint8).tolist()
    data = np.asarray(data, dtype=np.uint8).tolist()
    if not len(fv) == len(lv) == len(data):
        raise ValueError("fv, lv and data must have the same length")
    if geometry.downscale != "keep":
        raise ValueError("the stream-level rules are the thesis's capture (downscale 'keep'); the averaging "
                         "capture is defined at the image level only (capture_frame)")
    s = geometry.scale
    bw, bh = geometry.buf_width, geometry.buf_height
    line_len = 2 * geometry.width
    buffer = (np.zeros(geometry.buf_depth, dtype=np.uint8) if initial is None
              else np.array(initial, dtype=np.uint8).reshape(-1).copy())
    result = StreamCapture()

    fv_prev = 1                  # rule 1
    in_frame = False
    lv_prev = 0                  # gated LV of the previous sample
    row = 0
    nbytes = 0                   # bytes of the current LV-high run
    first = 0
    bad = False
    start = 0
    for i in range(len(fv)):
        f = fv[i]
        if f and not fv_prev:                        # rule 2: frame start
            in_frame, row, bad, start = True, 0, False, i
        lv_now = 1 if (in_frame and f and lv[i]) else 0
        if lv_prev and not lv_now:                   # rule 4: a line ends
            if row % s == 0 and row // s < bh:       # rule 7
                result.rows.append(("end", i, row // s))
            if nbytes != line_len:
                bad = True
            row += 1
            nbytes = 0
        if in_frame and not f:                       # rule 2: frame end
            result.frames.append(FrameStatus(start, i, row, ok=(not bad and row == geometry.height)))
            in_frame = False
        if lv_now and not lv_prev and row % s == 0 and row // s < bh:     # rule 7
            result.rows.append(("start", i, row // s))
        if lv_now:                                   # rule 3
            if nbytes % 2 == 0:
                first = data[i]
            else:
                column = nbytes // 2
                word = bytes_to_rgb565(first, data[i], r_byte_first)
                if column % s == 0 and row % s == 0 and column // s < bw and row // s < bh:   # rule 5
                    addr = (row // s) * bw + column // s
                    value = grey5(word)
                    buffer[addr] = value
                    result.writes.append((i, addr, value))
            nbytes += 1
        fv_prev, lv_prev = f, lv_now
    result.buffer = buffer.reshape(bh, bw)
    return result
