"""Evaluation of the thesis's software pipeline on the Middlebury motorcycle pair (skimage.data.stereo_motorcycle,
741 x 500, ground-truth disparity; inf = unknown).

1. Disparity quality: bad-pixel rates (|d - truth| > 1 px and > 2 px, over every pixel with a known truth;
   a pixel a method leaves without a value counts as bad) for the thesis's SAD + winner-take-all at its window
   sizes 9, 15 and 30, side by side with OpenCV's StereoBM and StereoSGBM run here on the same grey images
   with the same 64 candidate disparities (0..63). Run times are wall-clock, best of 3.
2. Vertical-shift recovery: the right image moved down/up by 1..6 rows (both images cropped by 6 rows, so no
   row is invented) and the tangent method's estimate, with the default rule (3 zero slope differences per
   row) and with the thesis's literal rule (one zero).
3. What the shift costs when it is not corrected (thesis figure 3.18): SAD 15 x 15 bad-pixel rate with and
   without the found shift.

``main()`` prints the tables and writes them to build/bench/stereo_eval.md and build/bench/stereo_eval_*.csv.
Run: ``python -m bench.bench_stereo_eval`` (or ``python bench/bench_stereo_eval.py``) from the project root.
Timings depend on the machine and its load: on a shared machine they are pessimistic.
"""

import csv
import platform
import time
from pathlib import Path

import cv2
import numpy as np
from skimage import data

from sim.runners import build_dir
from golden.software.pipeline import depth_pipeline, estimate_vertical_shift, to_grey
from golden.software.rectify import vertical_shift
from golden.software.sad import SAD_WINDOWS, sad_disparity

OUT_DIR = build_dir("bench")
NUM_DISPARITIES = 64            # candidates 0..63 for every method (OpenCV needs a multiple of 16)
SHIFTS = range(-6, 7)
MARGIN = 6


def bad_pixel_rates(disparity, truth, valid=None):
    """(bad1, bad2, density, bad2 where a value is given) over the pixels with a known truth; in the first two
    a pixel without a value counts as bad."""
    known = np.isfinite(truth)
    if valid is None:
        valid = np.ones(truth.shape, dtype=bool)
    err = np.where(valid, np.abs(disparity.astype(np.float64) - np.where(known, truth, 0)), np.inf)[known]
    given = valid[known]
    return (float(np.mean(err > 1)), float(np.mean(err > 2)), float(np.mean(given)),
            float(np.mean(err[given] > 2)))


def timed(fn, repeat=3):
    best, result = np.inf, None
    for _ in range(repeat):
        t = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - t)
    return result, best


def stereo_bm(block):
    return cv2.StereoBM_create(numDisparities=NUM_DISPARITIES, blockSize=block)


def stereo_sgbm():
    block = 5
    return cv2.StereoSGBM_create(minDisparity=0, numDisparities=NUM_DISPARITIES, blockSize=block,
                                 P1=8 * block * block, P2=32 * block * block, disp12MaxDiff=1, preFilterCap=63,
                                 uniquenessRatio=10, speckleWindowSize=100, speckleRange=2,
                                 mode=cv2.StereoSGBM_MODE_SGBM)


def describe(matcher):
    names = ["NumDisparities", "BlockSize", "MinDisparity", "P1", "P2", "Mode", "PreFilterType", "PreFilterSize",
             "PreFilterCap", "TextureThreshold", "UniquenessRatio", "SpeckleWindowSize", "SpeckleRange",
             "Disp12MaxDiff"]
    return ", ".join(f"{n}={getattr(matcher, 'get' + n)()}" for n in names if hasattr(matcher, "get" + n))


def run_opencv(matcher, left, right):
    raw = matcher.compute(left, right)                 # fixed point, 4 fractional bits; invalid < minDisparity
    return raw.astype(np.float64) / 16.0, raw >= 0


def disparity_table(left, right, truth):
    rows = []
    for window in SAD_WINDOWS:
        d, t = timed(lambda: sad_disparity(left, right, NUM_DISPARITIES - 1, window))
        rows.append((f"thesis SAD + WTA, {window}x{window}", *bad_pixel_rates(d, truth), t))
    for block in (9, 15, 31):                          # StereoBM needs an odd block: 31 stands for 30
        (d, valid), t = timed(lambda: run_opencv(stereo_bm(block), left, right))
        rows.append((f"OpenCV StereoBM, {block}x{block}", *bad_pixel_rates(d, truth, valid), t))
    (d, valid), t = timed(lambda: run_opencv(stereo_sgbm(), left, right))
    rows.append(("OpenCV StereoSGBM, 5x5", *bad_pixel_rates(d, truth, valid), t))
    return rows


def shift_table(left, right):
    rows = []
    h = left.shape[0]
    for shift in SHIFTS:
        l_crop = left[MARGIN:h - MARGIN]
        r_crop = right[MARGIN - shift:h - MARGIN - shift]      # right row y shows left-crop scene row y - shift
        search, t = timed(lambda: estimate_vertical_shift(l_crop, r_crop), repeat=1)
        est = search.estimate
        literal = vertical_shift(search.matched_left, search.matched_right, min_support=1)
        rows.append((shift, est.shift, est.mean, int(est.confirmed.sum()), len(search.matched_left),
                     literal.shift, literal.mean, t))
    return rows


def rectification_table(left, right, truth):
    rows = []
    h = left.shape[0]
    for shift in (1, 3, 6):
        l_crop, r_crop = left[MARGIN:h - MARGIN], right[MARGIN - shift:h - MARGIN - shift]
        t_crop = truth[MARGIN:h - MARGIN]
        fixed = depth_pipeline(l_crop, r_crop, NUM_DISPARITIES - 1, 15)
        plain = depth_pipeline(l_crop, r_crop, NUM_DISPARITIES - 1, 15, shift=0)
        rows.append((shift, fixed.shift,
                     bad_pixel_rates(plain.disparity, t_crop, plain.disparity >= 0)[1],  # no-data rows = bad
                     bad_pixel_rates(fixed.disparity, t_crop, fixed.disparity >= 0)[1]))
    return rows


def _pct(x):
    return f"{100 * x:.1f} %"


def render(disp_rows, shift_rows, rect_rows, shape, found_on_original):
    lines = [f"Middlebury motorcycle (skimage.data.stereo_motorcycle, {shape[1]}x{shape[0]}), grey = Matlab "
             f"rgb2gray weights, disparities 0..{NUM_DISPARITIES - 1}.",
             "Bad pixels: |d - truth| > 1 or > 2 px over all pixels with known truth; no value = bad.",
             f"Vertical shift found by the tangent method on the original pair: {found_on_original:+d} rows.",
             "",
             "| method | bad > 1 px | bad > 2 px | pixels with a value | bad > 2 px where a value is given "
             "| run time (s) |",
             "|---|---|---|---|---|---|"]
    lines += [f"| {name} | {_pct(b1)} | {_pct(b2)} | {_pct(dens)} | {_pct(b2v)} | {t:.3f} |"
              for name, b1, b2, dens, b2v, t in disp_rows]
    lines += ["", "Vertical-shift recovery (right image moved by the true shift; + = down):", "",
              "| true shift | found | mean row difference | confirmed / matched pairs | thesis rule (1 zero): found "
              "| its mean | time (s) |",
              "|---|---|---|---|---|---|---|"]
    lines += [f"| {s:+d} | {f:+d} | {m:+.3f} | {c} / {n} | {lf:+d} | {lm:+.3f} | {t:.2f} |"
              for s, f, m, c, n, lf, lm, t in shift_rows]
    lines += ["", "SAD 15x15 bad > 2 px on the shifted pair, without and with the found shift (figure 3.18):", "",
              "| true shift | found | without correction | with correction |", "|---|---|---|---|"]
    lines += [f"| {s:+d} | {f:+d} | {_pct(a)} | {_pct(b)} |" for s, f, a, b in rect_rows]
    return "\n".join(lines)


def main():
    left_rgb, right_rgb, truth = data.stereo_motorcycle()
    left, right = to_grey(left_rgb), to_grey(right_rgb)
    truth = np.where(np.isfinite(truth), truth, np.inf).astype(np.float64)
    disp_rows = disparity_table(left, right, truth)
    shift_rows = shift_table(left, right)
    rect_rows = rectification_table(left, right, truth)
    found = estimate_vertical_shift(left, right).shift
    text = render(disp_rows, shift_rows, rect_rows, left.shape, found)
    params = (f"StereoBM: {describe(stereo_bm(15))} (BlockSize 9/15/31 in the rows).\n"
              f"StereoSGBM: {describe(stereo_sgbm())}.\n"
              f"OpenCV {cv2.__version__} ({cv2.getNumThreads()} threads), NumPy {np.__version__}, "
              f"Python {platform.python_version()}, {platform.machine()}; times are best of 3 on a possibly "
              "shared machine.")
    print(text)
    print()
    print(params)
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    (OUT_DIR / "stereo_eval.md").write_text(text + "\n\n" + params + "\n")
    with open(OUT_DIR / "stereo_eval_disparity.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["method", "bad1", "bad2", "density", "bad2_where_given", "seconds"])
        w.writerows([(n, f"{b1:.5f}", f"{b2:.5f}", f"{d:.5f}", f"{b2v:.5f}", f"{t:.4f}")
                     for n, b1, b2, d, b2v, t in disp_rows])
    with open(OUT_DIR / "stereo_eval_shift.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["true_shift", "found", "mean", "confirmed", "matched", "thesis_rule_found", "thesis_rule_mean",
                    "seconds"])
        w.writerows([(s, fd, f"{m:.4f}", c, n, lf, f"{lm:.4f}", f"{t:.3f}")
                     for s, fd, m, c, n, lf, lm, t in shift_rows])
    with open(OUT_DIR / "stereo_eval_rectification.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["true_shift", "found", "bad2_without_correction", "bad2_with_correction"])
        w.writerows([(s, fd, f"{a:.5f}", f"{b:.5f}") for s, fd, a, b in rect_rows])
    print(f"\nwrote {OUT_DIR / 'stereo_eval.md'} and stereo_eval_*.csv")


if __name__ == "__main__":
    main()
