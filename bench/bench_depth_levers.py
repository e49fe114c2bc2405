"""Lever study for the depth engine (docs/depth.md): what each change of the golden model buys, measured before it is
built. NumPy only (golden/depth.py's stages), on the motorcycle pair and the synthetic scenes of bench depth.

Levers:

* sub-pixel interpolation on the summed path costs S(d* - 1), S(d*), S(d* + 1) of the raw winner: parabola
  (a - c) / (2 (a + c - 2 b)) or equiangular (a - c) / (2 (max(a, c) - b)), rounded to 1/16, before the
  median (the RTL's order: the median then sorts sub-pixel codes), beside the parabola after the median on the
  median's integer code (needs the whole cost volume after the median: not buildable, shown for reference);
* a third aggregation path (right to left along the row) and what it costs: its block RAM is counted from the
  buffers it needs (a row of costs to replay backwards, double-buffered), its logic is one more path stage;
* confidence measures, each applied to the raw winner before the median (invalid raw codes then go through
  the median): uniqueness (second-best S away from d* +- 1 against S*), the cost curve's sharpness
  (min(a, c) - b, free with the sub-pixel stage's inputs), a left-right check (a second, left-referenced map);
  bad > 2 among the valid pixels against density at a few thresholds;
* penalties P1 / P2;
* for the 800 x 600 engine without its quality options (``DEPTH_800_BASE``, :func:`levers_800`): a third and a
  fourth path, the confidence threshold.

Figures: bad > 0.5 / 1 / 2 px over every pixel with a truth (invalid counts bad), mean absolute error of the
valid pixels, density. Run: ``python -m bench depth_levers``; writes build/bench/depth_levers.md.
"""

import numpy as np

from bench.bench_depth import motorcycle_buffers, synthetic_scenes
from golden.capture import capture_frame
from golden.depth import matching_cost, median3x3, path_cost
from sim.analysis.truth import error_figures, motorcycle_truth, scene_truth
from sim.runners import build_dir
from spec.depth import DEPTH
from spec.sensor import SENSOR

OUT_DIR = build_dir("bench")
FRACTION = 16


def pairs():
    """[(name, left, right, truth)]: the motorcycle (right view) and the synthetic scenes."""
    from sim.testbed.scene import render_pair
    left, right = motorcycle_buffers()
    out = [("motorcycle", left, right, motorcycle_truth("right"))]
    scenes, rig = synthetic_scenes()
    for name, scene in scenes.items():
        l_rgb, r_rgb = render_pair(scene, rig)
        out.append((name.split(" (")[0], capture_frame(l_rgb, SENSOR).astype(np.int64),
                    capture_frame(r_rgb, SENSOR).astype(np.int64), scene_truth(scene, rig)))
    return out


def _winner(total, max_cost, config=DEPTH):
    d = np.argmin(total, axis=0)
    best = np.take_along_axis(total, d[None], axis=0)[0]
    return d, best, (best <= max_cost) & (d != config.disparities - 1)


def _neighbours(total, d):
    D = total.shape[0]
    a = np.take_along_axis(total, np.clip(d - 1, 0, D - 1)[None], axis=0)[0].astype(np.int64)
    b = np.take_along_axis(total, d[None], axis=0)[0].astype(np.int64)
    c = np.take_along_axis(total, np.clip(d + 1, 0, D - 1)[None], axis=0)[0].astype(np.int64)
    return a, b, c


def offset(total, d, kind):
    """Sub-pixel offset in (-0.5, 0.5] of the winner ``d`` (0 where d = 0 or D - 1), unrounded."""
    a, b, c = _neighbours(total, d)
    inner = (d > 0) & (d < total.shape[0] - 1)
    if kind == "parabola":
        den = 2 * (a + c - 2 * b)
    elif kind == "equiangular":
        den = 2 * (np.maximum(a, c) - b)
    else:
        raise ValueError(kind)
    with np.errstate(divide="ignore", invalid="ignore"):
        off = np.where(inner & (den > 0), (a - c) / np.where(den > 0, den, 1), 0.0)
    return np.clip(off, -0.5, 0.5)


def finish(d, valid, frac=None, config=DEPTH):
    """Median of raw codes (in 1/16 pixel when ``frac`` is given), as disparities + validity."""
    if frac is None:
        codes = median3x3(np.where(valid, d, config.invalid))
        return codes.astype(np.float64), codes != config.invalid
    sub = np.where(valid, d * FRACTION + np.floor(frac * FRACTION + 0.5).astype(np.int64),
                   config.invalid * FRACTION)
    codes = median3x3(sub)
    return codes / FRACTION, codes != config.invalid * FRACTION


def row(name, disparity, valid, truth):
    b05, b1, b2, mae, density = error_figures(disparity, valid, truth)
    return f"| {name} | {100 * b05:.1f} | {100 * b1:.1f} | {100 * b2:.1f} | {mae:.2f} | {100 * density:.1f} |"


def among_valid(disparity, valid, truth):
    known = np.isfinite(truth) & valid
    err = np.abs(disparity[known] - truth[known])
    return float(np.mean(err > 2)) if err.size else float("nan"), float(valid[np.isfinite(truth)].mean())


def paths(cost, config):
    return tuple(path_cost(cost, p, config) for p in ("left_to_right", "top_to_bottom", "right_to_left"))


def second_best(total, d):
    """Smallest S at |d' - d| >= 2."""
    D = total.shape[0]
    idx = np.arange(D)[:, None, None]
    masked = np.where(np.abs(idx - d[None]) >= 2, total, np.iinfo(np.int32).max)
    return masked.min(axis=0)


def left_map(left, right, config):
    """The left-referenced integer winner (the engine on the mirrored, swapped pair, mirrored back)."""
    cost = matching_cost(right[:, ::-1], left[:, ::-1], config)
    h, v, _ = paths(cost, config)
    d, _, valid = _winner(h + v, config.max_cost, config)
    return d[:, ::-1], valid[:, ::-1]


def study(name, left, right, truth, lines):
    config = DEPTH
    cost = matching_cost(left, right, config)
    h, v, rl = paths(cost, config)
    total = h + v
    d, best, valid = _winner(total, config.max_cost)
    lines += [f"### {name}", "", "| lever | bad > 0.5 % | bad > 1 % | bad > 2 % | MAE px | density % |",
              "|---|---|---|---|---|---|"]
    lines.append(row("today: integer, 2 paths", *finish(d, valid), truth))
    for kind in ("parabola", "equiangular"):
        lines.append(row(f"{kind}, 1/16, before the median", *finish(d, valid, offset(total, d, kind)), truth))
    md, mv = finish(d, valid)
    mdi = np.where(mv, md, 0).astype(np.int64)
    lines.append(row("parabola after the median (not buildable)",
                     np.where(mv, mdi + offset(total, mdi, "parabola"), 0), mv, truth))
    total3 = total + rl
    d3, _, valid3 = _winner(total3, config.max_cost * 3 // 2)
    lines.append(row("3 paths (+ right to left), max_cost 180", *finish(d3, valid3), truth))
    lines.append(row("3 paths + parabola", *finish(d3, valid3, offset(total3, d3, "parabola")), truth))
    for p1, p2 in ((8, 64), (16, 64), (16, 128), (24, 96), (32, 128)):
        pc = DEPTH.__class__(**{**DEPTH.__dict__, "p1": p1, "p2": p2})
        hp, vp = path_cost(cost, "left_to_right", pc), path_cost(cost, "top_to_bottom", pc)
        dp, _, validp = _winner(hp + vp, config.max_cost)
        lines.append(row(f"P1 {p1} / P2 {p2} (integer)", *finish(dp, validp), truth))
    lines.append("")
    # Confidence: bad > 2 among valid vs density.
    frac = offset(total, d, "parabola")
    a, b, c = _neighbours(total, d)
    sharp = np.minimum(a, c) - b
    s2 = second_best(total, d)
    dl, vl = left_map(left, right, config)
    cols = np.arange(d.shape[1])[None, :]
    lr_gap = np.abs(d - dl[np.arange(d.shape[0])[:, None], np.clip(cols + d, 0, d.shape[1] - 1)])
    lines += ["| confidence (then the median) | threshold | bad > 2 among valid % | density % | bad > 2 all % |",
              "|---|---|---|---|---|"]
    measures = [("none (max_cost 120 only)", [("-", np.ones_like(valid))])]
    measures.append(("uniqueness: 64 S* <= k S2", [(f"k = {k}", 64 * best <= k * s2) for k in (64, 60, 56, 52)]))
    measures.append(("curve sharpness min(a, c) - b >= t", [(f"t = {t}", sharp >= t) for t in (1, 2, 4, 8, 12)]))
    slope = np.maximum(a, c) - b
    measures.append(("curve slope max(a, c) - b >= t", [(f"t = {t}", slope >= t) for t in (4, 8, 12, 16, 24)]))
    measures.append(("left-right |dR - dL| <= t", [(f"t = {t}", (lr_gap <= t) & vl) for t in (1, 2)]))
    for title, options in measures:
        for label, keep in options:
            fd, fv = finish(d, valid & keep, frac)
            bad, density = among_valid(fd, fv, truth)
            b2 = error_figures(fd, fv, truth)[2]
            lines.append(f"| {title} | {label} | {100 * bad:.1f} | {100 * density:.1f} | {100 * b2:.1f} |")
    lines.append("")


def costs():
    """Block RAM of the third path (arithmetic from the widths; one RAMB36 = 36 Kbit, 64 bits wide max 512)."""
    w, D, cb, pb = SENSOR.buf_width, DEPTH.disparities, DEPTH.cost_bits, DEPTH.path_bits
    row_bits = w * D * cb
    # RAMB36 as 512 x 72: a row of cost vectors, D x 6 bits wide per column.
    width_blocks = -(-D * cb // 72)
    depth_blocks = -(-w // 512)
    per_row = width_blocks * depth_blocks
    return [f"third path (right to left): a row of costs ({row_bits:,} bits = W x D x {cb}) must be replayed "
            f"backwards while the next row is written: 2 rows = {2 * per_row} RAMB36 at 512 x 72 "
            f"({width_blocks} blocks wide); plus one path stage like the horizontal one "
            f"({DEPTH.lanes} lanes x {pb}-bit L, the D x {pb}-bit next/current banks) and a third adder in the "
            f"winner's sum; the map's rows then come out a row later (the median and the reader move by one row).",
            "left-right check: a second, left-referenced cost + two-path pipeline (the census shift register "
            "mirrored, a second vertical line buffer of W x D x "
            f"{pb} bits = {-(-w * D * pb // 36864)}+ RAMB36) and a row of left winners: about the engine twice.",
            "uniqueness: a second-best tracker in the winner (S2 away from d* +- 1 across groups): one more "
            "comparator tree per group; curve sharpness: free beside the sub-pixel stage (a, b, c).", ""]


def main():
    lines = ["## Depth engine levers (golden model, NumPy)", ""]
    for name, left, right, truth in pairs():
        study(name, left, right, truth, lines)
    lines += costs()
    lines += levers_800()
    text = "\n".join(lines)
    print(text)
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    (OUT_DIR / "depth_levers.md").write_text(text + "\n")


if __name__ == "__main__":
    main()


# --- The 800 x 600 build's levers (bench depth prints them when its goals are not met) --------------------------

def levers_800(build_pairs=None):
    """Lines of a table: the 800 x 600 engine without its quality options (``DEPTH_800_BASE``) and one
    lever changed at a time, each through the golden
    model's own stages (golden.depth: paths, winner with its fit and confidence, median), on every pair of bench
    depth, errors in 400-pixel units, invalid counted bad. Levers: the third path (right to left), a fourth beside
    it (either diagonal from above, the paths a row-by-row engine can add; ``max_cost`` kept at 60 per path), the
    confidence threshold (``uniqueness`` k < 64) and ``max_cost`` off (the cheap levers beyond the golden model's
    parameters: bench/bench_depth_probe.py)."""
    import dataclasses
    from bench.depth_builds import BUILDS, pairs as build_pairs_of
    from golden.depth import winner
    from spec.depth import DEPTH_800_BASE, DEPTH_800_THREE, PATH_STEPS, THREE_PATHS
    build = BUILDS[1]
    per_path = DEPTH_800_BASE.max_cost // len(DEPTH_800_BASE.paths)
    variants = [("base: 2 paths, k = 64 (off)", DEPTH_800_BASE), ("+ third path right to left", DEPTH_800_THREE)]
    for extra in ("top_left_to_bottom_right", "top_right_to_bottom_left"):
        paths4 = THREE_PATHS + (extra,)
        variants.append((f"+ third path + fourth path {extra.replace('_', ' ')}",
                         dataclasses.replace(DEPTH_800_BASE, paths=paths4, max_cost=per_path * len(paths4))))
    variants += [(f"2 paths, uniqueness k = {k}", dataclasses.replace(DEPTH_800_BASE, uniqueness=k))
                 for k in (62, 60, 56)]
    variants.append(("2 paths, max_cost off (= sum_max: invalid only at d* = D - 1)",
                     dataclasses.replace(DEPTH_800_BASE, max_cost=DEPTH_800_BASE.sum_max)))
    results = {name: [] for name, _ in variants}
    pair_names = []
    for pair_name, left, right, truth in build_pairs or build_pairs_of(build):
        pair_names.append(pair_name)
        cost = matching_cost(left, right, DEPTH_800_BASE)
        needed = sorted({p for _, config in variants for p in config.paths}, key=list(PATH_STEPS).index)
        volumes = {p: path_cost(cost, p, dataclasses.replace(DEPTH_800_BASE, paths=tuple(needed))) for p in needed}
        del cost
        for name, config in variants:
            total = sum(volumes[p] for p in config.paths)
            raw, _ = winner(total, config)
            codes = median3x3(raw)
            disparity = codes.astype(np.float64) / config.fraction * build.to_400
            results[name].append(error_figures(disparity, codes != config.invalid, truth))
        del volumes
    lines = ["### The 800 x 600 build's levers (golden model; 400-pixel units, invalid counted bad; "
             "bad > 0.5 / 1 / 2 %, density %)", "",
             "| lever | " + " | ".join(pair_names) + " |", "|---|" + "---|" * len(pair_names)]
    for name, figures in results.items():
        cells = [f"{100 * f[0]:.1f} / {100 * f[1]:.1f} / {100 * f[2]:.1f}, {100 * f[4]:.1f}" for f in figures]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    return lines + [""]
