"""Quality of the depth engine's map (golden/depth.py, which the RTL equals bit for bit) beside OpenCV.

Pairs: the bundled motorcycle pair as the system captures it (``stereodepth run``: fitted to the 1600 x 1200
sensor, then ``golden.capture.capture_frame`` to the 400 x 300 x 5-bit buffers) and three synthetic scenes of
sim/testbed/scene.py rendered for the VmodCAM (textured planes; the thesis's test-bed cards on white; a card nearer
than D allows). No other real stereo pair with ground truth is available offline (scikit-image ships only the
motorcycle; opencv-python-headless ships no sample images).

Figures: bad > 0.5, bad > 1 and bad > 2 px over every pixel with a ground truth (an invalid pixel counts bad),
the mean absolute error of the valid pixels and the density, for the engine (sub-pixel codes / 16), the
whole-pixel engine (``fraction_bits = 0``), and under it the engine's confidence trade (bad > 2 among the valid pixels
against density for a few uniqueness thresholds); for the thesis's SAD 15 x 15 + WTA, OpenCV StereoBM (best block size) and StereoSGBM on
the same buffers shifted to 8 bits, all with the right image as reference (OpenCV runs on the mirrored pair).
Motorcycle ground truth: the right view made from Middlebury's left map (sim/analysis/truth.py), and, to compare
with the probe of the engine's goals, the mirrored pair against Middlebury's own left map ("left view").

First section (bench/depth_builds.py): the thesis build against the 800 x 600 build (8-bit 2 x 2 averaged buffers,
128 disparities, 3 paths; golden model only), with OpenCV's StereoSGBM in its full 8-path mode on the same buffers,
errors in 400-pixel units, the goals checked; when they are not met, the 800 x 600 build's lever table
(bench_depth_levers.levers_800: a third and a fourth path, the confidence threshold). Then the thesis build in detail.

Writes build/bench/depth.md and build/bench/depth_motorcycle.png (right image, ground truth, the four maps;
one colour scale with a legend; invalid / unknown in grey). Run: ``python -m bench depth``.
"""

import dataclasses
import time
from pathlib import Path

import cv2
import numpy as np

from sim.runners import build_dir
from golden.capture import capture_frame
from golden.depth import depth_map
from golden.software.sad import sad_disparity
from golden.stereo_pair import load_default_pair
from hdl.depth import schedule, tag_delay
from hdl.depth.engine import median_block
from spec.depth import DEPTH
from spec.sensor import SENSOR
from sim.analysis.truth import bad_pixel_rates, error_figures, motorcycle_truth, scene_truth

OUT_DIR = build_dir("bench")
BM_BLOCKS = tuple(range(5, 33, 4))


def engine(left, right, config=DEPTH):
    """The engine's map in pixels (sub-pixel codes / 2**F) and its validity."""
    codes = depth_map(left, right, config)
    return codes.astype(np.float64) / config.fraction, codes != config.invalid


def whole_pixels(left, right):
    """The whole-pixel engine (no sub-pixel fit, no confidence stage) for comparison."""
    return engine(left, right, dataclasses.replace(DEPTH, fraction_bits=0, uniqueness=64))


def _opencv(matcher, left, right):
    """Right-reference disparity from a left-reference matcher: run it on the mirrored pair."""
    raw = matcher.compute(np.ascontiguousarray((right[:, ::-1] << 3).astype(np.uint8)),
                          np.ascontiguousarray((left[:, ::-1] << 3).astype(np.uint8)))[:, ::-1]
    return raw / 16.0, raw >= 0


def sgbm(left, right):
    block = 5
    return _opencv(cv2.StereoSGBM_create(minDisparity=0, numDisparities=DEPTH.disparities, blockSize=block,
                                         P1=8 * block * block, P2=32 * block * block, disp12MaxDiff=1,
                                         preFilterCap=63, uniquenessRatio=10, speckleWindowSize=100,
                                         speckleRange=2), left, right)


def bm(block):
    return lambda left, right: _opencv(cv2.StereoBM_create(numDisparities=DEPTH.disparities, blockSize=block),
                                       left, right)


def sad15(left, right):
    d = sad_disparity(right[:, ::-1], left[:, ::-1], DEPTH.disparities - 1, 15)[:, ::-1]
    return d.astype(np.float64), np.ones(d.shape, dtype=bool)


def mirrored(method):
    """``method`` on the mirrored, swapped pair: its map of the left image (for Middlebury's left truth)."""
    def run(left, right):
        d, v = method(right[:, ::-1], left[:, ::-1])
        return d[:, ::-1], v[:, ::-1]
    return run


def evaluate(left, right, truth, *, mirror=False):
    """[(name, bad1, bad2, density, map, valid, (bad0.5, bad1, bad2, mae, density))] for the engine, the
    whole-pixel engine, SAD, best BM, SGBM."""
    wrap = mirrored if mirror else (lambda f: f)
    rows = []
    for name, method in (("depth engine, 1/16 pixel (golden = RTL)", engine),
                         ("depth engine, whole pixels", whole_pixels), ("thesis SAD 15x15 + WTA", sad15),
                         ("OpenCV StereoSGBM 5x5", sgbm)):
        d, v = wrap(method)(left, right)
        rows.append((name, *bad_pixel_rates(d, v, truth), d, v, error_figures(d, v, truth)))
    best = None
    for block in BM_BLOCKS:
        d, v = wrap(bm(block))(left, right)
        r = (f"OpenCV StereoBM {block}x{block} (best block)", *bad_pixel_rates(d, v, truth), d, v,
             error_figures(d, v, truth))
        if best is None or r[2] < best[2]:
            best = r
    rows.insert(3, best)
    return rows


UNIQUENESS = (64, 62, 60, 58, 56)


def confidence(title, left, right, truth):
    """bad > 2 among the valid pixels and density of the engine for a few ``uniqueness`` thresholds."""
    lines = [f"#### {title}: confidence (uniqueness 64 S* <= k S2)", "",
             "| k | bad > 2 among valid | density | bad > 2 (invalid counted bad) |", "|---|---|---|---|"]
    known = np.isfinite(truth)
    for k in UNIQUENESS:
        d, v = engine(left, right, dataclasses.replace(DEPTH, uniqueness=k))
        among = float(np.mean(np.abs(d - truth)[known & v] > 2))
        b2, density = error_figures(d, v, truth)[2], error_figures(d, v, truth)[4]
        board = " (board)" if k == DEPTH.uniqueness else ""
        lines.append(f"| {k}{board} | {100 * among:.1f} % | {100 * density:.1f} % | {100 * b2:.1f} % |")
    return lines + [""]


def motorcycle_buffers():
    left_rgb, right_rgb = load_default_pair(SENSOR.width, SENSOR.height)
    return (capture_frame(left_rgb, SENSOR).astype(np.int64), capture_frame(right_rgb, SENSOR).astype(np.int64))


def synthetic_scenes():
    from sim.testbed.scene import VMODCAM, PlanarObject
    textured = dict(finish="textured", texel_m=0.02)
    return {
        "textured planes (2.5 m wall, cards at 0.8 / 1.2 / 1.6 m)": (
            PlanarObject("rectangle", (3.0, 2.4), 2.5, **textured),
            PlanarObject("rectangle", (0.19, 0.13), 0.8, centre_x_m=-0.1, **textured),
            PlanarObject("circle", (0.3, 0.3), 1.2, centre_x_m=0.25, centre_y_m=0.1, **textured),
            PlanarObject("triangle", (0.4, 0.35), 1.6, centre_x_m=0.1, centre_y_m=-0.25, **textured)),
        "test-bed cards on white (truth on the cards only)": (
            PlanarObject("rectangle", (0.19, 0.13), 1.0, centre_x_m=-0.12),
            PlanarObject("circle", (0.155, 0.155), 1.5, centre_x_m=0.15)),
        "card at 0.35 m (disparity 78 > D) before a 2.5 m wall": (
            PlanarObject("rectangle", (3.0, 2.4), 2.5, **textured),
            PlanarObject("rectangle", (0.10, 0.08), 0.35, finish="textured", texel_m=0.005)),
    }, VMODCAM


def table(title, rows):
    lines = [f"### {title}", "", "| method | bad > 0.5 px | bad > 1 px | bad > 2 px | MAE (valid) | density |",
             "|---|---|---|---|---|---|"]
    lines += [f"| {r[0]} | {100 * r[6][0]:.1f} % | {100 * r[6][1]:.1f} % | {100 * r[6][2]:.1f} % | "
              f"{r[6][3]:.2f} px | {100 * r[6][4]:.1f} % |" for r in rows]
    return lines + [""]


def picture(right, truth, rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cmap = plt.get_cmap("turbo").copy()
    cmap.set_bad((0.45, 0.45, 0.45))
    panels = [("right image (reference)", right, "grey", None), ("ground truth (right view)", truth, cmap, True)]
    panels += [(f"{r[0]}\nbad>2 {100 * r[2]:.1f} %, density {100 * r[3]:.1f} %",
                np.where(r[5], r[4], np.nan), cmap, True) for r in rows if r[0] != "depth engine, whole pixels"]
    fig, axes = plt.subplots(2, 3, figsize=(15, 8.4), constrained_layout=True)
    image = None
    for ax, (title, img, cm, scaled) in zip(axes.flat, panels):
        shown = ax.imshow(img, cmap=cm, vmin=0 if scaled else None, vmax=DEPTH.disparities - 1 if scaled else None,
                          interpolation="nearest")
        image = shown if scaled else image
        ax.set_title(title, fontsize=9)
        ax.axis("off")
    bar = fig.colorbar(image, ax=axes, shrink=0.8, label="disparity (buffer pixels); grey: invalid / no truth")
    bar.set_ticks(range(0, DEPTH.disparities, 8))
    fig.suptitle("Motorcycle, 400 x 300 x 5-bit buffers, D = 64", fontsize=11)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=80)
    plt.close(fig)


def main():
    from golden.capture import capture_frame as capture
    from sim.testbed.scene import render_pair
    left, right = motorcycle_buffers()
    t = min(_timed(lambda: depth_map(left, right, DEPTH)) for _ in range(3))
    plan = schedule(SENSOR, DEPTH)
    passes = SENSOR.buf_height + median_block(DEPTH).ROW_LAG
    per_map = 4 * SENSOR.buf_width + passes * (plan.pass_clocks + 3) + tag_delay(DEPTH)
    lines = ["## Depth engine: the two builds", ""]
    lines += builds_section()
    lines += ["## Depth engine (census 7x7, SGM horizontal + vertical, P1 16, P2 96, WTA, equiangular 1/16 pixel, "
             f"uniqueness {DEPTH.uniqueness}, 3x3 median)", "",
             f"golden model, full 400 x 300 map: {t:.2f} s (best of 3)",
             f"RTL schedule: {plan.steps} steps x {plan.step_clocks} clocks + {plan.drain_clocks} per row pass = "
             f"{plan.pass_clocks + 3} clocks (1080p: 4,400 clocks per buffer row at 2x); whole map with every read "
             f"granted: {per_map:,} pixel clocks of the 2,475,000 in a 1080p60 frame (the row-tag samples: "
             f"{tag_delay(DEPTH)} of them)", ""]
    truth_right = motorcycle_truth("right")
    rows = evaluate(left, right, truth_right)
    lines += table("Motorcycle, right view (ground truth made from Middlebury's left map)", rows)
    lines += confidence("Motorcycle", left, right, truth_right)
    lines += table("Motorcycle, mirrored pair, left view (Middlebury's own map)",
                   evaluate(left, right, motorcycle_truth("left"), mirror=True))
    scenes, rig = synthetic_scenes()
    for name, scene in scenes.items():
        l_rgb, r_rgb = render_pair(scene, rig)
        sl, sr = capture(l_rgb, SENSOR).astype(np.int64), capture(r_rgb, SENSOR).astype(np.int64)
        truth = scene_truth(scene, rig)
        lines += table(f"Synthetic: {name}", evaluate(sl, sr, truth))
        lines += confidence(name.split(" (")[0], sl, sr, truth)
    png = OUT_DIR / "depth_motorcycle.png"
    picture(right, truth_right, rows, png)
    lines.append(f"picture: {png}")
    text = "\n".join(lines)
    print(text)
    (OUT_DIR / "depth.md").write_text(text + "\n")


def builds_section():
    """The builds table, the goals, and the lever table when the goals are not met."""
    from bench.bench_depth_levers import levers_800
    from bench.depth_builds import BUILDS, builds_table, goal_lines, pairs
    by_geometry = {}                # builds on the same buffers share their pairs
    for build in BUILDS:
        if build.geometry not in by_geometry:
            by_geometry[build.geometry] = pairs(build)
    pairs_of_build = {build: by_geometry[build.geometry] for build in BUILDS}
    lines, results = builds_table(pairs_of_build)
    goals, met = goal_lines(results)
    lines += goals
    if not met:
        lines += levers_800(pairs_of_build[BUILDS[1]])
    return lines


def _timed(fn):
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


if __name__ == "__main__":
    main()
