"""The one image-file reader: every command and model that takes an image file reads it here.

An image file becomes an ``(H, W, 3)`` uint8 RGB array:

==============================  ==================================================================================
Pillow mode (what the file is)  becomes
==============================  ==================================================================================
``L`` (8-bit grey), ``1``       the grey value in R, G and B (``1``: 0 or 255)
``I;16``, ``I;16B``, ...        16-bit grey scaled to 8 bits, ``round(v * 255 / 65535)`` (not clipped)
``RGB``                         as it is (Pillow reads a 16-bit-per-channel RGB PNG as its high bytes)
``P`` (palette)                 the palette's colours
``LA``, ``RGBA``, ``PA``        alpha ignored: the colour channels as they are
``CMYK``, ``YCbCr``             Pillow's conversion to RGB
anything else (``I``, ``F``..)  :class:`ImageFileError` (32-bit integer or float pixels have no defined range)
==============================  ==================================================================================

The size is checked from the file's header, before any pixel is decoded: more than ``max_pixels`` (default
:data:`MAX_PIXELS`) or smaller than ``min_size`` is an :class:`ImageFileError`; so is a file Pillow itself refuses
as a decompression bomb. An EXIF orientation tag is applied (the picture as a viewer shows it).
"""

import warnings
from pathlib import Path

import numpy as np
from PIL import Image, ImageOps, UnidentifiedImageError

__all__ = ["MAX_PIXELS", "ImageFileError", "read_image", "image_size"]

#: The most pixels an image file may have (header size, before decoding): 25 M, e.g. 6000 x 4000 or 5000 x 5000;
#: about 75 MB decoded. docs/running.md states it.
MAX_PIXELS = 25_000_000

_ORIENTATION = 0x0112                   # the EXIF tag
_GREY = ("L", "1")
_GREY16 = ("I;16", "I;16L", "I;16B", "I;16N")
_COLOUR = ("RGB", "RGBA", "RGBX", "RGBa", "P", "PA", "LA", "La", "CMYK", "YCbCr")


class ImageFileError(ValueError):
    """An image file that cannot be used: missing, a directory, unreadable, an unsupported pixel format, too small
    or too large. The message is one line and names the file."""


def _open(path):
    """``Image.open`` with the one-line errors of the module docstring; Pillow's bomb warning is ours to give."""
    path = Path(path)
    if path.is_dir():
        raise ImageFileError(f"{path} is a directory, not an image file")
    if not path.exists():
        raise ImageFileError(f"no such image file: {path}")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)     # the size check below says it
            return Image.open(path)
    except Image.DecompressionBombError:
        raise ImageFileError(f"image {path} has more than {Image.MAX_IMAGE_PIXELS * 2:,} pixels (Pillow refuses "
                             f"to decode it); the limit is {MAX_PIXELS:,}") from None
    except UnidentifiedImageError:
        raise ImageFileError(f"cannot read image {path}: not an image file Pillow can read") from None
    except OSError as exc:
        raise ImageFileError(f"cannot read image {path}: {exc.strerror or exc}") from None


def _check_size(path, size, min_size, max_pixels):
    w, h = size
    if w * h > max_pixels:
        raise ImageFileError(f"image {path} is {w}x{h} = {w * h:,} pixels, more than the limit of "
                             f"{max_pixels:,}: scale it down first")
    if w < min_size[0] or h < min_size[1]:
        raise ImageFileError(f"image {path} is {w}x{h}, smaller than the least usable {min_size[0]}x{min_size[1]}")


def image_size(path):
    """``(width, height)`` of an image file from its header (no pixel decoded); :class:`ImageFileError` as in
    :func:`read_image`."""
    with _open(path) as img:
        return img.size


def _to_rgb(img, path):
    if img.mode in _GREY16:
        grey = np.asarray(img).astype(np.uint32)
        grey = ((grey * 255 + 32767) // 65535).astype(np.uint8)            # round(v * 255 / 65535)
        return np.repeat(grey[..., None], 3, axis=2)
    if img.mode in _GREY:
        return np.repeat(np.asarray(img.convert("L"), dtype=np.uint8)[..., None], 3, axis=2)
    if img.mode in _COLOUR:
        return np.asarray(img if img.mode == "RGB" else img.convert("RGB"), dtype=np.uint8)
    raise ImageFileError(f"image {path} has pixel format {img.mode!r}, which has no defined 8-bit range: save it "
                         "as 8- or 16-bit grey, RGB, RGBA or palette")


def read_image(path, *, min_size=(1, 1), max_pixels=MAX_PIXELS):
    """The image file ``path`` as an ``(H, W, 3)`` uint8 RGB array (see the module docstring). ``min_size``:
    the least ``(width, height)``; ``max_pixels``: the most pixels. Raises :class:`ImageFileError`."""
    with _open(path) as img:
        _check_size(path, img.size, (0, 0), max_pixels)                   # before any pixel is decoded
        try:
            img.load()
            if img.getexif().get(_ORIENTATION, 1) != 1:
                img = ImageOps.exif_transpose(img)
            rgb = _to_rgb(img, path)
        except ImageFileError:
            raise
        except (OSError, ValueError, SyntaxError) as exc:
            first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise ImageFileError(f"cannot read image {path}: {first}") from None
    _check_size(path, (rgb.shape[1], rgb.shape[0]), min_size, max_pixels)
    return rgb
