"""Run every ``bench/bench_*.py`` module's ``main()`` in turn, or only the ones named on the command line; options
after a single name go to that benchmark (``python -m bench system --cocotb``)."""

import argparse
import importlib
import pkgutil
import sys
import time
from pathlib import Path


def available():
    here = Path(__file__).resolve().parent
    return sorted(m.name for m in pkgutil.iter_modules([str(here)]) if m.name.startswith("bench_"))


def main(argv=None):
    names = available()
    parser = argparse.ArgumentParser(prog="python -m bench", description=__doc__)
    parser.add_argument("benches", nargs="*", metavar="NAME",
                        help=f"benchmarks to run (default: all): {', '.join(n[len('bench_'):] for n in names)}")
    args, options = parser.parse_known_args(argv)
    if options and len(args.benches) != 1:
        parser.error(f"options {' '.join(options)} go to one benchmark: name exactly one")
    chosen = []
    for name in args.benches or names:
        module = name if name.startswith("bench_") else f"bench_{name}"
        if module not in names:
            parser.error(f"no benchmark {name!r}; available: {', '.join(names)}")
        chosen.append(module)
    failed = []
    for module in chosen:
        print(f"== {module} ==", flush=True)
        start = time.perf_counter()
        try:
            bench_main = importlib.import_module(f"bench.{module}").main
            bench_main(options) if options else bench_main()
        except Exception as exc:        # noqa: BLE001 - one failing bench must not hide the others' figures
            failed.append(module)
            print(f"{module} failed: {type(exc).__name__}: {exc}", file=sys.stderr)
        print(f"== {module}: {time.perf_counter() - start:.1f} s ==\n", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
