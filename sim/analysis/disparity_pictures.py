"""Pictures of the disparity display for the bundled stereo pair (thesis figures 4.15-4.17, on the Middlebury
motorcycle instead of the thesis's rectangle).

:func:`write_pictures` writes the composited 1920 x 1080 frame (left image, right image, 2x disparity map) at
the disparity where the motorcycle matches -- its pixels' |L - R| drop below the first threshold and it fades
to black -- and at a wrong one, where the motorcycle shows up as bright doubled edges. Both at rectification
0 (the Middlebury pair is rectified; :func:`find_settings` checks that 0 is the best vertical shift).

The frames come from the golden model (``golden.disparity.composite_frame``), which the RTL is tested equal to
bit for bit (tests/test_compositor.py); the file names say ``golden`` and each PNG carries a caption in its
``Description`` text chunk.

How "the right disparity" is found, honestly:

* Ground truth: ``skimage.data.stereo_motorcycle()`` returns Middlebury's disparity map of the left image
  (left x = right x + d, 741 x 500 pixels). The bundled pair is its columns 37..703 (golden/data/README.md;
  :func:`crop_offset` re-finds the offset by exact comparison), resized to 1600 x 1200 and downscaled by 4, so
  a buffer pixel (i, j) is original pixel ((4j + 0.5) * 667 / 1600 - 0.5 + 37, (4i + 0.5) * 500 / 1200 - 0.5)
  and a disparity of d original pixels is d * 1600 / 667 / 4 buffer pixels.
* The motorcycle: a box around it in the original image (x 120..690, y 100..445) where the ground truth says
  it is near (more than 40 original pixels of disparity; the shelves behind it are below 35).
* :func:`find_settings` takes the (disparity, rectification) minimising the mean |L - R| over the
  motorcycle's pixels of the captured 5-bit buffers, and reports the ground-truth median beside it. The wrong
  disparity is the one that best matches the background instead (ground truth below 15 buffer pixels).
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image
from PIL.PngImagePlugin import PngInfo

from golden.capture import capture_frame
from golden.disparity import composite_frame, difference_levels
from golden.stereo_pair import DATA_DIR, load_default_pair
from spec.sensor import SENSOR
from spec.video import CEA_1080P60

__all__ = ["bundled_pair_settings", "crop_offset", "find_settings", "Settings", "write_pictures"]

#: The motorcycle's bounding box in the original 741 x 500 image (x0, x1, y0, y1), and the ground-truth
#: disparity (original pixels) above which a pixel in the box is the motorcycle, not the shelves behind it.
MOTORCYCLE_BOX = (120, 690, 100, 445)
MOTORCYCLE_MIN_DISPARITY = 40.0
#: Ground-truth disparity (buffer pixels) below which a pixel is background (shelves, wall).
BACKGROUND_MAX_DISPARITY = 15.0


def _middlebury():
    import skimage.data
    left, _, disparity = skimage.data.stereo_motorcycle()
    return left, disparity


def crop_offset():
    """The first column of skimage's motorcycle image that the bundled left image starts at (exact match)."""
    original, _ = _middlebury()
    bundled = np.asarray(Image.open(DATA_DIR / "motorcycle_left.png").convert("RGB"))
    h, w = bundled.shape[:2]
    for x0 in range(original.shape[1] - w + 1):
        if original.shape[0] == h and np.array_equal(original[:, x0:x0 + w], bundled):
            return x0
    raise ValueError("the bundled pair is not a column crop of skimage.data.stereo_motorcycle()")


def ground_truth(geometry=SENSOR):
    """Middlebury's disparity at every buffer pixel (left-image coordinates), in buffer pixels; NaN where the
    ground truth has none."""
    _, disparity = _middlebury()
    x0 = crop_offset()
    crop_w, crop_h = Image.open(DATA_DIR / "motorcycle_left.png").size
    i = np.arange(geometry.buf_height)
    j = np.arange(geometry.buf_width)
    src_y = np.rint((geometry.scale * i + 0.5) * crop_h / geometry.height - 0.5).astype(int).clip(0, crop_h - 1)
    src_x = np.rint((geometry.scale * j + 0.5) * crop_w / geometry.width - 0.5).astype(int).clip(0, crop_w - 1)
    gt = disparity[np.ix_(src_y, src_x + x0)].astype(np.float64)
    gt[~np.isfinite(gt)] = np.nan
    return gt * geometry.width / crop_w / geometry.scale, (src_x + x0, src_y)


def motorcycle_mask(geometry=SENSOR):
    """Buffer pixels (left-image coordinates) of the motorcycle, from the box and the ground truth."""
    gt, (orig_x, orig_y) = ground_truth(geometry)
    bx0, bx1, by0, by1 = MOTORCYCLE_BOX
    in_box = ((orig_y >= by0) & (orig_y < by1))[:, None] & ((orig_x >= bx0) & (orig_x < bx1))[None, :]
    scale = geometry.width / Image.open(DATA_DIR / "motorcycle_left.png").size[0] / geometry.scale
    with np.errstate(invalid="ignore"):
        return in_box & (gt > MOTORCYCLE_MIN_DISPARITY * scale), gt


def _mean_residual(left, right, mask, d, r):
    """Mean |L(x, y) - R(x - d, y - r)| over the left-image pixels in ``mask`` that have a right pixel."""
    h, w = left.shape
    if d >= w or r >= h:
        return np.inf
    diff = np.abs(left[r:, d:].astype(int) - right[:h - r, :w - d].astype(int))
    m = mask[r:, d:]
    return diff[m].mean() if m.any() else np.inf


def _black_fraction(left, right, mask, d, r):
    """Fraction of the masked left-image pixels shown black (level 0, with data) in the disparity map."""
    levels, no_data = difference_levels(left, right, d, r)
    yy, xx = np.nonzero(mask)
    ok = (xx - d >= 0) & (yy - r >= 0)
    shown = levels[yy[ok] - r, xx[ok] - d] == 0
    return float((shown & ~no_data[yy[ok] - r, xx[ok] - d]).mean())


@dataclass(frozen=True)
class Settings:
    """What :func:`find_settings` found (disparities in buffer pixels)."""
    disparity: int                  # minimises the motorcycle's residual
    rectification: int              # minimises it at that disparity
    ground_truth_median: float      # Middlebury's median over the motorcycle, scaled to buffer pixels
    wrong_disparity: int            # minimises the background's residual instead
    black_right: float              # fraction of the motorcycle shown black at `disparity`
    black_wrong: float              # ... at `wrong_disparity`


def find_settings(left, right, geometry=SENSOR, max_disparity=None, max_rectification=4):
    """The motorcycle's disparity and rectification (residual minimum) and a wrong disparity, for the buffers.
    ``max_disparity`` None: 60 at the thesis's 400-pixel buffers, scaled with the buffer width, at most 127 (the
    disparity switches' range)."""
    if max_disparity is None:
        max_disparity = min(127, round(60 * geometry.buf_width / SENSOR.buf_width))
    mask, gt = motorcycle_mask(geometry)
    background = np.isfinite(gt) & (gt < BACKGROUND_MAX_DISPARITY)
    d = min(range(max_disparity + 1), key=lambda k: _mean_residual(left, right, mask, k, 0))
    r = min(range(max_rectification + 1), key=lambda k: _mean_residual(left, right, mask, d, k))
    wrong = min(range(max_disparity + 1), key=lambda k: _mean_residual(left, right, background, k, 0))
    return Settings(d, r, float(np.nanmedian(gt[mask])), wrong,
                    _black_fraction(left, right, mask, d, r), _black_fraction(left, right, mask, wrong, 0))


def bundled_pair_settings(geometry=SENSOR):
    """``(Settings, left, right)``: :func:`find_settings` on the bundled pair's captured buffers (the switch
    settings ``make demo`` runs the system at), with the pair's buffers (``golden.capture.capture_frame``)."""
    left_rgb, right_rgb = load_default_pair(geometry.width, geometry.height)
    left, right = capture_frame(left_rgb, geometry), capture_frame(right_rgb, geometry)
    return find_settings(left, right, geometry), left, right


def write_pictures(outdir, timing=CEA_1080P60, geometry=SENSOR):
    """Write the golden composited frames for the bundled pair at the motorcycle's disparity and at a wrong one
    (both at the rectification found, 0) into ``outdir``; return their paths (matched first)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    s, left, right = bundled_pair_settings(geometry)
    pictures = [
        (s.disparity, s.rectification, "matched",
         f"Golden model frame, disparity {s.disparity}, rectification {s.rectification}: the motorcycle's "
         f"disparity (mean |L-R| minimum; Middlebury ground truth median {s.ground_truth_median:.1f} buffer "
         f"pixels). The motorcycle fades: {100 * s.black_right:.0f}% of its pixels are black."),
        (s.wrong_disparity, s.rectification, "wrong",
         f"Golden model frame, disparity {s.wrong_disparity}, rectification {s.rectification}: wrong for the "
         f"motorcycle (this one matches the background, which fades instead); the motorcycle shows bright "
         f"doubled edges, only {100 * s.black_wrong:.0f}% of its pixels are black."),
    ]
    paths = []
    for d, r, tag, caption in pictures:
        frame = composite_frame(left, right, d, r, timing, geometry)
        path = outdir / f"disparity_golden_{tag}_d{d}_r{r}.png"
        info = PngInfo()
        info.add_text("Description", caption)
        Image.fromarray(frame).save(path, pnginfo=info)
        paths.append(path)
    return paths


def main(argv=None):
    import sys
    outdir = (argv or sys.argv[1:] or ["build/disparity_pictures"])[0]
    for path in write_pictures(outdir):
        print(path, "-", Image.open(path).text["Description"])


if __name__ == "__main__":
    main()
