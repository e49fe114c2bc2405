"""The bundled default stereo pair (golden/data/README.md), resized to a sensor's resolution.

Resizing uses Pillow's bilinear filter on 8-bit RGB, which is deterministic for a given Pillow version
(pinned in pyproject.toml); every consumer (tests, demo, golden model) gets the same pixels from here.
"""

from pathlib import Path

import numpy as np
from PIL import Image

__all__ = ["DATA_DIR", "load_default_pair", "load_pair", "read_image", "fit_to_sensor"]

DATA_DIR = Path(__file__).resolve().parent / "data"


def fit_to_sensor(image, width, height):
    """Centre-crop ``image`` (H x W x 3 uint8) to ``width:height`` and resize it to ``width`` x ``height``."""
    img = Image.fromarray(np.asarray(image, dtype=np.uint8))
    w, h = img.size
    if w * height > h * width:          # too wide: crop columns
        new_w = round(h * width / height)
        x0 = (w - new_w) // 2
        img = img.crop((x0, 0, x0 + new_w, h))
    elif w * height < h * width:        # too tall: crop rows
        new_h = round(w * height / width)
        y0 = (h - new_h) // 2
        img = img.crop((0, y0, w, y0 + new_h))
    if img.size != (width, height):
        img = img.resize((width, height), Image.BILINEAR)
    return np.asarray(img.convert("RGB"), dtype=np.uint8)


def read_image(path):
    """An image file as an (H, W, 3) uint8 RGB array. Raises ``OSError`` with a one-line message for a missing or
    unreadable file."""
    path = Path(path)
    if not path.is_file():
        raise OSError(f"no such image file: {path}")
    try:
        with Image.open(path) as img:
            return np.asarray(img.convert("RGB"), dtype=np.uint8)
    except (OSError, ValueError) as exc:
        raise OSError(f"cannot read image {path}: {exc}") from None


def load_pair(left_path, right_path, width, height):
    """Read a stereo pair from image files and fit both to the sensor size. Raises ``OSError`` or
    ``ValueError`` (with a one-line message) for a missing, unreadable or mismatched pair."""
    images = [read_image(left_path), read_image(right_path)]
    if images[0].shape != images[1].shape:
        raise ValueError(f"left image is {images[0].shape[1]}x{images[0].shape[0]} but right image is "
                         f"{images[1].shape[1]}x{images[1].shape[0]}: a stereo pair must be the same size")
    return tuple(fit_to_sensor(img, width, height) for img in images)


def load_default_pair(width=1600, height=1200):
    """The bundled Middlebury motorcycle pair as two (height, width, 3) uint8 RGB arrays."""
    return load_pair(DATA_DIR / "motorcycle_left.png", DATA_DIR / "motorcycle_right.png", width, height)
