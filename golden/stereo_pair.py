"""Stereo pairs fitted to a sensor's resolution, and the bundled default pair (golden/data/README.md). Image files
are read by :func:`golden.image_file.read_image` (re-exported here).

Resizing uses Pillow's bilinear filter on 8-bit RGB, which is deterministic for a given Pillow version
(pinned in pyproject.toml); every consumer (tests, demo, golden model) gets the same pixels from here.
"""

from pathlib import Path

import numpy as np
from PIL import Image

from .image_file import ImageFileError, read_image

__all__ = ["DATA_DIR", "load_default_pair", "load_pair", "read_image", "fit_to_sensor", "crop_size"]

DATA_DIR = Path(__file__).resolve().parent / "data"


def crop_size(width, height, sensor_width, sensor_height):
    """``(w, h)`` of the centre crop of a ``width`` x ``height`` image to the sensor's aspect ratio."""
    if width * sensor_height > height * sensor_width:          # too wide: crop columns
        return round(height * sensor_width / sensor_height), height
    if width * sensor_height < height * sensor_width:          # too tall: crop rows
        return width, round(width * sensor_height / sensor_width)
    return width, height


def fit_to_sensor(image, width, height):
    """Centre-crop ``image`` (H x W x 3 uint8) to ``width:height`` and resize it to ``width`` x ``height``."""
    img = Image.fromarray(np.asarray(image, dtype=np.uint8))
    w, h = img.size
    new_w, new_h = crop_size(w, h, width, height)
    x0, y0 = (w - new_w) // 2, (h - new_h) // 2
    if (new_w, new_h) != (w, h):
        img = img.crop((x0, y0, x0 + new_w, y0 + new_h))
    if img.size != (width, height):
        img = img.resize((width, height), Image.BILINEAR)
    return np.asarray(img.convert("RGB"), dtype=np.uint8)


def check_crop(shape, width, height, min_size):
    """:class:`~golden.image_file.ImageFileError` (one line) when an image of ``shape`` (rows, columns, ...),
    centre-cropped to the sensor's ``width``:``height``, is smaller than ``min_size`` ``(w, h)``."""
    h, w = shape[:2]
    crop = crop_size(w, h, width, height)
    if crop[0] < min_size[0] or crop[1] < min_size[1]:
        raise ImageFileError(f"the pair is {w}x{h} ({crop[0]}x{crop[1]} once centre-cropped to the sensor's "
                             f"{width}:{height}), smaller than the least usable {min_size[0]}x{min_size[1]}")


def load_pair(left_path, right_path, width, height, *, min_size=(1, 1)):
    """Read a stereo pair from image files and fit both to the sensor size. ``min_size``: the least ``(w, h)``
    of the centre crop. Raises :class:`~golden.image_file.ImageFileError` (a ``ValueError``, one line) for a
    missing, unreadable, too small, too large or mismatched pair. One decoded file is held at a time."""
    fitted, shapes = [], []
    for path in (left_path, right_path):
        image = read_image(path)
        shapes.append(image.shape)
        if shapes[0] != shapes[-1]:
            raise ImageFileError(f"left image is {shapes[0][1]}x{shapes[0][0]} but right image is "
                                 f"{shapes[1][1]}x{shapes[1][0]}: a stereo pair must be the same size")
        check_crop(image.shape, width, height, min_size)
        fitted.append(fit_to_sensor(image, width, height))
        del image
    return tuple(fitted)


def load_default_pair(width=1600, height=1200):
    """The bundled Middlebury motorcycle pair as two (height, width, 3) uint8 RGB arrays."""
    return load_pair(DATA_DIR / "motorcycle_left.png", DATA_DIR / "motorcycle_right.png", width, height)
