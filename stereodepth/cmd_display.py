"""``stereodepth display``: simulate the display path alone (test pattern -> CH7301C bus -> HDMI sink -> PNG).

The simulation is ``sim/testbench/display.py``; this module parses the arguments and prints what came out.
"""

import sys
from pathlib import Path

from .errors import UserError, prepare_out_dir
from .outputs import RunOutputs
from .progress import Progress

SIMULATORS = ("verilator", "icarus", "amaranth")
OUTPUTS = ("hdmi_frame.png", "display.vcd", "display.gtkw")
DEFAULT_OUT = Path("build/display")   # not build/demo: the whole-system demo writes its own hdmi_frame.png there


def modes():
    """The video modes by command-line name."""
    from spec.video import CEA_1080P60, SMALL_TIMING
    return {"1080p": CEA_1080P60, "small": SMALL_TIMING}


def add_arguments(parser):
    parser.add_argument("--simulator", choices=SIMULATORS, default="verilator",
                        help="verilator (default, the fastest for a full 1080p frame), icarus or amaranth (both far "
                             "slower at 1080p; fine with --mode small)")
    parser.add_argument("--mode", choices=("1080p", "small"), default="1080p",
                        help="video mode: 1080p (CEA-861 1920x1080p60, default) or small (112x52 test mode)")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output directory (default build/display)")
    parser.add_argument("--no-waves", action="store_true", help="do not write the VCD and GTKWave files")
    parser.add_argument("--wave-lines", type=int, default=None, metavar="N",
                        help="lines in the VCD window, which starts at the last active line (default: up to "
                             "two lines after the vsync pulse)")


def run(args):
    from sim.testbench.display import capture_frame
    from sim import SimulationFailed
    from sim.models.ch7301c.hdmi_sink import write_png
    timing = modes()[args.mode]
    out = prepare_out_dir(args.out)
    lines = check_wave_lines(args.wave_lines, timing)
    outputs = RunOutputs(out, OUTPUTS).start()
    bar = Progress(f"{args.simulator}: simulate", total=timing.clocks_per_frame + 16, unit="clk")
    try:
        capture = capture_frame(timing, args.simulator, out, progress=bar.update)
    except SimulationFailed as exc:
        print(f"stereodepth: simulation failed: {exc}", file=sys.stderr)
        return 1
    finally:
        bar.close()
    files = {}
    if capture.frame is not None:
        files["PNG"] = outputs.write("hdmi_frame.png", lambda p: write_png(capture.frame, p))
    if not args.no_waves:
        files.update(write_waves(timing, outputs, lines))
    print_capture(capture, timing, args.simulator)
    print_outputs(files)
    return 0 if capture.ok else 1


def write_waves(timing, outputs, lines):
    """``display.vcd`` + ``display.gtkw`` of ``outputs`` (written under their partial names, then committed)."""
    from sim.testbench.display import write_display_waves
    write_display_waves(timing, outputs.partial("display.vcd"), lines=lines)     # the .gtkw beside it
    return {"VCD": outputs.commit("display.vcd"), "GTKWave": outputs.commit_save_file("display.gtkw", "display.vcd")}


def check_wave_lines(lines, timing):
    if lines is not None and not 1 <= lines <= timing.v_total:
        raise UserError(f"--wave-lines must be between 1 and {timing.v_total}, got {lines}")
    return lines


def print_capture(capture, timing, simulator):
    rate = capture.clocks / capture.wall_s if capture.wall_s else 0
    print(f"display path, {timing.h_active}x{timing.v_active} ({timing.h_total}x{timing.v_total} clocks a frame) "
          f"on {simulator}: {capture.clocks:,} pixel clocks in {capture.wall_s:.1f} s ({rate:,.0f} clocks/s)")
    print(capture.report)
    print("OK" if capture.ok else "FAILED: see above")


def print_outputs(files):
    """Print where the files are and how to open them."""
    if not files:
        return
    print("wrote:")
    width = max(len(str(p)) for p in files.values())
    how = {"PNG": "open with any image viewer, e.g. xdg-open {p}",
           "VCD": "waveforms (open the .gtkw file below)",
           "GTKWave": "gtkwave {p}   (pins, sync generator and pattern grouped)"}
    for kind, path in files.items():
        shown = _relative(path)
        print(f"  {shown:<{width}}  {how.get(kind, kind).format(p=shown)}")


def _relative(path):
    path = Path(path)
    try:
        return str(path.resolve().relative_to(Path.cwd()))
    except ValueError:
        return str(path)
