"""golden/image_file.py, the one image reader: files of every pixel format written here, each read back and compared
with what the format means (computed here from the values written, not by Pillow's conversion), and the files it
must refuse, each with a one-line ImageFileError that names the file."""

import contextlib
import warnings

import numpy as np
import pytest
from PIL import Image, ImageFile

from golden.image_file import ImageFileError, image_size, read_image

H, W = 12, 17
RNG = np.random.default_rng(18)
RGB = RNG.integers(0, 256, (H, W, 3), dtype=np.uint8)
GREY = RNG.integers(0, 256, (H, W), dtype=np.uint8)
GREY16 = RNG.integers(0, 65536, (H, W), dtype=np.uint16)
ALPHA = RNG.integers(0, 256, (H, W), dtype=np.uint8)


def grey3(grey):
    return np.stack([grey] * 3, axis=-1)


def scaled16(v):
    """16-bit to 8-bit by the rule round(v * 255 / 65535), in exact fractions."""
    from fractions import Fraction
    return np.vectorize(lambda x: round(Fraction(int(x) * 255, 65535)), otypes=[np.uint8])(v)


def palette_image():
    colours = RNG.integers(0, 256, (16, 3), dtype=np.uint8)
    index = RNG.integers(0, 16, (H, W), dtype=np.uint8)
    img = Image.new("P", (W, H))
    img.putpalette(colours.flatten().tolist())
    img.putdata(index.flatten().tolist())
    return img, colours[index]


def _cases():
    pal, pal_rgb = palette_image()
    cmyk = np.zeros((H, W, 4), dtype=np.uint8)
    cmyk[..., :3] = RGB                                             # K = 0: R = 255 - C, G = 255 - M, B = 255 - Y
    return {
        "L.png": (Image.fromarray(GREY), grey3(GREY)),
        "1.png": (Image.fromarray(GREY >= 128).convert("1"), grey3(np.where(GREY >= 128, 255, 0).astype(np.uint8))),
        "I16.png": (Image.fromarray(GREY16), grey3(scaled16(GREY16))),
        "I16B.tif": (_i16b(), grey3(scaled16(GREY16))),
        "RGB.png": (Image.fromarray(RGB), RGB),
        "RGBA.png": (Image.fromarray(np.dstack([RGB, ALPHA])), RGB),
        "LA.png": (Image.fromarray(np.dstack([GREY, ALPHA])), grey3(GREY)),
        "P.png": (pal, pal_rgb),
        "P.gif": (pal, pal_rgb),
        "P-transparency.png": (pal, pal_rgb, {"transparency": 3}),       # tRNS: alpha per palette entry
        "CMYK.tif": (Image.fromarray(cmyk, mode="CMYK"), 255 - RGB),
        "RGB.bmp": (Image.fromarray(RGB), RGB),
        "RGB.tif": (Image.fromarray(RGB), RGB),
    }


def _i16b():
    img = Image.new("I;16B", (W, H))
    img.frombytes(GREY16.astype(">u2").tobytes())
    return img


CASES = _cases()


@pytest.mark.parametrize("name", sorted(CASES))
def test_every_pixel_format_reads_as_what_it_means(tmp_path, name):
    img, expected, *options = CASES[name]
    path = tmp_path / name
    img.save(path, **(options[0] if options else {}))
    with Image.open(path) as back:                                  # the file really is in that format
        assert back.mode.replace("I;16B", "I;16") in (img.mode.replace("I;16B", "I;16"), "P" if name == "P.gif"
                                                      else img.mode), back.mode
    got = read_image(path)
    assert got.dtype == np.uint8 and got.shape == (H, W, 3)
    assert np.array_equal(got, expected)
    assert image_size(path) == (W, H)


def test_16_bit_grey_is_scaled_not_saturated(tmp_path):
    ramp = np.linspace(0, 65535, W * H).round().astype(np.uint16).reshape(H, W)
    Image.fromarray(ramp).save(tmp_path / "ramp.png")
    got = read_image(tmp_path / "ramp.png")[..., 0]
    assert got.min() == 0 and got.max() == 255
    assert abs(float(got.mean()) - 127.5) < 2                     # a ramp stays a ramp (saturated: mean ~ 255)
    Image.fromarray(GREY.astype(np.uint16) * 257).save(tmp_path / "exact.png")      # v * 257 -> v exactly
    assert np.array_equal(read_image(tmp_path / "exact.png"), grey3(GREY))


def test_exif_orientation_is_applied(tmp_path):
    img = Image.fromarray(RGB)
    exif = img.getexif()
    exif[0x0112] = 6                                                # rotate 90 degrees clockwise to view
    img.save(tmp_path / "rotated.jpg", exif=exif, quality=100)
    assert read_image(tmp_path / "rotated.jpg").shape == (W, H, 3)


def _float_tiff(path):
    Image.fromarray(GREY.astype(np.float32)).save(path)


def _int32_tiff(path):
    Image.fromarray(GREY.astype(np.int32)).save(path)


@pytest.mark.parametrize("make, message", [
    (lambda p: None, "no such image file"),
    (lambda p: p.mkdir(), "is a directory, not an image file"),
    (lambda p: p.write_text("not a picture\n"), "not an image file Pillow can read"),
    (lambda p: p.write_bytes((_png_bytes())[:200]), "cannot read image"),
    (_float_tiff, "pixel format 'F'"),
    (_int32_tiff, "pixel format 'I'"),
])
def test_unusable_files_are_one_line_errors_naming_the_file(tmp_path, make, message):
    path = tmp_path / "bad.tif"
    make(path)
    with pytest.raises(ImageFileError) as info:
        read_image(path)
    text = str(info.value)
    assert message in text and str(path) in text and "\n" not in text


def _png_bytes():
    import io
    buf = io.BytesIO()
    Image.fromarray(RNG.integers(0, 256, (64, 64, 3), dtype=np.uint8)).save(buf, format="PNG")
    return buf.getvalue()


def test_size_limits_are_checked_before_decoding(tmp_path, monkeypatch):
    path = tmp_path / "big.png"
    Image.fromarray(RGB).save(path)
    decoded, load = [], ImageFile.ImageFile.load
    monkeypatch.setattr(ImageFile.ImageFile, "load", lambda self: decoded.append(1) or load(self))
    with pytest.raises(ImageFileError, match=f"is {W}x{H} = {W * H:,} pixels, more than the limit of 100"):
        read_image(path, max_pixels=100)
    assert decoded == []
    with pytest.raises(ImageFileError, match=f"is {W}x{H}, smaller than the least usable 18x2"):
        read_image(path, min_size=(18, 2))
    assert decoded                                                 # the spy sees a decode


def test_pillow_decompression_bomb_is_our_one_line_error(tmp_path):
    path = tmp_path / "bomb.png"
    Image.new("1", (20000, 10000)).save(path)                       # 200 M pixels, 25 kB on disk
    with pytest.raises(ImageFileError) as info:
        read_image(path)
    assert "Pillow refuses to decode it" in str(info.value) and "\n" not in str(info.value)
    path = tmp_path / "huge.png"
    Image.new("1", (10000, 10000)).save(path)                       # 100 M: Pillow only warns; we refuse
    with _no_warning(), pytest.raises(ImageFileError, match="10000x10000 = 100,000,000 pixels, more than the limit"):
        read_image(path)


@contextlib.contextmanager
def _no_warning():
    with warnings.catch_warnings(record=True) as log:
        warnings.simplefilter("always")
        yield
    assert not log, [str(w.message) for w in log]
