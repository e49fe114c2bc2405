"""Multi-frame whole-system runs at full size on Verilator (docs/capture.md, "Frame after frame"): the test bed's
card moving from 3 m to 0.5 m over N camera frames of both 1600 x 1200 sensors and every 1080p display frame
they overlap.

Printed (all from the run's result, ``sim.system.simulate``): the wall time (build apart), simulated time, display
frames, per display frame the frames the captures had completed, the rows of the depth panel from each camera frame,
the mixed ones and those withheld at a tear, and the tear found against the torn golden map (the run's verdict,
``sim/system/verdict.py``); the centre distance shown against the truth and bad > 2 against the scene's truth; the
frame-start skew (the
captures' ``in_frame`` in simulation, the design's skew meter in ``sync`` clocks); whether the settled frame equals
the golden frame of the last pair. ``--frames N`` (default 3), ``--ppm P`` and ``--delay-us T`` put camera B's PCLK
off by P ppm and its start T microseconds late (the sensor model's knobs for the synchronisation figures).
``--memory ddr2`` runs the DDR2 build (the camera frames in the frame store behind the MIG model) instead of the
block-RAM build (``bram``, the default) and prints its promise too: the pair each display frame shows and whether
every display frame is made from one camera-frame pair (``display_frames_from_one_pair``: no row withheld, none
mixed). ``--video`` sends the same card through the video input: the rendered pairs written as two lossless (FFV1)
video files and read back by ``sim.testbed.sequence.sequence_from_videos``, the path of ``stereodepth run L.avi R.avi
--frames N``, the scene's truth kept.
"""

import argparse
import time


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m bench frames", description=__doc__)
    parser.add_argument("--frames", type=int, default=3)
    parser.add_argument("--ppm", type=float, default=0.0)
    parser.add_argument("--delay-us", type=float, default=0.0)
    parser.add_argument("--disparity", type=int, default=20)
    parser.add_argument("--memory", choices=("bram", "ddr2"), default="bram")
    parser.add_argument("--video", action="store_true", help="the card through two lossless video files")
    args = parser.parse_args(argv or [])
    from sim.analysis.depth_panel import depth_summary
    from sim.runners.verilator.build import build
    from sim.system import Verilator, simulate
    from sim.testbed.sequence import moving_card
    from sim.testbench.system.setup import SystemSetup
    setup = SystemSetup.full(disparity=args.disparity, cam_phase_s={"a": 0.0, "b": args.delay_us * 1e-6},
                             cam_clock_ppm={"b": args.ppm}, memory=args.memory)
    t = time.perf_counter()
    build(setup)
    print(f"build (cached or made now): {time.perf_counter() - t:.1f} s")
    sequence = moving_card(setup, args.frames)
    if args.video:
        sequence = through_videos(sequence, setup)
    t = time.perf_counter()
    result = simulate(setup, sequence, Verilator())
    wall = time.perf_counter() - t
    status, shown = result.status, result.frames
    print(f"{args.memory} build, {'video files' if args.video else 'rendered frames'}: {args.frames} camera frames -> {len(shown)} display frames: {wall:.1f} s wall, "
          f"{status['t_end_s'] * 1e3:.1f} ms simulated, {wall / len(shown):.1f} s a display frame")
    layout, g = setup.display_layout, setup.geometry
    for s in shown:
        k = s.verdict
        d = k["depth_frame"]
        depth = depth_summary(s.frame, layout, g, setup.depth, sequence.truth[d] if d is not None and d >= 0 else None)
        truth = sequence.centre_m[d] if d is not None and d >= 0 else None
        print(f"  display frame {s.index:2d} at {s.t_start_s * 1e3:7.2f} ms: captured {s.captured['a']}/"
              f"{s.captured['b']}, depth rows {k['depth_rows_by_frame']}, mixed {k['depth_rows_mixed']}, withheld "
              f"{k.get('depth_rows_withheld')}, tear {k.get('tear')}, centre {depth['centre_distance_cm']} cm "
              f"(truth {None if truth is None else round(100 * truth, 1)}), bad > 2 {depth.get('bad2')}")
    events = status["capture_events_s"]
    sim_skew = [(b - a) * 1e6 for a, b in zip(events["a"]["frame_start"], events["b"]["frame_start"])]
    print(f"frame-start skew B - A in simulation (us): {[round(x, 4) for x in sim_skew]}")
    print(f"the design's skew meter (sync clocks): {[m['skew_sync_clocks'] for m in status['hardware_skew']]}, "
          f"aligned {[m['aligned'] for m in status['hardware_skew']]}")
    torn = [s.verdict for s in shown if s.verdict.get("tear")]
    consistent = sum(1 for s in shown if s.verdict["consistent"])
    print(f"display frames without a mixed depth row: {consistent}/{len(shown)}")
    print(f"display frames computed across a tear: {len(torn)}, mixed rows against the torn golden "
          f"{[t['depth_rows_mixed'] for t in torn]}, withheld at the tear {[t['depth_rows_withheld'] for t in torn]}")
    print(f"settled frame equals the last pair's golden frame: {result.verdict['settled_equals_last_pair']}")
    if "pairs_shown" in result.verdict:
        withheld = sum(s.verdict.get("depth_rows_withheld") or 0 for s in shown)
        print(f"DDR2 frame store: pair shown per display frame {result.verdict['pairs_shown']} (-1: the empty "
              f"buffers); every display frame from one camera-frame pair: "
              f"{result.verdict['display_frames_from_one_pair']}; withheld depth rows in all: {withheld}; display "
              f"reads refused in {status.get('display_missed')} pixel clocks")
    print(f"verdict ok: {result.verdict['ok']}")


def through_videos(sequence, setup):
    """``sequence``'s pairs written as two lossless video files (FFV1 in AVI) and read back as the command line
    reads a video pair; the truth, centre distances and names carried over. Exits if OpenCV has no FFV1 encoder."""
    import tempfile
    from pathlib import Path

    import cv2

    from sim.testbed.sequence import sequence_from_videos
    with tempfile.TemporaryDirectory() as tmp:
        paths = [Path(tmp) / "left.avi", Path(tmp) / "right.avi"]
        height, width = sequence.pairs[0][0].shape[:2]
        for side, path in enumerate(paths):
            writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"FFV1"), 15, (width, height))
            if not writer.isOpened():
                raise SystemExit("--video: OpenCV has no FFV1 encoder here")
            for pair in sequence.pairs:
                writer.write(cv2.cvtColor(pair[side], cv2.COLOR_RGB2BGR))
            writer.release()
        read = sequence_from_videos(*paths, setup, frames=len(sequence.pairs))
    if any((a != b).any() for p, q in zip(read.pairs, sequence.pairs) for a, b in zip(p, q)):
        raise SystemExit("--video: the frames read back differ from those written (the codec is not lossless)")
    read.truth, read.centre_m, read.names = sequence.truth, sequence.centre_m, sequence.names
    return read

