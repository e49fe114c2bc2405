"""``python -m sim.formal [NAME...] [--slow] [-j N]`` (``make formal``): prove every harness, print the table.

Exit status 1 if a proof fails, a cover is unreachable or a tool is missing; each failure has a one-line summary
naming the property and its counterexample VCD under build/formal/<harness>/.
"""

import argparse
import sys
import time
from concurrent.futures import ProcessPoolExecutor

from sim.formal.runner import check, format_table
from sim.formal.engines import FormalToolError

from sim.formal.registry import DEFAULT, SLOW


def _run(name):
    factories = {**DEFAULT, **SLOW}
    try:
        return name, check(factories[name]()), None
    except FormalToolError as exc:
        return name, None, str(exc)


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m sim.formal", description=__doc__.splitlines()[0])
    parser.add_argument("names", nargs="*", metavar="NAME", help=f"harnesses (default: all): {', '.join(DEFAULT)}")
    parser.add_argument("--slow", action="store_true", help=f"also the slow full-size ones: {', '.join(SLOW)}")
    parser.add_argument("-j", "--jobs", type=int, default=2, help="proofs run at once (default 2)")
    args = parser.parse_args(argv)
    names = args.names or [*DEFAULT, *(SLOW if args.slow else ())]
    unknown = [n for n in names if n not in DEFAULT and n not in SLOW]
    if unknown:
        parser.error(f"no harness {', '.join(unknown)}; available: {', '.join([*DEFAULT, *SLOW])}")
    start = time.perf_counter()
    with ProcessPoolExecutor(max_workers=max(1, args.jobs)) as pool:
        results = list(pool.map(_run, names))
    reports = [r for _, r, _ in results if r is not None]
    print(format_table(reports))
    print(f"\n{sum(r.property_count for r in reports)} properties "
          f"({sum(len(g.names) for r in reports for g in r.groups if g.bound is None)} unbounded), "
          f"{sum(len(r.covers) for r in reports)} covers, {time.perf_counter() - start:.0f} s wall clock")
    ok = True
    for name, report, error in results:
        if error is not None:
            print(f"ERROR {name}: {error}")
            ok = False
        else:
            for line in report.lines():
                if not line.startswith("PASS"):
                    print(line)
            ok &= report.ok
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
