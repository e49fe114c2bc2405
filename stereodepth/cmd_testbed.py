"""``stereodepth testbed``: the thesis's test bed (4.6) in simulation -> table 4.2 and figure 4.35.

For each distance: render the test object for both cameras (sim/testbed/scene.py), capture both through the golden
model, sweep the disparity register 0..127 (and the rectification register), find where the object's residual
in the difference image is smallest (sim/testbed/experiment.py); then the near-field case of thesis 4.6.6, fits that
explain the thesis's observed column (re-simulated with the fitted rig), and a sample of points run through
the RTL DisparitySubtractor in Amaranth's simulator, compared bit for bit. Writes into ``--out``:

* ``table.csv``: one row per distance (calculated, thesis, found, plateau, bound, fits, re-simulated fits, and
  the automatic depth engine on the same pair: the median of its sub-pixel disparities over the object, the
  centre readout it shows, that distance and its error against the true distance; and the vertical-offset
  estimator on the same pair: the offset in use after a still scene from reset, its lock frames, held);
* ``near_field.csv``: every test object at 0.25 m;
* ``fits.csv``: each model's parameters, rms and per-distance residuals;
* ``rtl_check.csv``: the RTL sample;
* ``figure_4_35.png`` (calculated vs found vs observed), ``disparity_maps.png`` (difference images at
  found - 1, found, found + 1 at 1 m, like figures 4.15-4.17) and ``near_field.png`` (figures 4.31-4.33).

Exit status: 0, or 1 when an RTL sample differs from the golden model; bad arguments: one-line error, 2.
"""

import csv
import math

import numpy as np

from .errors import UserError, prepare_out_dir
from .outputs import RunOutputs, write_atomic

#: Every file ``testbed`` writes into ``--out`` (an earlier run's are removed at the start; each is written under
#: its partial name and renamed when complete).
OUTPUTS = ("table.csv", "near_field.csv", "fits.csv", "rtl_check.csv", "figure_4_35.png", "disparity_maps.png",
           "near_field.png")


#: The longest distance accepted: the disparity there is 27.3 / 20 = 1.4 buffer pixels.
MAX_DISTANCE_M = 20.0


def add_arguments(parser):
    parser.add_argument("--out", default="build/testbed", metavar="DIR",
                        help="output directory (default: build/testbed)")
    parser.add_argument("--distances", nargs="+", type=float, metavar="Z",
                        help="object distances in metres (default: the thesis's 0.25 0.5 ... 3.0)")
    parser.add_argument("--rtl-samples", type=int, default=3, metavar="N",
                        help="(distance, disparity) points to run through the RTL in Amaranth's simulator and "
                             "compare bit for bit with the golden model (default 3; 0: none)")
    parser.add_argument("--supersample", type=int, default=1, metavar="K",
                        help="render with K x K samples per sensor pixel (default 1: point sampling)")
    parser.add_argument("--finish", default="solid", choices=("solid", "edged", "textured"),
                        help="how the test objects look (default solid)")
    parser.add_argument("--max-rectification", type=int, default=None, metavar="R",
                        help="sweep the rectification register 0..R (default 15; 0: fixed at 0)")
    parser.add_argument("--vertical-offset", type=float, default=0.0, metavar="ROWS",
                        help="left principal point minus right, vertically, in sensor rows (default 0)")
    parser.add_argument("--principal-offset", type=float, default=0.0, metavar="PX",
                        help="left principal point minus right, horizontally, in sensor pixels (default 0)")
    parser.add_argument("--convergence", type=float, default=0.0, metavar="DEG",
                        help="toe-in angle between the optical axes in degrees (default 0)")
    parser.add_argument("--no-fit", action="store_true",
                        help="skip re-simulating the fitted rigs (the fits themselves are always reported)")
    parser.add_argument("--quiet", action="store_true", help="print only the summary")


def _check_args(args):
    from sim.testbed.experiment import MAX_DISPARITY, MAX_RECTIFICATION, THESIS_DISTANCES_M, exact_disparity

    distances = list(THESIS_DISTANCES_M if args.distances is None else args.distances)
    min_z = exact_disparity(1.0) / MAX_DISPARITY
    for z in distances:
        if not math.isfinite(z) or z < min_z or z > MAX_DISTANCE_M:
            raise UserError(f"distance {z} m is outside {min_z:.3f}..{MAX_DISTANCE_M:g} m (the disparity register "
                            f"reaches {MAX_DISPARITY} pixels, i.e. {min_z:.3f} m)")
    if len(set(distances)) != len(distances):
        raise UserError("each distance may be given once")
    if not 0 <= args.rtl_samples <= 3 * len(distances):
        raise UserError(f"--rtl-samples must be 0..{3 * len(distances)} (three disparities per distance)")
    if not 1 <= args.supersample <= 8:
        raise UserError("--supersample must be 1..8")
    max_r = MAX_RECTIFICATION if args.max_rectification is None else args.max_rectification
    if not 0 <= max_r <= 127:
        raise UserError("--max-rectification must be 0..127 (a 7-bit register)")
    for name, value, limit in (("--vertical-offset", args.vertical_offset, 400),
                               ("--principal-offset", args.principal_offset, 400),
                               ("--convergence", args.convergence, 10)):
        if not math.isfinite(value) or abs(value) > limit:
            raise UserError(f"{name} must be a number within +-{limit}")
    return sorted(distances), max_r


def _write_csv(path, header, rows):
    def write(partial):
        with open(partial, "w", newline="") as f:
            writer = csv.writer(f)
            writer.writerow(header)
            writer.writerows(rows)
    write_atomic(path, write)


def _fmt(value, digits=3):
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.{digits}f}"
    return value


def _rtl_samples(points, n):
    """{point index: [(disparity, rectification)]}: n samples, distances spread over the series from the
    farthest (the cheapest to simulate: fewest rows) to the nearest, disparities found, found + 1, found - 1
    in turn (clamped to 0..127; duplicates dropped)."""
    picks = {}
    per = len(points)
    for k in range(n):
        if n <= per:
            idx, delta = per - 1 - round(k * (per - 1) / max(1, n - 1)), (0, 1, -1)[k % 3]
        else:
            idx, delta = k % per, (0, 1, -1)[k // per]
        p = points[idx]
        setting = (min(127, max(0, p.found + delta)), p.alignment.rectification)
        if setting not in picks.setdefault(idx, []):
            picks[idx].append(setting)
    return picks


def run(args):
    distances, max_r = _check_args(args)
    out = prepare_out_dir(args.out)
    RunOutputs(out, OUTPUTS).start()

    from sim.testbed import experiment as tb
    from sim.testbed.scene import StereoRig, object_footprint, make_object

    say = (lambda *a: None) if args.quiet else print
    rig = StereoRig(principal_offset_px=args.principal_offset, vertical_offset_px=args.vertical_offset,
                    convergence_deg=args.convergence)
    kw = dict(supersample=args.supersample, max_rectification=max_r, finish=args.finish)
    misaligned = bool(args.principal_offset or args.vertical_offset or args.convergence)

    say(f"test bed: {len(distances)} distances, rig offsets: principal {args.principal_offset} px, vertical "
        f"{args.vertical_offset} rows, toe-in {args.convergence} deg")
    say(f"{'Z (m)':>6} {'object':>16} {'eq.2.1':>7} {'thesis':>6} {'obs.':>5} {'found':>5} {'plateau':>9} {'rect':>4}"
        f" {'engine':>7} {'shown':>7} {'error':>7} {'auto':>4}")

    def show(p):
        say(_show_line(p, tb))

    table = tb.run_table(distances, rig, progress=show, **kw)
    say("near field (thesis 4.6.6):")
    near = tb.run_near_field(tb.NEAR_FIELD_DISTANCE_M, rig, **kw)
    for p in near:
        show(p)

    # Fits to the thesis's observed column, and the test bed re-run with each fitted rig.
    fits = [tb.fit_observed(model) for model in tb.FIT_MODELS]
    resim = {}
    if not args.no_fit:
        for fit in fits:
            fit_rig, true_z = tb.fitted_rig_and_distance(fit, rig)
            say(f"re-simulating with the '{fit.model}' fit ...")
            resim[fit.model] = [tb.run_point(z, tb.table_object_name(z, fit_rig), fit_rig,
                                             object_distance_m=true_z(z), **kw).found
                                for z in tb.THESIS_DISTANCES_M]

    # RTL sample.
    rtl_rows = []
    rtl_ok = True
    for idx, settings in _rtl_samples(table, args.rtl_samples).items():
        p = table[idx]
        scene = make_object(p.object_name, p.distance_m, finish=args.finish)
        left, right = tb.capture_pair(scene, rig, supersample=args.supersample)
        footprint = object_footprint(scene, rig)
        say(f"RTL: {p.distance_m} m, (disparity, rectification) {settings} ...")
        for check in tb.rtl_crosscheck(left, right, footprint, settings):
            curve = tb.disparity_curve(left, right, footprint, check.rectification)
            sweep_value = int(curve.residual[check.disparity])
            ok = check.ok and sweep_value == check.rtl_residual
            rtl_ok &= ok
            rtl_rows.append([f"{p.distance_m:.2f}", p.object_name, check.disparity, check.rectification,
                             f"{check.rows[0]}..{check.rows[1] - 1}", check.pixels, check.mismatches,
                             check.rtl_residual, check.golden_residual, sweep_value, "yes" if ok else "NO"])

    _write_outputs(out, table, near, fits, resim, rtl_rows, rig)
    _figures(out, table, near, fits, resim, rig, kw)

    # Summary.
    say("")
    bound = [p for p in table if not p.within_bound]
    print(f"stereodepth testbed: {len(table)} distance(s); found within [floor, ceil] of the expected disparity: "
          f"{len(table) - len(bound)}/{len(table)}" + ("" if not misaligned else " (misaligned rig)"))
    _auto_summary(table, rig)
    for fit in fits:
        extra = ", ".join(f"{k}={v:.4g}" for k, v in fit.params.items())
        sim = resim.get(fit.model)
        simtxt = ""
        if sim is not None:
            diff = np.array(tb.THESIS_OBSERVED_PX) - np.array(sim)
            simtxt = f"; re-simulated: max |observed - found| = {int(np.max(np.abs(diff)))} px"
        print(f"  fit {fit.model:>16}: rms {fit.rms:.2f} px, max {fit.max_abs:.2f} px ({extra}){simtxt}")
    if rtl_rows:
        print(f"  RTL sample: {len(rtl_rows)} points, {'all bit-exact' if rtl_ok else 'MISMATCH'}")
    print(f"  wrote {out}/table.csv, near_field.csv, fits.csv, rtl_check.csv, figure_4_35.png, "
          f"disparity_maps.png, near_field.png")
    return 0 if rtl_ok else 1


def _auto_summary(table, rig):
    """How often the automatic rectification found the rig's vertical offset (in buffer rows, rounded)."""
    from spec.sensor import SENSOR
    truth = round(rig.vertical_offset_px / SENSOR.scale)
    right = [p for p in table if p.auto.offset == truth]
    held = sum(p.auto.held and p.auto.offset != truth for p in table)
    lock = max((p.auto.lock_frames for p in right), default=0)
    print(f"  automatic rectification: offset {truth:+d} buffer rows in use at {len(right)}/{len(table)} distances "
          f"(each within {lock} frames of a still scene from reset); no clear minimum, the reset's 0 kept: {held}; "
          f"wrong: {len(table) - len(right) - held}")


def _show_line(p, tb):
    """One printed row: the sweep's columns and the depth engine's (sub-pixel disparity, readout, error)."""
    thesis = dict(zip(tb.THESIS_DISTANCES_M, zip(tb.THESIS_CALCULATED_PX, tb.THESIS_OBSERVED_PX)))
    calc, obs = thesis.get(round(p.distance_m, 6), ("", ""))
    e = p.engine
    return (f"{p.distance_m:6.2f} {p.object_name:>16} {p.exact_px:7.2f} {calc:>6} {obs:>5} {p.found:5d} "
            f"{str(p.plateau[0]) + '..' + str(p.plateau[1]):>9} {p.alignment.rectification:4d} "
            f"{'-' if e.disparity_px is None else f'{e.disparity_px:.2f}':>7} {e.readout:>7} "
            f"{'-' if e.error is None else f'{100 * e.error:+.1f}%':>7} {_auto_text(p.auto):>4}")


def _auto_text(auto):
    """The estimator's offset in use, with ``h`` when the last frame had no clear minimum (offset held)."""
    return f"{auto.offset:+d}{'h' if auto.held else ''}"


def _point_row(p):
    lo, hi = p.plateau
    return [f"{p.distance_m:.2f}", p.object_name, _fmt(p.exact_px), _fmt(p.expected_px), p.found, lo, hi,
            _fmt(p.found - p.expected_px), "yes" if p.within_bound else "no", p.alignment.rectification,
            p.alignment.disparity_sweep.minimum, p.alignment.disparity_sweep.region_pixels,
            "" if p.engine.disparity_px is None else f"{p.engine.disparity_px:.4f}", p.engine.readout.strip(),
            "" if p.engine.shown_m is None else f"{p.engine.shown_m:.2f}",
            "" if p.engine.error is None else f"{100 * p.engine.error:.2f}", p.auto.offset, p.auto.lock_frames,
            "yes" if p.auto.held else "no"]


_POINT_HEADER = ["distance_m", "object", "calculated_exact_px", "expected_px", "found_px", "plateau_lo_px",
                 "plateau_hi_px", "found_minus_expected_px", "within_bound", "rectification", "residual_min",
                 "region_pixels", "engine_disparity_px", "engine_readout", "engine_shown_m", "engine_error_pct",
                 "auto_rectification", "auto_lock_frames", "auto_held"]


def _write_outputs(out, table, near, fits, resim, rtl_rows, rig):
    from sim.testbed import experiment as tb

    thesis = dict(zip(tb.THESIS_DISTANCES_M, zip(tb.THESIS_CALCULATED_PX, tb.THESIS_OBSERVED_PX)))
    fit_by_z = {f.model: dict(zip(tb.THESIS_DISTANCES_M, f.predicted)) for f in fits}
    sim_by_z = {m: dict(zip(tb.THESIS_DISTANCES_M, v)) for m, v in resim.items()}
    header = _POINT_HEADER[:3] + ["thesis_calculated_px", "thesis_observed_px"] + _POINT_HEADER[3:]
    for f in fits:
        header += [f"fit_{f.model}_px", f"resim_{f.model}_px"]
    rows = []
    for p in table:
        z = round(p.distance_m, 6)
        calc, obs = thesis.get(z, ("", ""))
        base = _point_row(p)
        row = base[:3] + [calc, obs] + base[3:]
        for f in fits:
            row += [_fmt(fit_by_z[f.model].get(z)), sim_by_z.get(f.model, {}).get(z, "")]
        rows.append(row)
    _write_csv(out / "table.csv", header, rows)

    near_header = _POINT_HEADER + ["object_width_m", "common_field_width_m", "fits_common_field"]
    from sim.testbed.scene import make_object
    near_rows = []
    for p in near:
        width = make_object(p.object_name, p.distance_m).size_m[0]
        common = rig.common_field_width_m(p.distance_m)
        near_rows.append(_point_row(p) + [_fmt(width), _fmt(common), "yes" if width < common else "no"])
    _write_csv(out / "near_field.csv", near_header, near_rows)

    fit_header = ["model", "parameters", "rms_px", "max_abs_px"] + [f"residual_{z:.2f}m" for z in
                                                                      tb.THESIS_DISTANCES_M]
    fit_rows = []
    for f in fits:
        params = "; ".join(f"{k}={v:.6g}" for k, v in f.params.items())
        fit_rows.append([f.model, params, _fmt(f.rms), _fmt(f.max_abs)] + [_fmt(float(r), 2) for r in f.residual])
        if f.model in resim:
            diff = np.array(tb.THESIS_OBSERVED_PX) - np.array(resim[f.model])
            fit_rows.append([f.model + " (re-simulated found)", params, _fmt(float(np.sqrt(np.mean(diff ** 2)))),
                             _fmt(float(np.max(np.abs(diff))))] + [int(d) for d in diff])
    _write_csv(out / "fits.csv", fit_header, fit_rows)

    _write_csv(out / "rtl_check.csv",
               ["distance_m", "object", "disparity", "rectification", "rows", "pixels", "mismatches",
                "rtl_residual", "golden_residual", "sweep_residual", "bit_exact"], rtl_rows)


def _levels_rgb(levels, no_data):
    from spec.display import DIFF_LEVEL_GREY, NO_DATA_RGB
    grey = np.asarray(DIFF_LEVEL_GREY, dtype=np.uint8)[levels]
    rgb = np.repeat(grey[..., None], 3, axis=-1)
    rgb[no_data] = ((NO_DATA_RGB >> 16) & 0xFF, (NO_DATA_RGB >> 8) & 0xFF, NO_DATA_RGB & 0xFF)
    return rgb


def _figures(out, table, near, fits, resim, rig, kw):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    _figure_4_35(plt, out, table, fits, resim)
    _difference_images(plt, out, table, rig, kw)
    _near_field_figure(plt, out, near, rig, kw)


def _figure_4_35(plt, out, table, fits, resim):
    """Figure 4.35: calculated, found and observed disparity against distance."""
    from sim.testbed import experiment as tb
    z = np.array([p.distance_m for p in table])
    found = np.array([p.found for p in table])
    lo = np.array([p.plateau[0] for p in table])
    hi = np.array([p.plateau[1] for p in table])
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(8, 8), sharex=True, gridspec_kw=dict(height_ratios=(3, 2)))
    zz = np.linspace(min(0.2, z.min()), max(3.1, z.max()), 300)
    ax.plot(zz, tb.exact_disparity(zz), color="0.6", lw=1, label="equation 2.1 (B f / Z / 8.8 um)")
    ax.plot(tb.THESIS_DISTANCES_M, tb.THESIS_CALCULATED_PX, "s-", color="tab:blue", ms=5,
            label="thesis: calculated")
    ax.plot(tb.THESIS_DISTANCES_M, tb.THESIS_OBSERVED_PX, "o-", color="tab:red", ms=5, label="thesis: observed")
    ax.errorbar(z, found, yerr=[found - lo, hi - found], fmt="^", color="tab:green", ms=6, capsize=3,
                label="simulated: found (plateau)")
    best = min(fits, key=lambda f: f.rms)
    ax.plot(tb.THESIS_DISTANCES_M, best.predicted, "--", color="tab:purple",
            label=f"fit '{best.model}' (rms {best.rms:.2f} px)")
    if best.model in resim:
        ax.plot(tb.THESIS_DISTANCES_M, resim[best.model], "x", color="tab:purple", ms=7,
                label=f"simulated with the '{best.model}' rig: found")
    ax.set_ylabel("disparity (buffer pixels)")
    ax.set_title("Thesis figure 4.35 reproduced: disparity at which the object disappears")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax2.axhspan(-1, 1, color="tab:green", alpha=0.1, label="+-1 px (1/16-downscale bound)")
    ax2.plot(z, found - np.array([p.expected_px for p in table]), "^", color="tab:green",
             label="simulated found - expected")
    for f, marker in zip(fits, "os+"):
        ax2.plot(tb.THESIS_DISTANCES_M, f.residual, marker + ":", ms=5, mfc="none",
                 label=f"observed - fit '{f.model}'")
    ax2.axhline(0, color="0.5", lw=0.8)
    ax2.set_xlabel("distance Z (m)")
    ax2.set_ylabel("residual (pixels)")
    ax2.grid(alpha=0.3)
    ax2.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    write_atomic(out / "figure_4_35.png", lambda p: fig.savefig(p, dpi=110))
    plt.close(fig)


def _difference_images(plt, out, table, rig, kw):
    """Difference images at found - 1, found, found + 1 (figures 4.15-4.17), at the distance nearest 1 m."""
    from golden.disparity import difference_levels
    from sim.testbed import experiment as tb
    from sim.testbed.scene import make_object
    p = min(table, key=lambda q: abs(q.distance_m - 1.0))
    scene = make_object(p.object_name, p.distance_m, finish=kw["finish"])
    left, right = tb.capture_pair(scene, rig, supersample=kw["supersample"])
    r = p.alignment.rectification
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.4))
    for axis, d in zip(axes, (p.found - 1, p.found, p.found + 1)):
        d = min(127, max(0, d))
        axis.imshow(_levels_rgb(*difference_levels(left, right, d, r)))
        axis.set_title(f"{p.object_name} at {p.distance_m:.2f} m: disparity {d}, rectification {r}", fontsize=8)
        axis.axis("off")
    fig.tight_layout()
    write_atomic(out / "disparity_maps.png", lambda p: fig.savefig(p, dpi=100))
    plt.close(fig)


def _near_field_figure(plt, out, near, rig, kw):
    """Near field (figures 4.31-4.33): each object's residual per disparity (normalised by its region), the big
    rectangle at the smallest disparity that makes it vanish (far from its true one), the small rectangle at zero
    disparity (its two images separated) and at the found disparity."""
    from golden.disparity import difference_levels
    from sim.testbed import experiment as tb
    from sim.testbed.scene import make_object
    by_name = {q.object_name: q for q in near}
    fig = plt.figure(figsize=(13, 6.6))
    grid = fig.add_gridspec(2, 3, height_ratios=(1.1, 1))
    ax = fig.add_subplot(grid[0, :])
    for q in near:
        sweep = q.alignment.disparity_sweep
        ax.plot(sweep.values, sweep.residual / sweep.region_pixels, label=f"{q.object_name} "
                f"(found {q.found}, plateau {q.plateau[0]}..{q.plateau[1]})")
    ax.axvline(tb.exact_disparity(near[0].distance_m), color="0.5", ls="--", lw=1, label="equation 2.1")
    ax.set_xlabel("disparity register")
    ax.set_ylabel("residual / region pixels")
    ax.set_title(f"Near field, {near[0].distance_m:.2f} m (thesis 4.6.6): common field "
                 f"{100 * rig.common_field_width_m(near[0].distance_m):.1f} cm wide", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    panels = []
    if "rectangle" in by_name:
        q = by_name["rectangle"]
        panels.append((q, q.found, f"19 cm rectangle vanishes (eq. 2.1: {tb.exact_disparity(q.distance_m):.0f})"))
    if "small_rectangle" in by_name:
        q = by_name["small_rectangle"]
        panels += [(q, 0, "small rectangle: images separated"), (q, q.found, "small rectangle: found")]
    for k, (q, d, what) in enumerate(panels):
        axis = fig.add_subplot(grid[1, k])
        scene = make_object(q.object_name, q.distance_m, finish=kw["finish"])
        left, right = tb.capture_pair(scene, rig, supersample=kw["supersample"])
        axis.imshow(_levels_rgb(*difference_levels(left, right, d, q.alignment.rectification)))
        axis.set_title(f"d = {d}: {what}", fontsize=8)
        axis.axis("off")
    fig.tight_layout()
    write_atomic(out / "near_field.png", lambda p: fig.savefig(p, dpi=100))
    plt.close(fig)
