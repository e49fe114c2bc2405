"""Multi-frame whole-system runs at full size on Verilator (docs/capture.md, "Frame after frame"): the test bed's
card moving from 3 m to 0.5 m over N camera frames of both 1600 x 1200 sensors and every 1080p display frame
they overlap.

Printed: the wall time (build apart), simulated time, display frames, per display frame the frames the captures had
completed, the rows of the depth panel from one camera frame and the mixed ones (``sim/analysis/frame_sources.py``),
for a display frame with mixed rows the tear found against the torn golden map (row c, frames k above and k' below,
row c torn or not) and its rows from a frame, invalid at the tear and still mixed; the centre distance shown
against the truth and bad > 2 against the scene's truth; the frame-start skew (the
captures' ``in_frame`` in simulation, the design's skew meter in ``sync`` clocks); whether the settled frame equals
the golden frame of the last pair. ``--frames N`` (default 3), ``--ppm P`` and ``--delay-us T`` put camera B's PCLK
off by P ppm and its start T microseconds late (the sensor model's knobs for the synchronisation figures).
"""

import argparse
import time


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m bench frames", description=__doc__)
    parser.add_argument("--frames", type=int, default=3)
    parser.add_argument("--ppm", type=float, default=0.0)
    parser.add_argument("--delay-us", type=float, default=0.0)
    parser.add_argument("--disparity", type=int, default=20)
    args = parser.parse_args(argv or [])
    import numpy as np
    from sim.analysis.depth_panel import depth_summary
    from golden.capture import capture_frame
    from sim.analysis.frame_sources import EMPTY, frame_sources, source_summary, torn_depth_rows, torn_summary
    from sim.runners.verilator.build import build
    from sim.testbed.sequence import moving_card
    from sim.testbench.system.frames_verilator import run_verilator_frames
    from sim.testbench.system.setup import SystemSetup
    setup = SystemSetup.full(disparity=args.disparity, cam_phase_s={"a": 0.0, "b": args.delay_us * 1e-6},
                             cam_clock_ppm={"b": args.ppm})
    t = time.perf_counter()
    build(setup)
    print(f"build (cached or made now): {time.perf_counter() - t:.1f} s")
    sequence = moving_card(setup, args.frames)
    black = np.zeros_like(sequence.pairs[0][0])
    goldens = {EMPTY: setup.golden_frame(black, black),
               **{k: setup.golden_frame(*pair) for k, pair in enumerate(sequence.pairs)}}
    shown = []
    t = time.perf_counter()
    status, _ = run_verilator_frames(sequence, setup, on_frame=shown.append)
    wall = time.perf_counter() - t
    print(f"{args.frames} camera frames -> {len(shown)} display frames: {wall:.1f} s wall, "
          f"{status['t_end_s'] * 1e3:.1f} ms simulated, {wall / len(shown):.1f} s a display frame")
    layout, g = setup.display_layout, setup.geometry
    zeros = np.zeros((g.buf_height, g.buf_width), np.uint8)
    buffers = {EMPTY: (zeros, zeros), **{k: (capture_frame(setup.fit(left), g), capture_frame(setup.fit(right), g))
                                         for k, (left, right) in enumerate(sequence.pairs)}}
    summaries, torn_frames = [], []
    for s in shown:
        k = source_summary(frame_sources(s.frame, goldens, layout, g))
        d = k["depth_frame"]
        depth = depth_summary(s.frame, layout, g, setup.depth, sequence.truth[d] if d is not None and d >= 0 else None)
        truth = sequence.centre_m[d] if d is not None and d >= 0 else None
        summaries.append(k)
        print(f"  display frame {s.index:2d} at {s.t_start_s * 1e3:7.2f} ms: captured {s.captured['a']}/"
              f"{s.captured['b']}, depth rows {k['depth_rows_by_frame']}, mixed {k['depth_rows_mixed']}, centre "
              f"{depth['centre_distance_cm']} cm (truth {None if truth is None else round(100 * truth, 1)}), "
              f"bad > 2 {depth.get('bad2')}")
        if k["depth_rows_mixed"]:
            t = torn_summary(torn_depth_rows(s.frame, buffers, layout, g, setup.depth,
                                             rectification=setup.rectification, window=12))
            torn_frames.append(t)
            print(f"    torn golden: tear (c, k, k', torn) {t['tear']}: rows from {t['depth_rows_from']}, invalid at "
                  f"the tear {t['depth_rows_invalid_at_tear']}, mixed {t['depth_rows_mixed_at_tear']}")
    events = status["capture_events_s"]
    sim_skew = [(b - a) * 1e6 for a, b in zip(events["a"]["frame_start"], events["b"]["frame_start"])]
    print(f"frame-start skew B - A in simulation (us): {[round(x, 4) for x in sim_skew]}")
    print(f"the design's skew meter (sync clocks): {[m['skew_sync_clocks'] for m in status['hardware_skew']]}, "
          f"aligned {[m['aligned'] for m in status['hardware_skew']]}")
    consistent = sum(1 for k in summaries if k["consistent"])
    print(f"display frames without a mixed depth row: {consistent}/{len(summaries)}")
    print(f"torn display frames: {len(torn_frames)}, mixed rows against the torn golden "
          f"{[t['depth_rows_mixed_at_tear'] for t in torn_frames]}, invalid at the tear "
          f"{[t['depth_rows_invalid_at_tear'] for t in torn_frames]}")
    print(f"settled frame equals the last pair's golden frame: {summaries[-1]['equals_pair'] == args.frames - 1}")
