"""Birchfield-Tomasi's sampling-insensitive dissimilarity as the AD term of the 800 x 600 build (``ad_sampling``
"bt_left": the left image interpolated, or "bt": the symmetric form, ``DEPTH_800``'s; golden/depth.py), at the clip
and shift 16 >> 1 and 32 >> 2, against the plain AD term |I_R - I_L| and against no AD term: bench depth's pairs (the
motorcycle's bad > 0.5 / 1 / 2 and density against the goals, bad > 2 of the synthetic scenes) and the test bed
(bench testbed's readings, every finish: the worst |error| over the 12 distances of table 4.2 against the goals, and
the misses among 26 distances, 0.50 .. 1.50 m every 5 cm and 2.90 .. 3.10 m, x 3 finishes). Golden models only.

Run: ``python -m bench depth_bt`` (every variant, the pairs and the test bed: about half an hour of CPU);
``--variants WORD ...`` for the variants whose name holds a WORD; ``--pairs`` or ``--testbed`` for one half.
"""

import argparse
import dataclasses

from spec.depth import DEPTH_800

#: The variants: (name, config); every other constant DEPTH_800's.
VARIANTS = (("AD 16 >> 1", dataclasses.replace(DEPTH_800, ad_sampling="pixel")),
            ("no AD term", dataclasses.replace(DEPTH_800, ad_clip=0, ad_shift=0, ad_sampling="pixel")),
            ("BT left 16 >> 1", dataclasses.replace(DEPTH_800, ad_sampling="bt_left")),
            ("BT 16 >> 1 (DEPTH_800)", DEPTH_800),
            ("BT left 32 >> 2", dataclasses.replace(DEPTH_800, ad_sampling="bt_left", ad_clip=32, ad_shift=2)),
            ("BT 32 >> 2", dataclasses.replace(DEPTH_800, ad_sampling="bt", ad_clip=32, ad_shift=2)))
#: bench depth's synthetic scenes, in the order of its pairs.
SCENES = ("textured planes", "test-bed cards on white", "card at 0.35 m")
#: The test bed's extra distances: every 5 cm in the 1 % range and around 3 m.
TALLY_DISTANCES_M = tuple(round(0.5 + 0.05 * k, 2) for k in range(21)) + (2.9, 2.95, 3.0, 3.05, 3.1)


def pair_cells(config):
    """{pair name: (bad > 0.5, bad > 1, bad > 2, mae, density)} of ``config`` on bench depth's pairs."""
    from bench.depth_builds import BUILDS, engine, pairs
    from sim.analysis.truth import error_figures
    build = BUILDS[1]
    return {name: error_figures(*engine(build, left, right, config), truth)
            for name, left, right, truth in pairs(build)}


def pair_line(name, figures):
    from bench.depth_builds import GOALS
    (g05, g1, g2), g_density = GOALS
    b05, b1, b2, _, density = figures["motorcycle"]
    met = b05 <= g05 and b1 <= g1 and b2 <= g2 and density >= g_density
    others = " | ".join(f"{100 * f[2]:.2f}" for pair, f in figures.items() if pair != "motorcycle")
    return (f"| {name} | {100 * b05:.1f} / {100 * b1:.1f} / {100 * b2:.1f}, {100 * density:.1f} "
            f"({'met' if met else 'NOT met'}) | {others} |")


def testbed_cells(config):
    """Per finish: (worst |error| 0.5-1.5 m, met, at 3 m, met) over the 12 table distances; misses among the 26
    tally distances x 3 finishes; [(finish, distance, readout)] of the misses."""
    from bench.bench_testbed import GOALS
    from sim.testbed.experiment import THESIS_DISTANCES_M, engine_point
    from sim.testbed.scene import FINISHES
    from spec.sensor import SENSOR_800
    goals = GOALS["800"]
    worst, misses = {}, []
    for finish in FINISHES:
        readings = {z: engine_point(z, None, geometry=SENSOR_800, config=config, finish=finish)
                    for z in sorted(set(THESIS_DISTANCES_M) | set(TALLY_DISTANCES_M))}
        cells = []
        for (lo, hi), limit in goals:
            inside = [readings[z] for z in THESIS_DISTANCES_M if lo <= z <= hi]
            error = max(abs(r.error) if r.error is not None else float("inf") for r in inside)
            cells.append((error, all(r.within(limit) for r in inside)))
        worst[finish] = cells
        for z in TALLY_DISTANCES_M:
            limit = goals[0][1] if z <= goals[0][0][1] else goals[1][1]      # 1 % to 1.5 m, 2 % around 3 m
            if not readings[z].within(limit):
                misses.append((finish, z, readings[z].readout))
    return worst, misses


def testbed_line(name, worst, misses):
    cells = " | ".join(", ".join(f"{100 * e:.1f}{'' if ok else ' (miss)'}" for e, ok in worst[f]) for f in worst)
    listed = "; ".join(f"{f} {z:.2f} m: {text.strip()}" for f, z, text in misses)
    return f"| {name} | {cells} | {len(misses)} of {3 * len(TALLY_DISTANCES_M)} ({listed}) |"


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m bench depth_bt", description=__doc__.split("\n\n")[0])
    parser.add_argument("--variants", nargs="+", metavar="WORD", help="only the variants whose name holds a WORD")
    part = parser.add_mutually_exclusive_group()
    part.add_argument("--pairs", action="store_true", help="bench depth's pairs only")
    part.add_argument("--testbed", action="store_true", help="the test bed only")
    args = parser.parse_args(argv or [])
    chosen = [(n, c) for n, c in VARIANTS if not args.variants or any(w in n for w in args.variants)]
    if not chosen:
        raise SystemExit(f"no variant holds {' or '.join(args.variants)}; variants: "
                         f"{', '.join(n for n, _ in VARIANTS)}")
    if not args.testbed:
        print("| variant | motorcycle bad > 0.5 / 1 / 2 %, density % (goals 17 / 13.5 / 11, 97) | bad > 2 %: "
              + " | ".join(SCENES) + " |")
        print("|---|---|" + "---|" * len(SCENES))
        for name, config in chosen:
            print(pair_line(name, pair_cells(config)), flush=True)
    if not args.pairs:
        print("| variant | solid: worst 0.5-1.5 m, 3 m (%) | edged | textured | test bed misses (26 distances x 3 "
              "finishes) |")
        print("|---|---|---|---|---|")
        for name, config in chosen:
            print(testbed_line(name, *testbed_cells(config)), flush=True)


if __name__ == "__main__":
    main()
