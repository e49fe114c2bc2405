"""The frame store's worst case (docs/frame_store.md, "The worst case"): ``FrameStore`` on the MIG model
(``sim/testbench/frame_store_worst_case.py``) with the largest read latency (32 clk0), a refresh every tREFI, both
cameras writing every buffer row at the capture's rate (a kept pixel every 100 ns), two engine streams reading as
fast as they are granted and four display streams each showing a 400-pixel buffer row on every 2200-clock line of
the 1080p raster; pix 148.5 MHz, mem 125 MHz, cam 80 MHz.

Printed: whether the display was ever refused, the least time a display row landed before its first pixel and the
fewest rows landed beyond the one starting to show, the DDR2 bandwidth each stream needs and gets (the display's,
the cameras' writes, the engine's), all streams' and the user interface's efficiency (read and written words per
clk0), the refreshes covered; MIG violations stop the run. ``--rows``, ``--frames``: the buffer's rows and the
display frames measured (2 blank lines + ``rows`` lines each); ``--latency``; ``--fifo-depth``: the MIG model's
address FIFO; ``--banks``: the banks the buffers are spread over (1: all in bank 0, to compare); ``--not-urgent``:
the display's camera streams served after the writers and the engine (the bite); ``--build 800``: the 800 x 600
build's store (800-pixel 8-bit rows written at the averaging capture's rate, a pixel every 50 ns; the half-size
panels, every second row, then the difference map's rows at 1:1 on the display's two camera streams; the map buffers
with the map writer writing a code a clock while the store has room and the map stream read by the depth panel at
1:1, two bytes a code; ``--rows`` even), which also prints the map stream's and the map writer's figures;
``--map-row-clocks``: the pix clocks between the rows the map writer is given (by default an engine pass, 11,247:
the design's; 0: every row at once, so the writer drains row after row at a code a clock, 297 MB/s);
``--map-backlog``: rows ready at a map's start, drained back to back (the engine's ring of 4 full: a writer held
back for three passes); ``--map-pace``: the map writer's clocks a code (the design's ``MAP_PACE``, 1).
"""

import argparse
import time


def main(argv=None):
    from hdl.stereo_display import MAP_PACE
    from sim.models.mig import READ_LATENCY_RANGE
    from sim.testbench.frame_store_worst_case import BUILDS, WorstCase, run_worst_case
    from spec.memory import MIG
    parser = argparse.ArgumentParser(prog="python -m bench frame_store_worst_case", description=__doc__)
    parser.add_argument("--rows", type=int, default=6)
    parser.add_argument("--frames", type=int, default=2)
    parser.add_argument("--latency", type=int, default=READ_LATENCY_RANGE[1])
    parser.add_argument("--not-urgent", action="store_true")
    parser.add_argument("--engine-streams", type=int, default=2, help="greedy engine readers (the design: 2)")
    parser.add_argument("--fifo-depth", type=int, default=1024, help="the MIG model's address FIFO (MIG: 1024)")
    parser.add_argument("--banks", type=int, default=MIG.BANKS,
                        help="banks the buffers are spread over (1: all in bank 0)")
    parser.add_argument("--build", type=int, choices=BUILDS, default=400,
                        help="400: the 400 x 300 store; 800: the 800 x 600 build's, the maps in it")
    parser.add_argument("--map-row-clocks", type=int, default=None,
                        help="800: pix clocks between the map writer's rows (default: an engine pass, the design's; "
                             "0: row after row)")
    parser.add_argument("--map-backlog", type=int, default=0,
                        help="800: map rows ready at a map's start, drained back to back (the engine's ring holds 4)")
    parser.add_argument("--map-pace", type=int, default=MAP_PACE,
                        help=f"800: the map writer's clocks a code (the design: {MAP_PACE})")
    args = parser.parse_args(argv or [])
    lo, hi = READ_LATENCY_RANGE
    try:
        case = WorstCase(rows=args.rows, frames=args.frames, latency=args.latency,
                         latency_range=(lo, max(hi, args.latency)), display_urgent=not args.not_urgent,
                         mig_fifo_depth=args.fifo_depth, banks=args.banks, engine_streams=args.engine_streams,
                         build=args.build, map_row_clocks=args.map_row_clocks,
                         map_backlog=args.map_backlog, map_pace=args.map_pace)
    except ValueError as e:
        raise SystemExit(f"python -m bench frame_store_worst_case: {e}")
    wall = time.perf_counter()
    result = run_worst_case(case)
    print(f"{case.describe()}, read latency {args.latency} clk0, "
          f"display {'urgent' if case.display_urgent else 'after the writers and the engine'}, "
          f"{case.engine_streams} greedy engine streams, buffers in "
          f"{case.layout.banks_used} bank(s)")
    print(result.report())
    print(f"wall {time.perf_counter() - wall:.1f} s")
