"""The automatic depth engine on the thesis's test bed (docs/testbed.md), both builds side by side: the distance the
centre readout shows for the table object at the 12 distances of table 4.2, against the true distance, for each
card finish of the renderer (``solid``: the thesis's plain cards; ``edged``; ``textured``).

Builds (bench/depth_builds.py): the thesis's (1600 x 1200 scene, one pixel of every 4 x 4 block kept, 5-bit,
400 x 300; ``DEPTH``) and the 800 x 600 one (the same scene, each buffer pixel the 8-bit mean of its 2 x 2 block;
``DEPTH_800``); ``--build 800-base`` also the 800 x 600 engine without its quality options (``DEPTH_800_BASE``).
Printed per finish and build: every distance's engine disparity (median of the valid sub-pixel
codes over the object, in the build's own buffer pixels), the readout and its error, then the worst error from
0.5 to 1.5 m and at 3 m against the build's goal: 2 % and 5 % for the thesis build, 1 % and 2 % for the 800 x 600
build (the boundary included, in exact arithmetic on the whole centimetres shown).

Run: ``python -m bench testbed`` (about a minute and a half of CPU, most of it the 800 x 600 build's 36 maps);
``--build thesis|800|800-base`` for one build, ``--finish solid`` for one finish, ``--distances Z ...`` for other distances
(the goal ranges are then judged over whatever distances fall in them). Golden models (the thesis build's engine
is equal to the RTL bit for bit: tests/test_depth_engine.py); thesis rig, no misalignment.
"""

import argparse

from bench.depth_builds import BUILDS
from sim.testbed.experiment import THESIS_DISTANCES_M, engine_table
from sim.testbed.scene import FINISHES

#: The goals (docs/testbed.md), per build: (distance range in m, worst |error| allowed) for the range 0.5-1.5 m
#: and for 3 m.
GOALS = {"thesis": (((0.5, 1.5), 0.02), ((3.0, 3.0), 0.05)),
         "800": (((0.5, 1.5), 0.01), ((3.0, 3.0), 0.02)),
         "800-base": (((0.5, 1.5), 0.01), ((3.0, 3.0), 0.02))}
#: The builds by their option name.
TESTBED_BUILDS = {"thesis": BUILDS[0], "800": BUILDS[1], "800-base": BUILDS[2]}
#: The builds printed when none is named.
DEFAULT_BUILDS = ("thesis", "800")


def build_table(build_name, finish, distances=THESIS_DISTANCES_M):
    """[EngineReading] of ``build_name`` (a key of :data:`TESTBED_BUILDS`) at ``distances`` for ``finish``."""
    build = TESTBED_BUILDS[build_name]
    return engine_table(distances, geometry=build.geometry, config=build.config, finish=finish)


def goal_checks(build_name, readings):
    """[(range, worst |error| or None when no distance falls in it, limit, met)] of ``readings`` against the build's
    goals; a reading without a distance shown is an infinite error."""
    checks = []
    for (lo, hi), limit in GOALS[build_name]:
        inside = [r for r in readings if lo <= r.true_m <= hi]
        if not inside:
            checks.append(((lo, hi), None, limit, None))
            continue
        worst = max(abs(r.error) if r.error is not None else float("inf") for r in inside)
        checks.append(((lo, hi), worst, limit, all(r.within(limit) for r in inside)))
    return checks


def _text(value, form):
    """``value`` in ``form`` (a width first, then the rest), or a dash of that width."""
    return format("-", f">{form.lstrip('+').split('.')[0]}") if value is None else format(value, form)


def finish_lines(finish, tables):
    """Lines of one finish's table: ``tables`` maps each build name to its readings (same distances)."""
    names = list(tables)
    head = "  " + f"{'Z (m)':>6}" + "".join(f" | {name + ' px':>10} {'readout':>8} {'error':>7}" for name in names)
    lines = [f"finish {finish}:", head]
    for row in zip(*tables.values()):
        cells = "".join(f" | {_text(r.disparity_px, '10.2f')} {r.readout:>8} {_text(r.error, '+7.1%')}" for r in row)
        lines.append(f"  {row[0].true_m:6.2f}{cells}")
    for name in names:
        for (lo, hi), worst, limit, met in goal_checks(name, tables[name]):
            where = f"{lo:.2f} m" if lo == hi else f"{lo:.2f}-{hi:.2f} m"
            verdict = "no distance in range" if met is None else f"{worst:.1%} (goal {limit:.0%}: " \
                f"{'met' if met else 'not met'})"
            lines.append(f"  {name}: worst |error| at {where}: {verdict}")
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m bench testbed", description=__doc__.split("\n\n")[0])
    parser.add_argument("--finish", choices=FINISHES, action="append", help="card finish (default: all)")
    parser.add_argument("--build", choices=tuple(TESTBED_BUILDS), action="append",
                        help="build (default: thesis and 800)")
    parser.add_argument("--distances", type=float, nargs="+", metavar="Z", default=THESIS_DISTANCES_M,
                        help="object distances in m (default: the 12 of table 4.2)")
    args = parser.parse_args(argv or [])
    if not all(0 < z <= 20 for z in args.distances):
        parser.error("distances must be above 0 and at most 20 m")
    for finish in args.finish or FINISHES:
        tables = {name: build_table(name, finish, args.distances) for name in args.build or DEFAULT_BUILDS}
        print("\n".join(finish_lines(finish, tables)))


if __name__ == "__main__":
    main()
