"""Cycles per second of the display path (``hdl/display_path.py``, 1080p) on Amaranth's simulator, Icarus
and Verilator, in one run, printed as a table.

Two figures per simulator:

* free-running: the design runs with no Python per clock (Amaranth: a testbench awaiting N ticks at once;
  cocotb: one ``Timer`` of N clocks);
* with the HDMI sink: every pixel clock sampled on both XCLK phases and fed to ``sim/models/ch7301c/hdmi_sink.py`` (the way
  the tests and the demo rebuild frames).

The cocotb runs reuse the cached build of the design if there is one; build time is not included. The
numbers are wall-clock rates on this machine: on a shared, loaded machine they are pessimistic.
"""

import json
import tempfile
import time
from pathlib import Path

#: clocks per measurement: (free-running, with the sink)
CLOCKS = {"amaranth": (30_000, 10_000), "icarus": (30_000, 10_000), "verilator": (2_000_000, 200_000)}


def bench_amaranth(timing, free_clocks, sink_clocks):
    from hdl.display_path import DisplayPath
    from sim.runners.amaranth import simulate
    from sim.models.ch7301c.hdmi_sink import HdmiSink, amaranth_sink_testbench

    dut = DisplayPath(timing)

    async def free(ctx):
        await ctx.tick().repeat(free_clocks)

    wall = time.perf_counter()
    simulate(dut, clocks={"sync": timing.pixel_hz}, testbenches=[free])
    free_rate = free_clocks / (time.perf_counter() - wall)

    dut = DisplayPath(timing)
    sink = HdmiSink(timing)
    wall = time.perf_counter()
    simulate(dut, clocks={"sync": timing.pixel_hz},
             testbenches=[amaranth_sink_testbench(sink, dut.ch7301c, sink_clocks)])
    sink_rate = sink_clocks / (time.perf_counter() - wall)
    sink.check()
    return free_rate, sink_rate


def bench_cocotb(timing, simulator, free_clocks, sink_clocks):
    from hdl.display_path import DisplayPath
    from sim.testbench.display import run_display_cocotb

    with tempfile.TemporaryDirectory() as tmp:
        run_display_cocotb(DisplayPath(timing), timing, simulator=simulator, sink_clocks=sink_clocks, min_frames=0,
                           compare_golden=False, free_run_clocks=free_clocks, out_dir=tmp, optimise=True)
        sink = json.loads((Path(tmp) / "result.json").read_text())
        free = json.loads((Path(tmp) / "free_run.json").read_text())
    if not sink["ok"]:
        raise AssertionError(sink["report"])
    return free["clocks"] / free["wall_s"], sink["clocks"] / sink["wall_s"]


def main():
    from spec.video import CEA_1080P60
    from sim.runners.cocotb import simulator_available

    timing = CEA_1080P60
    rows = []
    for simulator, (free_clocks, sink_clocks) in CLOCKS.items():
        print(f"{simulator}: {free_clocks:,} clocks free-running, {sink_clocks:,} with the sink ...", flush=True)
        if simulator != "amaranth" and not simulator_available(simulator):
            rows.append((simulator, None, None, "not installed"))
            continue
        if simulator == "amaranth":
            free_rate, sink_rate = bench_amaranth(timing, free_clocks, sink_clocks)
        else:
            free_rate, sink_rate = bench_cocotb(timing, simulator, free_clocks, sink_clocks)
        frame_s = timing.clocks_per_frame / sink_rate
        rows.append((simulator, free_rate, sink_rate, f"{frame_s:,.0f} s per 1080p frame with the sink"))

    print()
    print(f"display path, {timing.h_active}x{timing.v_active}p60 design ({timing.clocks_per_frame:,} clocks a frame)")
    print(f"| {'simulator':<10} | {'free-running clocks/s':>22} | {'with HDMI sink clocks/s':>24} | note")
    print(f"|{'-' * 12}|{'-' * 24}|{'-' * 26}|-----")
    for simulator, free_rate, sink_rate, note in rows:
        f = f"{free_rate:,.0f}" if free_rate else "-"
        s = f"{sink_rate:,.0f}" if sink_rate else "-"
        print(f"| {simulator:<10} | {f:>22} | {s:>24} | {note}")
    return rows


if __name__ == "__main__":
    main()
