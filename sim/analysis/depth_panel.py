"""Reading the depth display back from a displayed frame (the HDMI sink's frame from the simulated pins).

* :func:`read_depth_panel`: the sub-pixel depth codes the depth panel shows, by inverting the colour map pixel
  by pixel (each buffer pixel's top-left display pixel; a colour shown by a few neighbouring codes reads as the
  middle one, :func:`colour_codes`); the crosshair's pixels and those under the readout carry no
  code and are returned as unknown (``known`` False).
* :func:`read_text`: a text box's characters, by matching every cell against the font.
* :func:`depth_summary`: bad > 1 / bad > 2 / density of the panel's codes against a ground truth (over the known
  pixels with a truth; invalid counts bad), and the centre distance the readout shows.
* :func:`panel_picture`, :func:`depth_picture_png`: the depth panel alone at buffer size with a colour bar and
  metre labels (a PNG for people; the bar drawn with the golden model's colours and font).
* :func:`read_truth`: a ground-truth disparity file (PFM, or 16-bit PNG in 1/256 pixel) fitted to the buffers
  exactly as the images are (``golden.stereo_pair.fit_to_sensor``: centre crop, then scale).
"""

from pathlib import Path

import numpy as np

from golden.depth_display import depth_colours, draw_text
from spec.display import BACKGROUND_RGB, TEXT_RGB
from spec.font import FONT, FONT_CELL
from spec.layout import TextBox
from spec.sensor import SENSOR, disparity_of_distance
from sim.analysis.truth import bad_pixel_rates, right_view
from sim import UserError

__all__ = ["colour_codes", "read_depth_panel", "read_text", "depth_summary", "panel_picture", "depth_picture_png",
           "read_truth", "depth_outputs", "summary_lines"]


def _to_rgb24(frame):
    frame = np.asarray(frame, dtype=np.int64)
    return (frame[..., 0] << 16) | (frame[..., 1] << 8) | frame[..., 2]


def colour_codes(config):
    """{colour: code}: each colour of the depth colour map (golden model) and the code it stands for: the middle
    (rounded down) of the run of codes 0..16 (D - 1) showing it (codes above 16 (D - 1) are never output), the
    invalid code for the invalid colour. ``ValueError`` when a colour's codes are not one run (then it could not
    be read back)."""
    colours = depth_colours(config).tolist()
    runs = {}
    for code, c in enumerate(colours[:config.fraction * (config.disparities - 1) + 1]):
        first, last = runs.get(c, (code, code))
        if last < code - 1:
            raise ValueError("the colour map repeats a colour after another: the panel cannot be read back")
        runs[c] = (first, code)
    if colours[-1] in runs:
        raise ValueError("the invalid colour is a valid code's: the panel cannot be read back")
    lookup = {c: (first + last) // 2 for c, (first, last) in runs.items()}
    lookup[colours[-1]] = config.invalid
    return lookup


def read_depth_panel(frame, layout, config):
    """``(codes, known)`` (H x W) from the depth panel of ``frame`` (uint8 v_active x h_active x 3): the sub-pixel
    codes the colours show (:func:`colour_codes`: exact up to the few codes sharing a colour; the invalid code
    for invalid or unknown). A pixel whose colour is no code's (crosshair, readout, a broken panel) is
    unknown."""
    panel = panel_picture(frame, layout)
    lookup = colour_codes(config)
    codes = np.vectorize(lambda c: lookup.get(int(c), -1), otypes=[np.int64])(panel)
    return np.where(codes < 0, config.invalid, codes), codes >= 0


def read_text(frame, box):
    """The characters in text box ``box`` (a ``spec.layout.TextBox``) of ``frame``; '?' for a cell that is no
    glyph of the font."""
    rgb = _to_rgb24(frame)
    cw, ch, s = FONT_CELL[0], FONT_CELL[1], box.scale
    glyphs = {c: np.array([[p == "#" for p in row] for row in g], dtype=bool) for c, g in FONT.items()}
    text = ""
    for i in range(len(box.text)):
        cell = rgb[box.y0:box.y0 + ch * s:s, box.x0 + i * cw * s:box.x0 + (i + 1) * cw * s:s]
        if not np.isin(cell, (TEXT_RGB, BACKGROUND_RGB)).all():
            text += "?"
            continue
        lit = cell == TEXT_RGB
        text += next((c for c, g in glyphs.items() if (lit[:-1, :-1] == g).all() and not lit[-1].any()
                      and not lit[:, -1].any()), "?")
    return text


def depth_summary(frame, layout, geometry, config, truth=None):
    """The depth display's figures from a displayed frame: the readout text and its centimetres, and with a
    ``truth`` (H x W buffer-pixel disparities, NaN = unknown) bad > 1, bad > 2 and density over the pixels
    with a truth that the panel shows (crosshair and readout pixels excluded; invalid counts bad)."""
    codes, known = read_depth_panel(frame, layout, config)
    readout = read_text(frame, layout.readout)
    digits = readout[:-2].strip()
    summary = {"centre_readout": readout, "centre_distance_cm": int(digits) if digits.isdigit() else None,
               "panel_pixels_unreadable": int((~known).sum())}
    if truth is not None:
        truth = np.where(known, truth, np.nan)
        bad1, bad2, density = bad_pixel_rates(codes / config.fraction, codes != config.invalid, truth)
        summary.update(bad1=bad1, bad2=bad2, density=density,
                       pixels_with_truth=int(np.isfinite(truth).sum()))
    return summary


def panel_picture(frame, layout):
    """(H, W) int 0xRRGGBB: the depth panel of ``frame`` at buffer size (each buffer pixel's top-left display
    pixel: its colour, or the crosshair's, or the readout's, whose 2x font becomes 1x)."""
    region = layout.region("depth")
    s = region.scale
    return _to_rgb24(frame)[region.y0:region.y1:s, region.x0:region.x1:s]


def depth_picture_png(picture, path, geometry=SENSOR, config=None):
    """Write ``picture`` (H x W 0xRRGGBB, :func:`panel_picture`) with a colour bar beside it (the colours of the
    D whole disparities, code 16 d, from near on top to far, over the picture's height) and the metre labels that
    fall inside the range to ``path``."""
    from spec.depth import DEPTH
    from spec.display import DEPTH_LABELS_M
    from sim.models.ch7301c.hdmi_sink import write_png
    config = config or DEPTH
    h, w = picture.shape
    colours = depth_colours(config)
    width = w + 8 + 10 + 2 + 4 * FONT_CELL[0] + 2
    canvas = np.full((h + 2 * FONT_CELL[1], width), BACKGROUND_RGB, dtype=np.int64)
    top = FONT_CELL[1]
    canvas[top:top + h, :w] = picture
    rows = np.arange(h)
    band = config.disparities - 1 - (rows * config.disparities) // h          # disparity shown on each bar row
    canvas[top:top + h, w + 8:w + 18] = colours[band * config.fraction][:, None]
    for z in DEPTH_LABELS_M:
        d = disparity_of_distance(z, geometry)
        if 0 < d < config.disparities:
            row = top + int((config.disparities - 1 - d + 0.5) * h / config.disparities)
            canvas[row, w + 18:w + 20] = TEXT_RGB
            label = TextBox(f"{z:g}m", w + 21, max(0, row - FONT_CELL[1] // 2), 1)
            draw_text(canvas, label, label.text)
    rgb = np.stack([(canvas >> 16) & 0xFF, (canvas >> 8) & 0xFF, canvas & 0xFF], axis=-1).astype(np.uint8)
    return write_png(rgb, Path(path))


def _read_pfm(path):
    with open(path, "rb") as f:
        header = f.readline().strip()
        if header not in (b"Pf", b"PF"):
            raise UserError(f"{path}: not a PFM file (header {header[:8]!r})")
        dims = f.readline().split()
        scale = float(f.readline())
        w, h = int(dims[0]), int(dims[1])
        data = np.fromfile(f, dtype="<f4" if scale < 0 else ">f4", count=w * h * (3 if header == b"PF" else 1))
    if data.size != w * h * (3 if header == b"PF" else 1):
        raise UserError(f"{path}: truncated PFM file")
    data = data.reshape(h, w, -1)[..., 0]
    return np.flipud(data).astype(np.float64)              # PFM rows run bottom to top


def read_truth(path, image_size, geometry=SENSOR, view="right"):
    """The ground-truth disparity (original pixels; PFM: inf = unknown; 16-bit PNG: value / 256, 0 = unknown)
    of the reference (right) image at each buffer pixel, in buffer pixels (NaN = unknown). ``image_size`` is
    (width, height) of the input images. ``view="left"``: the file is the left image's map (Middlebury's disp0),
    converted to the right view first (``sim.analysis.truth.right_view``). One-line :class:`UserError` for a
    bad file."""
    if view not in ("right", "left"):
        raise UserError(f"the ground truth's view must be 'right' or 'left', not {view!r}")
    path = Path(path)
    if not path.is_file():
        raise UserError(f"no such ground-truth file: {path}")
    try:
        if path.suffix.lower() == ".pfm":
            truth = _read_pfm(path)
            truth[~np.isfinite(truth)] = np.nan
        else:
            from PIL import Image
            with Image.open(path) as img:
                if img.mode not in ("I;16", "I;16B", "I"):
                    raise UserError(f"{path}: a PNG ground truth must be 16-bit grey (disparity x 256), not "
                                    f"{img.mode}")
                raw = np.asarray(img, dtype=np.float64)
            truth = np.where(raw > 0, raw / 256.0, np.nan)
    except (OSError, ValueError) as exc:
        raise UserError(f"cannot read ground truth {path}: {exc}") from None
    w, h = image_size
    if truth.shape != (h, w):
        raise UserError(f"ground truth {path} is {truth.shape[1]}x{truth.shape[0]}, the images {w}x{h}")
    return _fit_truth(truth, geometry, left_view=view == "left")


def _fit_truth(truth, geometry, left_view=False):
    """Crop as ``fit_to_sensor`` does, sample at the buffer pixels' centres (nearest), scale the disparities.
    ``left_view``: the sampled rows, whole, are converted to the right view before their columns are sampled (the
    conversion works row by row: converting only the rows sampled gives the same values)."""
    from golden.stereo_pair import crop_size
    h, w = truth.shape
    gw, gh = geometry.width, geometry.height
    cw, chh = crop_size(w, h, gw, gh)
    x0, y0 = (w - cw) // 2, (h - chh) // 2
    i, j = np.arange(geometry.buf_height), np.arange(geometry.buf_width)
    rows = np.clip(np.rint((geometry.scale * i + 0.5) * chh / gh - 0.5).astype(int), 0, chh - 1) + y0
    cols = np.clip(np.rint((geometry.scale * j + 0.5) * cw / gw - 0.5).astype(int), 0, cw - 1) + x0
    picked = truth[rows]
    if left_view:
        picked = right_view(picked)
    return picked[:, cols] * gw / cw / geometry.scale


def depth_outputs(frame, setup, truth=None, write=None):
    """The depth figures of a run's displayed ``frame`` (:func:`depth_summary`, ``truth`` in buffer pixels or
    None) and ``depth_map.png`` (:func:`depth_picture_png` of the panel), written through ``write(name,
    writer)`` (``writer(path)`` makes the file; ``write`` returns the final path); returns ``(summary, {what:
    path})``. Nothing without a frame."""
    if frame is None:
        return {}, {}
    layout, config = setup.display_layout, setup.depth
    summary = depth_summary(frame, layout, setup.geometry, config, truth)
    picture = panel_picture(frame, layout)
    path = write("depth_map.png", lambda p: depth_picture_png(picture, p, setup.geometry, config))
    return summary, {"depth map from the displayed frame, buffer size, with its colour bar": path}


def summary_lines(summary):
    """Printable lines of a :func:`depth_summary`."""
    if not summary:
        return []
    lines = [f"  centre distance shown: {summary['centre_readout'].strip()}"]
    if "bad2" in summary:
        lines.append(f"  depth panel vs ground truth: bad > 1 {100 * summary['bad1']:.1f} %, bad > 2 "
                     f"{100 * summary['bad2']:.1f} %, density {100 * summary['density']:.1f} % "
                     f"({summary['pixels_with_truth']} pixels with a truth)")
    return lines
