"""``stereodepth demo`` / ``make demo``: for now, the display path (the whole system replaces it later).

Writes ``build/demo/hdmi_frame.png`` (frame 0 of the simulated display path, rebuilt by the HDMI sink from
the CH7301C dual-edge bus on Verilator), ``build/demo/display.vcd`` and ``build/demo/display.gtkw``.
The frame-writing pieces live in :mod:`stereodepth.cmd_display` so the whole-system demo can reuse them.
"""

from pathlib import Path

from . import cmd_display

HELP = "run the simulated system -> build/demo/ (today: the display path's test pattern)"


def add_arguments(parser):
    parser.add_argument("--simulator", choices=cmd_display.SIMULATORS, default="verilator",
                        help="verilator (default; about a minute for the 1080p frame), icarus or amaranth "
                             "(both much slower at 1080p)")
    parser.add_argument("--out", type=Path, default=cmd_display.DEFAULT_OUT,
                        help="output directory (default build/demo)")


def run(args):
    args.mode = "1080p"
    args.no_waves = False
    args.wave_lines = None
    return cmd_display.run(args)
