"""cocotb tests of the display path (hdl/display_path.py) on its CH7301C pins, on Verilator and Icarus.

Driven through ``sim.testbench.display.run_display_cocotb`` from tests/test_display_path.py, ``sim.testbench.display.capture_frame``
(the ``display`` command) and the benchmark. Parameters (``sim.runners.cocotb.test_params()``):

* ``timing``: the :class:`spec.video.VideoTiming` fields of the design under test (required);
* ``sink_clocks``: pixel clocks the HDMI sink samples from reset (0 or absent: ``sink_frames`` is skipped);
* ``min_frames``: complete frames ``sink_frames`` must rebuild (default 1);
* ``compare_golden``: compare every rebuilt frame with ``golden.video.pattern_frame`` (default true);
* ``expect_values``: ``{interval: value}``: every measurement of that interval by the sink must equal it;
* ``out_dir``: where ``sink_frames`` saves the rebuilt frames (``frame_<n>.npy``) and ``result.json``;
* ``progress_file``: where the sink writes its progress (``"<done> <total>"``);
* ``expect_edges``: ``{interval: value}`` every interval the edge timestamps give must equal;
* ``free_run_clocks``: ``free_run`` lets the design run that many clocks without Python per clock and writes
  the wall time to ``out_dir/free_run.json`` (the benchmark's speed figure; 0 or absent: skipped).

``sink_frames`` checks the same pins in two independent ways during one run: the per-clock sink model
(``sim/models/ch7301c/hdmi_sink.py``) samples both words of every pixel clock, and an edge recorder timestamps the edges of
hsync, vsync and de (simulator callbacks) from which :func:`measure_edges` derives every interval with NumPy.
"""

import json
import time
from pathlib import Path

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, RisingEdge, Timer
from cocotb.utils import get_sim_time

from golden.video import pattern_frame
from spec.video import VideoTiming
from sim.runners.cocotb import TopPorts, test_params
from sim.models.ch7301c.hdmi_sink import CocotbSink, HdmiSink

PARAMS = test_params()
TIMING = VideoTiming(**PARAMS["timing"]) if "timing" in PARAMS else None
#: 148.5 MHz is 6734.0 ps; a multiple of 4 keeps the sink's quarter-period sample points whole picoseconds.
PERIOD_PS = 6736
RESET_CLOCKS = 3


async def start_in_reset(dut):
    """Start the pixel clock with reset asserted; returns the time (ps) of its first rising edge."""
    Clock(dut.clk, PERIOD_PS, unit="ps").start()
    dut.rst.value = 1
    await RisingEdge(dut.clk)
    return int(get_sim_time("ps"))


async def release_reset(dut):
    await ClockCycles(dut.clk, RESET_CLOCKS)
    await FallingEdge(dut.clk)
    dut.rst.value = 0


class EdgeRecorder:
    """Timestamps every edge of hsync, vsync and de (simulator edge callbacks; no per-clock Python)."""

    NAMES = ("hs_lead", "hs_trail", "vs_lead", "vs_trail", "de_rise", "de_fall")

    def __init__(self, pins, timing):
        t = timing
        lead = {True: RisingEdge, False: FallingEdge}
        trail = {True: FallingEdge, False: RisingEdge}
        self.triggers = {
            "hs_lead": lead[t.hsync_positive](pins.hsync), "hs_trail": trail[t.hsync_positive](pins.hsync),
            "vs_lead": lead[t.vsync_positive](pins.vsync), "vs_trail": trail[t.vsync_positive](pins.vsync),
            "de_rise": RisingEdge(pins.de), "de_fall": FallingEdge(pins.de),
        }
        self.edges = {name: [] for name in self.NAMES}

    def start(self):
        for name in self.NAMES:
            cocotb.start_soon(self._record(self.triggers[name], self.edges[name]))

    @staticmethod
    async def _record(trigger, times):
        while True:
            await trigger
            times.append(int(get_sim_time("ps")))


@cocotb.test(skip=not PARAMS.get("sink_clocks"))
async def sink_frames(dut):
    """From reset, sample the pins with the HDMI sink and timestamp their edges: no timing violation, every
    measured interval as expected (both ways), every rebuilt frame equal to the golden pattern."""
    sink = HdmiSink(TIMING)
    origin = await start_in_reset(dut)
    # The sink and the edge recorder start while reset holds the pins blank, so both see frame 0 from its
    # first pixel.
    pins = TopPorts(dut).ch7301c
    recorder = EdgeRecorder(pins, TIMING)
    recorder.start()
    reader = CocotbSink(pins, sink, period_ps=PERIOD_PS, progress_file=PARAMS.get("progress_file"))
    wall = time.perf_counter()
    task = cocotb.start_soon(reader.run(PARAMS["sink_clocks"]))
    await release_reset(dut)
    await task
    wall = time.perf_counter() - wall
    edges = measure_edges(recorder.edges, PERIOD_PS, origin)

    out_dir = PARAMS.get("out_dir")
    if out_dir:
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        for i, frame in enumerate(sink.frames):
            np.save(out / f"frame_{i}.npy", frame)
        result = {"clocks": sink.clock, "wall_s": wall, "frames": sink.frames_completed, "ok": sink.ok,
                  "report": sink.report(), "violations": dict(sink.violation_counts),
                  "observed": {k: {str(v): c for v, c in cnt.items()} for k, cnt in sink.observed.items()},
                  "edges": {k: sorted(v) for k, v in edges.items()}}
        (out / "result.json").write_text(json.dumps(result, indent=1))

    dut._log.info(sink.report())
    dut._log.info(f"sink measured (value: times): { {k: dict(v) for k, v in sink.observed.items()} }")
    dut._log.info(f"edge timestamps give: { {k: sorted(v) for k, v in edges.items()} }")
    sink.check()
    assert sink.frames_completed >= PARAMS.get("min_frames", 1), \
        f"only {sink.frames_completed} complete frame(s) in {sink.clock} clocks"
    if PARAMS.get("compare_golden", True):
        golden = pattern_frame(TIMING)
        for i, frame in enumerate(sink.frames):
            if not np.array_equal(frame, golden):
                bad = np.argwhere(np.any(frame != golden, axis=2))
                y, x = bad[0]
                raise AssertionError(f"frame {i}: {len(bad)} pixel(s) differ from the golden pattern; first at "
                                     f"x={x}, y={y}: got {frame[y, x].tolist()}, expected {golden[y, x].tolist()}")
    for name, value in PARAMS.get("expect_values", {}).items():
        got = dict(sink.observed[name])
        assert set(got) == {value}, f"sink measured {name} = {got} (value: times), expected only {value}"
    assert edges["vsync_aligned"] <= {True}, "a vsync edge does not coincide with an hsync leading edge"
    for name, value in PARAMS.get("expect_edges", {}).items():
        assert edges[name] == {value}, f"edge timestamps give {name} = {sorted(edges[name])}, expected {value}"


def measure_edges(edges, period_ps, origin=0):
    """Every raster interval found in lists of edge timestamps (ps) -> ``{name: set of values}``.

    The stream is assumed to start at the top of a frame (from reset): frames start at the first de rising
    edge and at the first de rising edge after each vsync pulse. Every timestamp must lie on the clock grid
    (``origin`` + a whole number of periods). Line/pulse/porch/frame intervals are in clocks;
    ``v_front``/``v_back``/``vsync_lines`` count hsync leading edges, ``active_lines`` de rising edges;
    ``vsync_aligned`` holds whether each vsync edge coincides with an hsync leading edge.
    """
    e = {}
    for name, times in edges.items():
        a = np.array(times, dtype=np.int64) - origin
        if np.any(a % period_ps):
            raise AssertionError(f"{name} edge off the clock grid: {a[a % period_ps != 0][:3]} ps")
        e[name] = a // period_ps
    hl, ht, vl, vt, dr, df = (e[k] for k in ("hs_lead", "hs_trail", "vs_lead", "vs_trail", "de_rise", "de_fall"))

    def before(ref, x):
        """For each x, the last element of ref strictly before it (-1: none)."""
        i = np.searchsorted(ref, x, side="left") - 1
        return np.where(i >= 0, ref[np.maximum(i, 0)] if len(ref) else -1, -1)

    def after(ref, x):
        """For each x, the first element of ref strictly after it (-1: none)."""
        i = np.searchsorted(ref, x, side="right")
        return np.where(i < len(ref), ref[np.minimum(i, len(ref) - 1)] if len(ref) else -1, -1)

    def count_between(ref, lo, hi):
        """For each (lo, hi), how many elements of ref lie strictly between them."""
        return np.searchsorted(ref, hi, side="left") - np.searchsorted(ref, lo, side="right")

    out = {"line_clocks": set(np.diff(hl).tolist())}
    p = before(hl, ht)
    out["hsync_clocks"] = set((ht - p)[p >= 0].tolist())
    p = before(dr, df)
    out["active_pixels"] = set((df - p)[p >= 0].tolist())
    n = after(hl, df)
    out["h_front"] = set((n - df)[n >= 0].tolist())
    p = before(ht, dr)
    out["h_back"] = set((dr - p)[p >= 0].tolist())
    p = before(vl, vt)
    out["vsync_clocks"] = set((vt - p)[p >= 0].tolist())
    out["vsync_lines"] = set(count_between(hl, p[p >= 0] - 1, vt[p >= 0]).tolist())   # leads in [lead, trail)
    out["vsync_aligned"] = set(np.isin(np.concatenate([vl, vt]), hl).tolist())
    p = before(df, vl)
    out["v_front"] = set(count_between(hl, p[p >= 0], vl[p >= 0]).tolist())
    n = after(dr, vt)
    out["v_back"] = set(count_between(hl, vt[n >= 0], n[n >= 0]).tolist())
    starts = np.unique(np.concatenate([dr[:1], n[n >= 0]]))
    out["active_lines"] = set(count_between(dr, starts[:-1] - 1, starts[1:]).tolist())
    out["frame_clocks"] = set(np.diff(starts).tolist())
    return out


@cocotb.test(skip=not PARAMS.get("free_run_clocks"))
async def free_run(dut):
    """Run the design for ``free_run_clocks`` clocks with no Python per clock; record the wall time."""
    await start_in_reset(dut)
    await release_reset(dut)
    clocks = PARAMS["free_run_clocks"]
    wall = time.perf_counter()
    await Timer(clocks * PERIOD_PS, "ps")
    wall = time.perf_counter() - wall
    dut._log.info(f"free run: {clocks} clocks in {wall:.2f} s = {clocks / wall:.0f} clocks/s")
    if PARAMS.get("out_dir"):
        out = Path(PARAMS["out_dir"])
        out.mkdir(parents=True, exist_ok=True)
        (out / "free_run.json").write_text(json.dumps({"clocks": clocks, "wall_s": wall}))
