"""The automatic depth engine on the thesis's test bed (docs/testbed.md): the distance the
centre readout shows for the table object at the 12 distances of table 4.2, against the true distance, for each
card finish of the renderer (``solid``: the thesis's plain cards; ``edged``; ``textured``).

Printed per finish: every distance's engine disparity (median of the valid sub-pixel codes over the object),
the readout and its error, then the worst error from 0.5 to 1.5 m and at 3 m against the goal (2 % and 5 %).

Run: ``python -m bench testbed`` (``--finish solid`` for one finish). Golden model (equal to the RTL bit for bit:
tests/test_depth_engine.py); thesis rig, no misalignment.
"""

import argparse

from sim.testbed.experiment import THESIS_DISTANCES_M, run_table
from sim.testbed.scene import FINISHES

#: The goal (docs/testbed.md): worst |error| over this range of distances (m) -> limit.
GOALS = (((0.5, 1.5), 0.02), ((3.0, 3.0), 0.05))


def finish_table(finish):
    """Rows (distance, engine px, readout, error) of one finish and the worst error per goal range."""
    points = run_table(THESIS_DISTANCES_M, finish=finish)
    rows = [(p.distance_m, p.engine.disparity_px, p.engine.readout, p.engine.error) for p in points]
    worst = []
    for (lo, hi), limit in GOALS:
        errors = [abs(e) if e is not None else float("inf") for z, _, _, e in rows if lo <= z <= hi]
        worst.append(((lo, hi), max(errors), limit))
    return rows, worst


def _text(value, form):
    return "-" if value is None else format(value, form)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m bench testbed", description=__doc__.split("\n\n")[0])
    parser.add_argument("--finish", choices=FINISHES, action="append", help="card finish (default: all)")
    args = parser.parse_args(argv or [])
    for finish in args.finish or FINISHES:
        rows, worst = finish_table(finish)
        print(f"finish {finish}:")
        print(f"  {'Z (m)':>6} {'engine px':>10} {'readout':>8} {'error':>7}")
        for z, px, readout, error in rows:
            print(f"  {z:6.2f} {_text(px, '10.2f')} {readout:>8} {_text(error, '+7.1%')}")
        for (lo, hi), error, limit in worst:
            where = f"{lo:.2f} m" if lo == hi else f"{lo:.2f}-{hi:.2f} m"
            print(f"  worst |error| at {where}: {error:.1%} (goal {limit:.0%}: {'met' if error <= limit else 'not met'})")


if __name__ == "__main__":
    main()
