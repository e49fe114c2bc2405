"""``stereodepth depth LEFT RIGHT``: the thesis's software pipeline (figure 3.8) on a stereo pair.

Writes to ``--out`` (default build/depth/):

* ``disparity.png``   the SAD winner-take-all disparity map with a colour bar in pixels,
* ``distance.png``    the distance map Z = B f / (d * pitch) with a colour bar in cm,
* ``disparity.npy``   the disparity map as int16 (-1 = no data), for scripts,
* ``vertical_shift.txt`` the vertical shift found by the tangent method (also printed),
* ``result.json``     the shift and the provenance (input files with SHA-256, parameters, tools, git commit, times).

Bad input (missing or unreadable file, different sizes, out-of-range values, an image over
:data:`MAX_PIXELS`) is a one-line error, exit 2. Outputs appear under their names only when complete
(``stereodepth/outputs.py``); a progress bar on stderr follows the vertical-shift search and the SAD search.
"""

import json
import math

from .errors import UserError, prepare_out_dir
from .outputs import RunOutputs
from .progress import Progress


_CAMERAS = ("board", "webcam")
#: The largest image ``depth`` takes: 4 M pixels (e.g. 2304 x 1728). Its SAD search keeps a few float64 maps of the
#: image (about 0.1 kB a pixel, so under 0.6 GB here) and takes about 6 s per M pixel per 64 disparities.
MAX_PIXELS = 4_000_000
OUTPUTS = ("disparity.png", "distance.png", "disparity.npy", "vertical_shift.txt", "result.json")


def add_arguments(parser):
    parser.add_argument("left", metavar="LEFT", help="left (reference) image file")
    parser.add_argument("right", metavar="RIGHT", help="right image file, same size as LEFT")
    parser.add_argument("--max-disparity", metavar="N", default="63",
                        help="largest disparity searched, in pixels (candidates 0..N; default 63)")
    parser.add_argument("--window", metavar="W", default="30",
                        help="SAD window size W x W (the thesis uses 9, 15 and 30; default 30)")
    parser.add_argument("--camera", choices=_CAMERAS, default="board",
                        help="camera parameters: 'board' = thesis 4.6.7 (B 6.3 cm, f 3.81 mm, pitch 8.8 um, the "
                             "VmodCAM at 400x300), 'webcam' = thesis 3.3 (B 15 cm, f 3.85 mm, pitch 4.1 um, "
                             "640x480); default board")
    parser.add_argument("--baseline", metavar="CM", help="baseline in cm (overrides --camera)")
    parser.add_argument("--focal", metavar="MM", help="focal length in mm (overrides --camera)")
    parser.add_argument("--pitch", metavar="UM", help="pixel pitch in micrometres (overrides --camera)")
    parser.add_argument("--shift", metavar="ROWS",
                        help="use this vertical shift (rows the right image moves up) instead of estimating it; "
                             "0 = no rectification")
    parser.add_argument("--max-vertical-shift", metavar="ROWS", default="16",
                        help="largest vertical shift the corner matching considers (default 16)")
    parser.add_argument("--out", metavar="DIR", default="build/depth", help="output directory (default build/depth)")


def _int(text, option, low, high=None):
    try:
        value = int(text)
    except (TypeError, ValueError):
        raise UserError(f"{option} must be a whole number, not {text!r}") from None
    if value < low or (high is not None and value > high):
        bound = f"between {low} and {high}" if high is not None else f"at least {low}"
        raise UserError(f"{option} must be {bound}, not {value}")
    return value


def _length(text, option, unit, scale):
    try:
        value = float(text)
    except (TypeError, ValueError):
        raise UserError(f"{option} must be a number ({unit}), not {text!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise UserError(f"{option} must be a positive length in {unit}, not {text}")
    return value * scale


def read_image(path):
    """An image file as an (H, W, 3) uint8 array (``golden.image_file``: 16-bit grey scaled, palette, alpha
    ignored) of at most :data:`MAX_PIXELS`; UserError if missing, unreadable or too large."""
    from golden.image_file import ImageFileError, read_image as read
    try:
        return read(path, max_pixels=MAX_PIXELS)
    except ImageFileError as exc:
        raise UserError(str(exc)) from None


def camera_from_args(args):
    from golden.software.distance import BOARD_CAMERAS, WEBCAM_CAMERAS, CameraParameters

    base = BOARD_CAMERAS if args.camera == "board" else WEBCAM_CAMERAS
    return CameraParameters(
        baseline_m=base.baseline_m if args.baseline is None else _length(args.baseline, "--baseline", "cm", 1e-2),
        focal_length_m=base.focal_length_m if args.focal is None else _length(args.focal, "--focal", "mm", 1e-3),
        pixel_pitch_m=base.pixel_pitch_m if args.pitch is None else _length(args.pitch, "--pitch", "um", 1e-6),
    )


def _shift_text(result):
    s = result.shift
    where = ("the right image is %d rows lower than the left; moved up by %d" % (s, s) if s > 0 else
             "the right image is %d rows higher than the left; moved down by %d" % (-s, -s) if s < 0 else
             "the images are aligned")
    lines = [f"vertical shift: {s:+d} rows ({where})"]
    if result.search is None:
        lines.append("given with --shift, not estimated")
    else:
        e = result.search.estimate
        lines.append(f"estimated by the tangent method from {int(e.confirmed.sum())} of "
                     f"{len(result.search.matched_left)} SSD-matched corner pairs "
                     f"(mean row difference {e.mean:+.3f}; {len(result.search.left_corners)} left and "
                     f"{len(result.search.right_corners)} right Harris corners)")
    return "\n".join(lines)


def _write_figures(result, outputs, camera, max_disparity, window):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from golden.software.distance import distance_from_disparity

    h, w = result.disparity.shape
    size = (min(12.0, 2.0 + w / 80), min(10.0, 1.2 + h / 80))
    cam = (f"B {camera.baseline_m * 100:g} cm, f {camera.focal_length_m * 1000:g} mm, "
           f"pitch {camera.pixel_pitch_m * 1e6:g} um")

    disp = np.ma.masked_less(result.disparity.astype(float), 0)
    cmap = plt.get_cmap("viridis").copy()
    cmap.set_bad("0.5")
    fig, ax = plt.subplots(figsize=size)
    im = ax.imshow(disp, cmap=cmap, vmin=0, vmax=max_disparity, interpolation="nearest")
    fig.colorbar(im, ax=ax, label="disparity (pixels)")
    ax.set_title(f"SAD {window}x{window} disparity, vertical shift {result.shift:+d} rows (grey: no data)",
                 fontsize=9)
    ax.set_axis_off()
    outputs.write("disparity.png", lambda p: fig.savefig(p, dpi=100, bbox_inches="tight", format="png"))
    plt.close(fig)

    dist_cm = result.distance_m * 100
    finite = dist_cm[np.isfinite(dist_cm)]
    near = float(distance_from_disparity(max_disparity, camera)) * 100
    far = float(np.percentile(finite, 98)) if finite.size else near * 2
    far = max(far, near * 1.01)
    cmap = plt.get_cmap("turbo_r").copy()
    cmap.set_bad("0.5")
    cmap.set_over("white")
    fig, ax = plt.subplots(figsize=size)
    im = ax.imshow(np.ma.masked_invalid(np.where(np.isposinf(dist_cm), far * 10, dist_cm)), cmap=cmap,
                   vmin=near, vmax=far, interpolation="nearest")
    fig.colorbar(im, ax=ax, label="distance from the cameras (cm)", extend="max")
    ax.set_title(f"distance Z = B f / (d pitch), {cam}\n(white: beyond {far:.0f} cm or d = 0; grey: no data)",
                 fontsize=9)
    ax.set_axis_off()
    outputs.write("distance.png", lambda p: fig.savefig(p, dpi=100, bbox_inches="tight", format="png"))
    plt.close(fig)


def _check_pair(args, left, right, max_disparity, window):
    """The pair against the options: same size, wider than ``max_disparity``, at least ``window`` square; returns
    the ``--shift`` value (None: estimate it)."""
    if left.shape != right.shape:
        raise UserError(f"left image is {left.shape[1]}x{left.shape[0]} but right image is "
                        f"{right.shape[1]}x{right.shape[0]}: a stereo pair must be the same size")
    h, w = left.shape[:2]
    if max_disparity >= w:
        raise UserError(f"--max-disparity must be below the image width {w}, not {max_disparity}")
    if window > min(h, w):
        raise UserError(f"--window {window} is larger than the {w}x{h} image")
    return None if args.shift is None else _int(args.shift, "--shift", -(h - 1), h - 1)


def run(args):
    from stereodepth.provenance import provenance, utc_now
    started = utc_now()
    max_disparity = _int(args.max_disparity, "--max-disparity", 1)
    window = _int(args.window, "--window", 1)
    max_vshift = _int(args.max_vertical_shift, "--max-vertical-shift", 0)
    camera = camera_from_args(args)
    out = prepare_out_dir(args.out)                             # writable, before any work
    left = read_image(args.left)
    right = read_image(args.right)
    shift = _check_pair(args, left, right, max_disparity, window)
    outputs = RunOutputs(out, OUTPUTS).start()

    import numpy as np

    from golden.software.pipeline import depth_pipeline

    bar = Progress("depth")
    try:
        result = depth_pipeline(left, right, max_disparity=max_disparity, window=window, camera=camera,
                                shift=shift, max_vertical_shift=max_vshift,
                                progress=lambda stage, f: bar.update(int(1000 * f), f"depth: {stage}"))
    except ValueError as exc:
        raise UserError(f"{exc} (give the shift with --shift)") from None
    finally:
        bar.close()
    text = _shift_text(result)
    try:
        outputs.write("disparity.npy", lambda p: np.save(p, result.disparity))
        outputs.write("vertical_shift.txt", lambda p: p.write_text(text + "\n"))
        _write_figures(result, outputs, camera, max_disparity, window)
        record = {"vertical_shift": result.shift, "estimated": result.search is not None,
                  "provenance": provenance([args.left, args.right], dict(vars(args), shift=shift), started)}
        outputs.write("result.json", lambda p: p.write_text(json.dumps(record, indent=1) + "\n"))
    except OSError as exc:
        raise UserError(f"cannot write to {out}: {exc.strerror or exc}") from None
    print(text)
    print(f"wrote {out / 'disparity.png'}, {out / 'distance.png'}, {out / 'disparity.npy'}, "
          f"{out / 'vertical_shift.txt'}, {out / 'result.json'}")
    return 0
