"""``stereodepth run LEFT RIGHT``: the whole simulated system end to end on your own stereo pair.

The pair (read by ``golden.image_file``; from the frame buffer's size once cropped to 4:3 up to 25 M pixels;
fitted to the sensor by centre-crop and resize, as ``golden.stereo_pair.load_pair`` does) goes into the two
MT9D112 sensor models; the RTL configures them and the CH7301C over I2C, captures both cameras into the frame
buffers, composites the left image, the right image, the difference map for the given switch settings and the
depth engine's map (colour bar, labels, crosshair, centre distance) and drives the CH7301C pins; the HDMI sink model rebuilds the frame, which is compared bit for
bit with the golden model's frame. The cameras send the pair every frame, so a display frame's depth map may be
computed while a capture overwrites the buffers (rows withheld at the tear, docs/depth.md): the run shows the first
display frame whose depth map comes from complete camera frames (within eight display frames; in automatic
rectification also with the offset locked) and says which one it was, and the offset found.

Writes to ``--out`` (default build/run/): ``hdmi_frame.png`` (the frame rebuilt from the simulated pins),
``golden_frame.png``, ``difference.png`` (only if they differ), ``depth_map.png`` (the depth map the displayed
frame carries, at buffer size with its colour bar), ``result.json`` (I2C outcome, timing checks, figures; under
``depth`` the centre distance shown and, with ``--ground-truth``, bad > 1 / bad > 2 of the depth panel; and
``provenance``: input files with SHA-256, parameters, tool versions, git commit, UTC start and end).
``--vcd`` (Amaranth simulator, ``--small`` only) also writes ``system.vcd`` + ``system.gtkw``. The directory is
checked writable before any work; an earlier run's outputs are removed at the start and each output appears under
its own name only when complete (``stereodepth/outputs.py``).

The run is ``sim.system.simulate`` with a still pair (``sim.system.still_pair``: the sensors send the pair every
frame) on the backend of ``--simulator``; this module parses the arguments and writes and prints what the result
holds. Sizes: the default is the board's (1600 x 1200 sensors, 400 x 300 buffers, 1080p60 display); ``--small``
runs the small test configuration (64 x 48 sensors, 112 x 52 display; ``sim/testbench/system/setup.py``), with
``--build 800`` the 800 x 600 build's at that size (``SystemSetup.small_800``: 32 x 24 8-bit buffers, D = 16).
Simulators (``sim/system/backends.py``): ``verilator`` (default) runs with its testbench in C++ (clocks, sensor
streams and the pin recorder in C++, the Python models answering the I2C buses); ``icarus`` runs through cocotb
along the in-simulator route (the sensors replayed and the pins recorded inside the simulator); ``amaranth`` runs
Amaranth's own simulator: at full size along its replay route (the sensor streams replayed from ROMs in the
simulated design), with ``--small`` with the sensor models driven from Python per PCLK. ``--frames N``:
``stereodepth/run_frames.py``. ``--memory ddr2`` runs the DDR2 build (the frames in the frame store behind MIG, its
simulation model in place of the DDR2: docs/frame_store.md) instead of the block-RAM buffers, on Verilator,
Icarus, or Amaranth's simulator with ``--small``; with it, ``--maps store`` keeps the depth maps whole in the frame
store and shows the latest whole one (docs/frame_store.md, "Depth maps in the store").
"""

import json
import sys
import time
from pathlib import Path

from sim.system.backends import SIMULATORS

from .design_args import add_build_argument
from .errors import UserError, prepare_out_dir
from .outputs import RunOutputs
from .run_frames import load_images, progress_bar
#: Every file ``run`` writes into ``--out``.
OUTPUTS = ("hdmi_frame.png", "golden_frame.png", "difference.png", "depth_map.png", "result.json", "system.vcd",
           "system.gtkw")


def add_arguments(parser):
    parser.add_argument("left", metavar="LEFT", nargs="?",
                        help="left image file (camera A); with --frames also a folder of images or a video file")
    parser.add_argument("right", metavar="RIGHT", nargs="?",
                        help="right image file (camera B), same size as LEFT; with --frames also a folder or a video")
    parser.add_argument("--frames", type=int, default=None, metavar="N",
                        help="N camera frames of a moving scene (LEFT/RIGHT folders or video files, or one pair "
                             "repeated, or --scene card) and every display frame they overlap: "
                             "stereodepth/run_frames.py")
    parser.add_argument("--scene", choices=("card",), default=None,
                        help="with --frames: the synthetic test bed, a textured card moving from --far to --near")
    parser.add_argument("--far", type=float, default=None, metavar="M",
                        help="--scene card: first distance in metres (3 m; 8 m with --small)")
    parser.add_argument("--near", type=float, default=None, metavar="M",
                        help="--scene card: last distance in metres (0.5 m; 4 m with --small)")
    parser.add_argument("--vertical-offset", default=None, metavar="V[,V2,...]",
                        help="--scene card: the rig's vertical offset in sensor rows (the left image V rows lower; "
                             "4 sensor rows = 1 buffer row); several values split the run into equal parts, e.g. "
                             "0,12 = a knock to the rig halfway (try it with --rectification auto)")
    parser.add_argument("--disparity", default="0", metavar="D",
                        help="disparity switch value 0..127 (SW7 = 1, SW6..SW0 = D); default 0")
    parser.add_argument("--rectification", default=None, metavar="R",
                        help="rectification switch value -62..63 buffer rows (SW7 = 0, SW6..SW0 = R in two's "
                             "complement; negative reads the left image higher), or 'auto' (SW6..SW0 = 1000000: "
                             "the offset the FPGA finds, docs/rectification.md); default 0 (auto with --segment)")
    parser.add_argument("--segment", action="store_true",
                        help="the segmentation view in the difference map's place: the right image dimmed outside "
                             "the depth band --disparity +-2 pixels, the band shown in metres (SW6..SW0 = 1000001: "
                             "automatic rectification; docs/display.md)")
    parser.add_argument("--simulator", choices=SIMULATORS, default="verilator",
                        help="verilator (default), icarus, or amaranth (hours at full size; quick with --small)")
    parser.add_argument("--out", type=Path, default=Path("build/run"), help="output directory (build/run)")
    parser.add_argument("--small", action="store_true",
                        help="small configuration: 64x48 sensors, 112x52 display (fast; for a quick look); with "
                             "--build 800 the 800 build's structure at that size (8-bit 32x24 buffers, D = 16)")
    parser.add_argument("--ground-truth", type=Path, default=None, metavar="FILE",
                        help="a disparity map at the input's size (PFM, inf = unknown; or 16-bit PNG in 1/256 "
                             "pixel, 0 = unknown), of the view --truth-view names: report bad > 1 / bad > 2 of "
                             "the depth panel")
    parser.add_argument("--truth-view", choices=("right", "left"), default="right",
                        help="which image --ground-truth describes: right (default, the engine's reference, e.g. "
                             "Middlebury disp1.pfm) or left (e.g. Middlebury disp0.pfm: converted to the right "
                             "view as sim/analysis/truth.py does for the motorcycle)")
    parser.add_argument("--vcd", action="store_true",
                        help="write system.vcd + system.gtkw (Amaranth simulator, --small only)")
    add_memory_argument(parser, default=None)
    parser.add_argument("--maps", choices=("ring", "store"), default=None,
                        help="where the depth maps are: ring (the engine's ring of result rows, a map a display "
                             "frame; the thesis build's default) or store (with --memory ddr2: whole maps in the "
                             "frame store, the latest whole one shown)")
    add_build_argument(parser)


def add_memory_argument(parser, default="bram"):
    """``--memory bram|ddr2``; ``default``: the command's choice (``None``: the build's, bram for the thesis's)."""
    parser.add_argument("--memory", choices=("bram", "ddr2"), default=default,
                        help="where the frames are: bram (the block-RAM buffers of the thesis design) or ddr2 (the "
                             "frame store in the DDR2 behind MIG, simulated with the MIG model); default "
                             f"{default or 'bram for the thesis build'}")


def switch_value(name, text, low=0, high=127):
    try:
        value = int(text, 0)
    except ValueError:
        raise UserError(f"--{name} must be an integer {low}..{high}, got {text!r}") from None
    if not low <= value <= high:
        raise UserError(f"--{name} must be {low}..{high} (seven switches), got {value}")
    return value


def make_setup(small, disparity, rectification, segment=False, memory=None, maps=None, build="thesis"):
    """The run's :class:`~sim.testbench.system.setup.SystemSetup`; ``memory`` / ``maps`` ``None``: the build's.
    One-line :class:`UserError` for a combination no design has."""
    from hdl.stereo_display import check_maps
    from sim.testbench.system.setup import SystemSetup
    from .design_args import check_build_800, preset_of
    switches = {"disparity": disparity, "rectification": rectification, "segment": segment}
    if build == "800":
        check_build_800(memory, maps)
        return getattr(SystemSetup, preset_of(build, small))(**switches)
    memory, maps = memory or "bram", maps or "ring"
    try:
        check_maps(memory, maps)
    except ValueError as exc:
        raise UserError(f"--maps {maps}: {exc}") from None
    return (SystemSetup.small if small else SystemSetup.full)(**switches, memory=memory, maps=maps)


def switch_settings(args):
    """``(disparity, rectification, segment)`` from the arguments; one-line :class:`UserError` for a bad value:
    ``--segment`` with a manual rectification, or a band that holds no disparity the engine gives."""
    from hdl.config import DesignConfig
    from hdl.rectification_select import MANUAL_RANGE
    from spec.display import SEGMENT_HALF_WIDTH
    from .design_args import preset_of
    depth = getattr(DesignConfig, preset_of(getattr(args, "build", "thesis"), getattr(args, "small", False)))().depth
    disparity = switch_value("disparity", args.disparity)
    text = args.rectification if args.rectification is not None else ("auto" if args.segment else "0")
    if text == "auto":
        rectification = "auto"
    else:
        rectification = switch_value("rectification", text, MANUAL_RANGE.start, MANUAL_RANGE.stop - 1)
    if args.segment:
        if rectification != "auto":
            raise UserError("--segment selects the automatic rectification (switches 1000001): drop "
                            f"--rectification {text}")
        top = min(depth.disparities - 1 + SEGMENT_HALF_WIDTH, 127)
        if disparity > top:
            raise UserError(f"--segment: the band {disparity} +-{SEGMENT_HALF_WIDTH} pixels holds no disparity the "
                            f"engine gives (0..{depth.disparities - 1}): use --disparity 0..{top}")
    return disparity, rectification, args.segment


def segmentation_record(setup):
    """``result.json``'s ``segmentation``: on or off, and the band (disparities and the text shown)."""
    if not setup.segment:
        return {"on": False}
    from golden.segmentation import band_text
    from spec.display import SEGMENT_HALF_WIDTH
    d, hw = setup.disparity, SEGMENT_HALF_WIDTH
    return {"on": True, "band_disparity_px": [max(d - hw, 0), d + hw], "band_text": band_text(d, setup.geometry),
            "text_shown": setup.display_layout.band is not None}


def simulate_still(setup, sequence, backend, simulator, policy="whole"):
    """The one-frame run of ``sequence`` (a still pair) on ``backend`` with a progress bar, showing the first display
    frame whose depth map has no withheld rows (``policy``, :data:`sim.system.verdict.POLICIES`); a
    :class:`~sim.system.run.SystemResult`. Raises :class:`sim.SimulationFailed` (the caller prints it)."""
    from sim.system import simulate
    bar, progress = progress_bar(simulator)
    try:
        return simulate(setup, sequence, backend, progress=progress, policy=policy)
    finally:
        bar.close()


def still_backend(args, out, outputs):
    """The backend of a one-frame run on ``args.simulator``: with ``--vcd`` Amaranth's simulator writing
    ``system.vcd`` + ``system.gtkw`` of ``outputs`` (a :class:`RunOutputs`) under their partial names."""
    from sim.system import Amaranth, backend_named
    if args.vcd:
        from sim.testbench.system.waves import system_waves
        return Amaranth(vcd=outputs.partial("system.vcd"), gtkw=outputs.partial("system.gtkw"), traces=system_waves)
    return backend_named(args.simulator, work_dir=out / f".{args.simulator}")


def write_outputs(outputs, frame, golden, status, figures):
    """The frames and ``result.json`` (``status`` + ``figures``), each committed when written, result.json
    last."""
    import numpy as np
    from sim.models.ch7301c.hdmi_sink import write_png
    files = {}
    if frame is not None:
        files["HDMI frame (from the simulated pins)"] = outputs.write("hdmi_frame.png", lambda p: write_png(frame, p))
    files["golden frame"] = outputs.write("golden_frame.png", lambda p: write_png(golden, p))
    if frame is not None and not np.array_equal(frame, golden):
        diff = np.where(np.any(frame != golden, axis=-1, keepdims=True), 255, 0).astype(np.uint8)
        files["difference (white = differs)"] = outputs.write("difference.png",
                                                              lambda p: write_png(np.repeat(diff, 3, axis=-1), p))
    status = dict(status, **figures)
    files["result"] = outputs.write("result.json",
                                    lambda p: p.write_text(json.dumps(status, indent=1, default=str) + "\n"))
    return files


def run_provenance(args, setup, started):
    """``result.json``'s ``provenance``: the pair's files, every argument and the setup, tools, commit, times."""
    from stereodepth.provenance import provenance
    parameters = dict(vars(args), disparity=setup.disparity, rectification=setup.rectification, setup=setup.to_spec())
    return provenance([args.left, args.right], parameters, started)


def shown_lines(verdict):
    """The lines saying which display frame a still pair's run shows and why, and the offset the automatic
    rectification found."""
    k, n = verdict.get("chosen"), verdict.get("display_frames", 0)
    if k is None:
        return []
    withheld = verdict["withheld_rows"]
    if verdict.get("policy") != "whole":
        lines = [f"  display frame {k} shown ({withheld[k]} depth rows withheld at a tear)"]
    elif withheld[k]:
        lines = [f"  display frame {k} shown: none of the {n} display frames run has a depth map of complete camera "
                 f"frames (depth rows withheld at a tear: {withheld})"]
    else:
        before = f" (depth rows withheld at a tear before it: {withheld[:k]})" if k and any(withheld[:k]) else ""
        whose = ("images and whole depth map are the captured pair's (the maps in the frame store)"
                 if verdict.get("maps") == "store" else "depth map comes from complete camera frames")
        lines = [f"  display frame {k} shown: the first whose {whose}{before}"]
    if "auto_offset" in verdict:
        first = verdict["auto_offset_first_frame"]
        lines.append(f"  automatic rectification: offset {verdict['auto_offset']:+d} buffer rows found, "
                     + (f"locked from display frame {first} on" if first is not None else "NOT locked"))
    return lines


def summarise(setup, simulator, frame, golden, status, wall, verdict=None):
    """``(ok, lines)`` of a one-frame run: the run's ``verdict`` (:meth:`sim.system.verdict.Judge.run_verdict`)
    and the ``status``'s marks."""
    g, t = setup.geometry, setup.timing
    ok = verdict["ok"] if verdict is not None else \
        frame is not None and status.get("mismatched_pixels") == 0 and not status.get("violations")
    lines = [f"whole system, {g.width}x{g.height} sensors -> {g.buf_width}x{g.buf_height} buffers -> "
             f"{t.h_active}x{t.v_active} display, disparity {setup.disparity}, rectification "
             f"{setup.rectification}{', segmentation on' if setup.segment else ''}"
             f"{', frames in the DDR2 (MIG model)' if setup.memory == 'ddr2' else ''}"
             f"{', depth maps in the frame store' if setup.maps == 'store' else ''}, on {simulator}: "
             f"{wall:.1f} s wall time"
             + (f" (the simulation {status['wall_s']:.1f} s)" if status.get("wall_s") else "")]
    if setup.segment:
        band = segmentation_record(setup)
        low, high = band["band_disparity_px"]
        lines.append(f"  segmentation view: band {band['band_text'].strip()} (disparities {low}..{high} px)")
    for bus in ("cam_a", "cam_b", "dvi"):
        if f"{bus}_init_done" in status:
            lines.append(f"  I2C {bus}: {'configured' if status[f'{bus}_init_done'] else 'FAILED'}")
    if status.get("t_end_s"):
        lines.append(f"  simulated time {status['t_end_s'] * 1e3:.2f} ms (I2C init done at "
                     f"{status.get('t_init_s', 0) * 1e3:.2f} ms, both cameras captured at "
                     f"{status.get('t_captured_s', 0) * 1e3:.2f} ms)")
    if status.get("violations"):
        lines.append(f"  HDMI timing violations: {len(status['violations'])}, first: {status['violations'][0]}")
    if "display_missed" in status:
        lines.append(f"  DDR2 frame store: display reads refused in {status['display_missed']} pixel clocks")
    if frame is None:
        lines.append("  no frame was rebuilt")
    elif status.get("mismatched_pixels") == 0:
        lines.append("  the HDMI frame equals the golden model's frame bit for bit")
    else:
        lines.append(f"  the HDMI frame DIFFERS from the golden frame in {status.get('mismatched_pixels')} pixels")
    lines += shown_lines(verdict or {})
    lines.append("OK" if ok else "FAILED")
    return ok, lines


def print_files(files):
    print("wrote:")
    for what, path in files.items():
        print(f"  {path}   {what}")


def run(args):
    from stereodepth.provenance import utc_now
    started = utc_now()
    disparity, rectification, segment = switch_settings(args)
    setup = make_setup(args.small, disparity, rectification, segment, args.memory, args.maps, args.build)
    if args.frames is not None or args.scene is not None:
        if args.vcd:
            raise UserError("--vcd is for one frame: drop --frames / --scene")
        from .run_frames import run_frames
        if args.frames is None:
            raise UserError("--scene card needs --frames N")
        return run_frames(args, setup, started)
    if args.vertical_offset is not None:
        raise UserError("--vertical-offset is for --frames N --scene card")
    if args.left is None or args.right is None:
        raise UserError("give LEFT and RIGHT image files (or --frames N with folders or --scene card)")
    if args.vcd and (args.simulator != "amaranth" or not args.small):
        raise UserError("--vcd is written by the Amaranth route at the small size: use --simulator amaranth --small")
    out = prepare_out_dir(args.out)                             # writable, before any work
    left, right = load_images(args.left, args.right, setup)     # validates the pair before any simulation
    truth = None
    if args.ground_truth is not None:
        from golden.image_file import image_size
        from sim.analysis.depth_panel import read_truth
        truth = read_truth(args.ground_truth, image_size(args.left), setup.geometry, view=args.truth_view)
    from sim.system import still_pair
    sequence = still_pair(left, right, setup, sources=[args.left, args.right])
    outputs = RunOutputs(out, OUTPUTS)
    backend = still_backend(args, out, outputs)
    backend.require(setup, sequence)
    outputs.start()
    wall = time.perf_counter()
    from sim import SimulationFailed
    try:
        result = simulate_still(setup, sequence, backend, args.simulator)
    except SimulationFailed as exc:
        print(f"stereodepth run: simulation failed: {exc}", file=sys.stderr)
        return 1
    wall = time.perf_counter() - wall
    if args.vcd:
        outputs.commit("system.vcd")
        outputs.commit_save_file("system.gtkw", "system.vcd")
    frame, golden, status = result.frame, result.golden, dict(result.status, **result.figures)
    from sim.analysis.depth_panel import depth_outputs, summary_lines
    depth, depth_files = depth_outputs(frame, setup, truth, outputs.write)
    files = write_outputs(outputs, frame, golden, status, {"total_wall_s": wall, "simulator": args.simulator,
                                                           "verdict": result.verdict, "depth": depth,
                                                           "segmentation": segmentation_record(setup),
                                                           "provenance": run_provenance(args, setup, started)})
    files.update(depth_files)
    if args.vcd:
        files["VCD"] = out / "system.vcd"
        files["GTKWave save file (gtkwave system.gtkw)"] = out / "system.gtkw"
    ok, lines = summarise(setup, args.simulator, frame, golden, status, wall, result.verdict)
    print("\n".join(lines[:-1] + summary_lines(depth) + lines[-1:]))
    print_files(files)
    return 0 if ok else 1
