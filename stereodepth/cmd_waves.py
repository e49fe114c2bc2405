"""``stereodepth waves``: a VCD window of the display path and a GTKWave save file that opens it.

Simulated in Amaranth's simulator; see :func:`sim.testbench.display.write_display_waves` for the window.
"""

from pathlib import Path

from . import cmd_display
from .errors import prepare_out_dir
from .outputs import RunOutputs


def add_arguments(parser):
    parser.add_argument("--mode", choices=("1080p", "small"), default="1080p",
                        help="video mode: 1080p (CEA-861 1920x1080p60, default) or small (112x52 test mode)")
    parser.add_argument("--out", type=Path, default=cmd_display.DEFAULT_OUT,
                        help="output directory (default build/display)")
    parser.add_argument("--lines", type=int, default=None, metavar="N",
                        help="lines in the window, which starts at the last active line (default: up to two "
                             "lines after the vsync pulse)")


def run(args):
    from sim.testbench.display import wave_window
    timing = cmd_display.modes()[args.mode]
    out = prepare_out_dir(args.out)
    lines = cmd_display.check_wave_lines(args.lines, timing)
    outputs = RunOutputs(out, ("display.vcd", "display.gtkw")).start()
    start, clocks = wave_window(timing, lines)
    print(f"display path, {timing.h_active}x{timing.v_active}: {clocks:,} pixel clocks from line {start[1]} "
          f"in Amaranth's simulator ...")
    files = cmd_display.write_waves(timing, outputs, lines)
    cmd_display.print_outputs(files)
    return 0
