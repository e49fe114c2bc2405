"""One full-resolution end-to-end frame of the whole system -- both cameras' 1600 x 1200 frames in, one 1080p
frame out -- on each simulator, in one run: wall time and clock cycles per second.

* Verilator: the complete end-to-end run of the slow test (``tests/test_system.py``), through the fast route
  (``sim/system_fast.py``: clocks, sensor replay and pin recording inside the simulator): the I2C init with the
  board's whole MT9D112 table at 100 kHz, one full sensor frame per camera, one 1080p display frame, compared bit
  for bit with the golden frame. Build time (first run only) is reported apart.
* Icarus and Amaranth's simulator: a whole end-to-end run would take hours, so each runs the same full-size
  design with every clock going for a slice of simulated time; the rate is measured there and the wall time of
  the whole run is **extrapolated** from the Verilator run's simulated time (stated as such).

"Cycles" counts the rising edges of every clock domain of the design (sync 100 MHz, pix 148.5 MHz, two 80 MHz
PCLKs) in the simulated time. Wall times are on this shared 2-core machine (usually loaded): pessimistic.
"""

import json
import tempfile
import time
from pathlib import Path

SYS_HZ, PIX_HZ, PCLK_HZ = 100e6, 148.5e6, 80e6
PROBE_US = {"icarus": 200, "amaranth": 4}


def _cycles(t_end, t_pix_start, t_cam_start):
    return {"sync": t_end * SYS_HZ, "pix": max(0.0, t_end - t_pix_start) * PIX_HZ,
            "cam_a": max(0.0, t_end - t_cam_start) * PCLK_HZ, "cam_b": max(0.0, t_end - t_cam_start) * PCLK_HZ}


def bench_verilator(tmp):
    from sim.system_cocotb import run_cocotb_system
    spec = {"preset": "full", "disparity": 10, "rectification": 1}
    wall = time.perf_counter()
    result = run_cocotb_system(spec, "verilator", out_dir=Path(tmp) / "verilator", sensor="replay",
                               sink="recorder")
    total = time.perf_counter() - wall
    s = result.status
    cycles = _cycles(s["t_end_s"], s["t_init_s"], s["t_init_s"])
    return {"ok": result.mismatched_pixels == 0 and not s["violations"], "sim_s": s["t_end_s"],
            "run_wall_s": s["wall_s"], "build_and_export_s": total - s["wall_s"], "cycles": cycles,
            "phases": s["phase_wall_s"]}


def _probe_rate_cocotb(simulator, tmp):
    from sim.cocotb_runner import REPO_ROOT, run_cocotb
    from sim.system_cocotb import _export, build_args, frame_period_samples, setup_from_spec
    from sim.system_fast import FastSystemBench, write_sources
    spec = {"preset": "full"}
    setup = setup_from_spec(spec)
    design = FastSystemBench(replay_depth=frame_period_samples(setup), **setup.system_kwargs())
    out = Path(tmp) / simulator
    wall = time.perf_counter()
    run_cocotb(_export(design, "system_fast"), name="system_fast", test_module="cocotb_system",
               simulator=simulator, testcase="rate_probe", build_args=build_args(simulator, True),
               extra_sources=(write_sources(REPO_ROOT / "build" / "cocotb"),),
               params={"setup": spec, "out_dir": str(out), "probe_us": PROBE_US[simulator]},
               verilator_fast=True)
    total = time.perf_counter() - wall
    probe = json.loads((out / "probe.json").read_text())
    return probe["probe_us"] * 1e-6, probe["wall_s"], total - probe["wall_s"]


def _probe_rate_amaranth():
    from amaranth.sim import Simulator
    from sim.system_bench import SystemBench
    from sim.system_cocotb import setup_from_spec
    setup = setup_from_spec({"preset": "full"})
    bench = SystemBench(**setup.system_kwargs())
    sim = Simulator(bench)
    sim.add_clock(1 / SYS_HZ, domain="sync")
    sim.add_clock(1 / PIX_HZ, domain="pix")
    sim.add_clock(1 / PCLK_HZ, domain="cam_a")
    sim.add_clock(1 / PCLK_HZ, domain="cam_b")
    wall = time.perf_counter()
    sim.run_until(PROBE_US["amaranth"] * 1e-6)
    return PROBE_US["amaranth"] * 1e-6, time.perf_counter() - wall


def main():
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench_system_") as tmp:
        v = bench_verilator(tmp)
        sim_s = v["sim_s"]
        total_cycles = sum(v["cycles"].values())
        rows.append(("verilator", "measured (whole run)", v["run_wall_s"], total_cycles / v["run_wall_s"],
                     v["cycles"]["pix"] / v["run_wall_s"]))
        print(f"verilator: frame {'equals' if v['ok'] else 'DIFFERS from'} the golden frame; simulated "
              f"{sim_s * 1e3:.1f} ms; run {v['run_wall_s']:.0f} s (phases: I2C init to "
              f"{v['phases']['init']:.0f} s, capture to {v['phases']['capture']:.0f} s, display to "
              f"{v['phases']['display']:.0f} s); export + build {v['build_and_export_s']:.0f} s", flush=True)
        per_s = total_cycles / sim_s            # design clock cycles per simulated second (for the probes)
        pix_share = v["cycles"]["pix"] / total_cycles
        for simulator in ("icarus",):
            probe_s, wall, build = _probe_rate_cocotb(simulator, tmp)
            rate = probe_s * per_s / wall        # probes run every clock: cycles in the slice / wall
            rows.append((simulator, f"extrapolated from {probe_s * 1e6:.0f} us", total_cycles / rate, rate,
                         rate * pix_share))
            print(f"{simulator}: {probe_s * 1e6:.0f} us of full-size simulation in {wall:.1f} s (+ {build:.0f} s "
                  f"export/build)", flush=True)
        probe_s, wall = _probe_rate_amaranth()
        rate = probe_s * per_s / wall
        rows.append(("amaranth", f"extrapolated from {probe_s * 1e6:.0f} us", total_cycles / rate, rate,
                     rate * pix_share))
        print(f"amaranth: {probe_s * 1e6:.0f} us of full-size simulation in {wall:.1f} s", flush=True)
    print()
    print(f"one full-resolution end-to-end frame ({sim_s * 1e3:.1f} ms simulated, {total_cycles / 1e6:.1f} M clock "
          f"cycles over all domains, {v['cycles']['pix'] / 1e6:.2f} M pixel clocks):")
    print(f"{'simulator':10} {'how':28} {'wall time':>12} {'cycles/s':>12} {'pix clocks/s':>13}")
    for name, how, wall, rate, pix in rows:
        shown = f"{wall:,.0f} s" if wall < 36_000 else f"{wall / 3600:,.1f} h"
        print(f"{name:10} {how:28} {shown:>12} {rate:>12,.0f} {pix:>13,.0f}")
    print("target: under 2 minutes on Verilator -- "
          + ("met" if rows[0][2] < 120 else f"NOT met ({rows[0][2]:.0f} s on this machine)"))


if __name__ == "__main__":
    main()
