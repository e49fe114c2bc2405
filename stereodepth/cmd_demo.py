"""``stereodepth demo`` / ``make demo``: the main job -- the whole simulated system on the bundled stereo pair.

1. The switch settings: the disparity at which the bundled pair's motorcycle matches (and fades to black) and the
   rectification, found from the pair (``sim.analysis.disparity_pictures.find_settings``, Middlebury ground truth beside).
2. The whole system end to end at the board's size -- 1600 x 1200 sensors, 400 x 300 camera frames, one
   1920 x 1080 frame -- on Verilator (``stereodepth run`` does the same with your own pair), the DDR2 build: the
   camera frames in the DDR2 frame store behind MIG, simulated with the MIG model; both MT9D112 models
   configured over I2C by the RTL, both cameras captured, the depth map computed by the engine, the four panels
   composited and driven onto the CH7301C pins, rebuilt by the HDMI sink model and compared bit for bit with the
   golden model. The frame shown is the first display frame whose depth map comes from complete camera frames
   (the DDR2 build's first; the block-RAM build's may withhold rows at a tear where a capture was overwriting its
   buffers: the summary says which one it was). The depth panel the pins carried is read back (its colours
   inverted) and scored against the motorcycle's ground truth (``sim.analysis.truth``): bad > 1, bad > 2,
   density; the readout gives the centre distance. -> ``hdmi_frame.png`` (the frame from the simulated pins), ``golden_frame.png``,
   ``depth_map.png`` (the depth map alone, buffer size, with its colour bar), ``result.json``.
3. Waveforms of the whole system at the small test size in Amaranth's simulator (I2C init, capture, one display
   frame; the block-RAM build: the DDR2 build with its MIG model takes minutes in Amaranth's simulator) ->
   ``system.vcd`` and ``system.gtkw`` (GTKWave save file with the buses, cameras, switches, video stream and
   CH7301C pins grouped), and that run's frame as ``hdmi_frame_small.png``. It runs in a second process beside
   step 2, so that the machine's two cores share the demo (Amaranth's simulator is one process, Verilator's run
   another), and reports after it.
4. The golden pictures of the disparity display at the matching and at a wrong disparity
   (``sim.analysis.disparity_pictures.write_pictures``).

``--small`` runs step 2 at the small size too (with ``--build 800`` ``SystemSetup.small_800``); ``--memory bram``
runs it on the thesis's build (the camera frames in block-RAM buffers): :data:`THESIS_COMMAND`. ``--build 800`` runs
step 2 on the 800 x 600 build (``SystemSetup.full_800``: the averaging capture, D = 128, the frames and the maps in
the DDR2; docs/depth.md, "The 800 x 600 build on the board") at the switch settings step 1 finds for its 800 x 600
buffers; the bundled pair, 667 x 500 once cropped to 4:3, is fitted up to the 1600 x 1200 sensors (``stereodepth
run`` refuses a pair smaller than the buffers: your own pair there must be at least 800 x 600). Step 4 draws the
thesis build's pictures only. README's table gives the run times. As with ``run``, an earlier run's outputs are
removed at the start, each output appears under its own name only when complete, and ``result.json`` records the
provenance (``stereodepth/outputs.py``, ``stereodepth/provenance.py``).
"""

import sys
import time
from pathlib import Path

from .cmd_run import add_memory_argument
from .design_args import add_build_argument
from .errors import prepare_out_dir
from .outputs import RunOutputs

#: Every file ``demo`` writes into ``--out`` (the golden pictures are named by disparity: removed by pattern).
OUTPUTS = ("hdmi_frame.png", "golden_frame.png", "difference.png", "depth_map.png", "result.json", "system.vcd",
           "system.gtkw", "hdmi_frame_small.png")
STALE_PATTERNS = ("disparity_golden_*.png",)


def add_arguments(parser):
    parser.add_argument("--simulator", choices=("verilator", "icarus"), default="verilator",
                        help="simulator of the end-to-end run: verilator (default) or icarus (much slower at full "
                             "size)")
    parser.add_argument("--small", action="store_true",
                        help="run the end-to-end step at the small test size (64x48 sensors, 112x52 display; with "
                             "--build 800 its structure at that size: 8-bit 32x24 buffers, D = 16)")
    parser.add_argument("--out", type=Path, default=Path("build/demo"), help="output directory (build/demo)")
    parser.add_argument("--no-waves", action="store_true", help="skip the VCD / GTKWave step")
    add_memory_argument(parser, default="ddr2")
    add_build_argument(parser)                  # with 800 the bundled pair is fitted up to the sensors


def small_disparity(disparity, setup_small, geometry=None):
    """A disparity of ``geometry``'s buffers (default the board's, ``spec.sensor.SENSOR``) scaled to the small
    buffers (same fraction of the image width, at least 1)."""
    from spec.sensor import SENSOR
    return max(1, round(disparity * setup_small.geometry.buf_width / (geometry or SENSOR).buf_width))


#: The command of the thesis's build (the camera frames in block-RAM buffers), which the demo's printout names.
THESIS_COMMAND = "python -m stereodepth demo --memory bram"


def waves_step(setup, out_dir):
    """Step 3: the bundled pair at the small ``setup`` in Amaranth's simulator with waveforms, into ``out_dir``
    (``system.vcd``, ``system.gtkw``, ``hdmi_frame_small.png``). Returns ``(ok, files, lines)``: whether its frame
    equals the golden frame (None when the run failed), the files written ({label: path}) and the lines to print.
    It prints nothing itself: it runs in a second process beside the full-size step (:class:`sim.runners.background.Background`)."""
    from golden.stereo_pair import load_default_pair
    from sim import SimulationFailed
    from sim.models.ch7301c.hdmi_sink import write_png
    from sim.system import Amaranth, simulate, still_pair
    from sim.testbench.system.waves import system_waves
    outputs = RunOutputs(out_dir, OUTPUTS, stale=STALE_PATTERNS)         # started by the parent
    left, right = load_default_pair(setup.geometry.width, setup.geometry.height)
    backend = Amaranth(vcd=outputs.partial("system.vcd"), gtkw=outputs.partial("system.gtkw"), traces=system_waves)
    try:
        result = simulate(setup, still_pair(left, right, setup), backend, policy="first")
    except SimulationFailed as exc:
        return None, {}, [f"stereodepth demo: waveform run failed: {exc}"]
    outputs.commit("system.vcd")
    outputs.commit_save_file("system.gtkw", "system.vcd")
    files = {}
    frame = result.frame
    if frame is not None:
        files["small-size HDMI frame (the waveform run)"] = outputs.write("hdmi_frame_small.png",
                                                                          lambda p: write_png(frame, p))
    files["VCD (whole system, small size)"] = outputs.dir / "system.vcd"
    files[f"GTKWave save file: gtkwave {outputs.dir / 'system.gtkw'}"] = outputs.dir / "system.gtkw"
    lines = [f"waveforms (the whole system at the small size in Amaranth's simulator, block-RAM build, beside the "
             f"full-size run): the small-size frame {'equals' if result.ok else 'DIFFERS from'} the golden frame "
             f"({result.figures.get('wall_s', 0):.0f} s)"]
    return result.ok, files, lines


def run(args):
    from . import cmd_run
    from sim.analysis.disparity_pictures import bundled_pair_settings
    from sim.testbench.system.setup import SystemSetup
    from sim.runners.background import Background
    from spec.sensor import SENSOR, SENSOR_800
    from stereodepth.provenance import utc_now
    from .design_args import check_build_800, preset_of
    build_800 = args.build == "800"
    if build_800:
        check_build_800(args.memory, None)                          # before any output is touched
    started = utc_now()
    out = prepare_out_dir(args.out)
    outputs = RunOutputs(out, OUTPUTS, stale=STALE_PATTERNS).start()
    t0 = time.perf_counter()
    geometry = SENSOR_800 if build_800 else SENSOR
    print(f"finding the motorcycle's disparity in the bundled pair's {geometry.buf_width} x {geometry.buf_height} "
          f"buffers ...", flush=True)
    settings, _, _ = bundled_pair_settings(geometry)
    d, r = settings.disparity, settings.rectification
    print(f"  disparity {d}, rectification {r} (mean |L-R| minimum over the motorcycle; Middlebury ground truth "
          f"median {settings.ground_truth_median:.1f} buffer pixels); a wrong one: {settings.wrong_disparity}")

    ds = small_disparity(d, SystemSetup.small(), geometry)                       # the waveform run's
    step_small = small_disparity(d, getattr(SystemSetup, preset_of(args.build, True))(), geometry)
    setup = cmd_run.make_setup(args.small, step_small if args.small else d, r if not args.small else 0,
                               memory=args.memory, build=args.build)
    g, t = setup.geometry, setup.timing
    fitted = "" if args.small else "; the bundled pair fitted up to the sensors"
    build_name = (f"the 800 x 600 build (8-bit 2 x 2 means, D = {setup.depth.disparities}, camera frames and depth "
                  f"maps in the DDR2 behind the MIG model{fitted})" if build_800 else
                  "the DDR2 build (camera frames in the DDR2 frame store behind the MIG model)"
                  if args.memory == "ddr2" else "the thesis's build (camera frames in block-RAM buffers)")
    print(f"whole system on {args.simulator}, {build_name}: {g.width}x{g.height} sensors -> "
          f"{g.buf_width}x{g.buf_height} frames -> {t.h_active}x{t.v_active} display", flush=True)
    waves = None
    if not args.no_waves:
        print("waveforms: the whole system at the small size in Amaranth's simulator, in a second process ...",
              flush=True)
        waves = Background(waves_step, SystemSetup.small(disparity=ds, rectification=0), out)
    try:
        ok, files = _full_step(args, setup, out, outputs, started)
    except BaseException:
        if waves is not None:
            waves.stop()
        raise
    if ok is None:
        if waves is not None:
            waves.stop()
        return 1

    if waves is not None:
        try:
            small_ok, small_files, lines = waves.result()
        except RuntimeError as exc:
            small_ok, small_files, lines = None, {}, [f"stereodepth demo: waveform run failed: {exc}"]
        print("\n".join(lines), file=sys.stdout if small_ok is not None else sys.stderr, flush=True)
        if small_ok is None:
            return 1
        files.update(small_files)
        ok = ok and small_ok

    if not build_800:
        from sim.analysis.disparity_pictures import write_pictures
        for path in write_pictures(out):
            files[f"golden disparity display picture ({'matched' if 'matched' in path.name else 'wrong'} "
                  f"disparity)"] = path
    print(f"total {time.perf_counter() - t0:.0f} s")
    cmd_run.print_files(files)
    if args.memory == "ddr2" and not build_800:
        print(f"the thesis's build (camera frames in block-RAM buffers): {THESIS_COMMAND}")
    print("OK" if ok else "FAILED")
    return 0 if ok else 1


def _full_step(args, setup, out, outputs, started):
    """Step 2 on ``setup``: the run, its files and its summary. Returns ``(ok, files)``, ok None when the run
    failed."""
    from . import cmd_run
    from sim import SimulationFailed
    from sim.system import backend_named, still_pair
    from sim.testbench.system.run_cocotb import DEFAULT_PAIR
    from golden.stereo_pair import load_default_pair
    from stereodepth.provenance import provenance
    files = {}
    t_step = time.perf_counter()
    try:
        left, right = load_default_pair(setup.geometry.width, setup.geometry.height)    # fitted, up if need be
        sequence = still_pair(left, right, setup, sources=DEFAULT_PAIR)
        backend = backend_named(args.simulator, work_dir=out / f".{args.simulator}")
        result = cmd_run.simulate_still(setup, sequence, backend, args.simulator)
    except SimulationFailed as exc:
        print(f"stereodepth demo: simulation failed: {exc}", file=sys.stderr)
        return None, files
    frame, golden, status = result.frame, result.golden, dict(result.status, **result.figures)
    record = provenance(DEFAULT_PAIR, dict(vars(args), setup=setup.to_spec()), started)
    from sim.analysis.depth_panel import depth_outputs, summary_lines
    from sim.analysis.truth import motorcycle_truth
    depth, depth_files = depth_outputs(frame, setup, motorcycle_truth("right", setup.geometry), outputs.write)
    files.update(cmd_run.write_outputs(outputs, frame, golden, status, {"simulator": args.simulator,
                                                                       "verdict": result.verdict, "depth": depth,
                                                                       "provenance": record}))
    files.update(depth_files)
    ok, lines = cmd_run.summarise(setup, args.simulator, frame, golden, status, time.perf_counter() - t_step,
                                  result.verdict)
    if status.get("t_end_s") and status.get("wall_s"):
        edges = sum(setup.clock_edges(status["t_end_s"], status["t_init_s"], status["t_init_s"]).values())
        lines.insert(-1, f"  {edges / 1e6:.1f} M clock edges (all domains) in {status['wall_s']:.1f} s of "
                         f"simulation: {edges / status['wall_s'] / 1e6:.2f} M edges/s")
    print("\n".join(lines[:-1] + summary_lines(depth) + lines[-1:]), flush=True)
    return ok, files
