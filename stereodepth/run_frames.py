"""``stereodepth run --frames N``: the whole simulated system on a moving scene, camera frame after camera frame.

Inputs (:mod:`sim.testbed.sequence`): LEFT and RIGHT two folders of images (paired in file-name order), two
video files (frame k of each a pair), or two image files (the same pair every frame; ``--ground-truth`` then gives
every frame its truth), or ``--scene card`` (the
synthetic test bed, a textured card moving from ``--far`` to ``--near`` metres over the run). The two sensor
models send N camera frames, one image each, and every display frame from the first after the I2C init to the
first one that starts after both captures have finished frame N is rebuilt from the simulated pins
(``sim.system.simulate``, which also judges each display frame: ``sim/system/verdict.py``): on Verilator (the C++
testbench; full size or small), on Amaranth's simulator (small) or on Icarus through cocotb (small; the frames
arrive when the simulation ends). This module turns the arguments into the sequence and prints the summary; the
files are written by ``sim/system/frame_files.py`` as each judged frame arrives.

Written into ``--out`` as the run goes (so Ctrl-C leaves every finished display frame readable):

* ``frames/hdmi_NNN.png`` (the display frame from the pins) and ``frames/depth_NNN.png`` (its depth panel at buffer
  size with the colour bar);
* ``frames.csv``: one row per display frame (a line appended and flushed per frame): its start time, the frames
  each capture had completed, which camera frame every panel's rows come from (``sim/analysis/frame_sources.py``:
  mixed depth rows, rows withheld at a tear, consistent, equal to a pair's golden frame), the centre distance
  shown against the truth and, with a truth, bad > 1 / bad > 2 / density of the depth panel;

and at the end (on Ctrl-C from the frames so far, under their partial names: ``frames.partial.csv``, ...):
``hdmi_video.png`` (animated PNG of the display frames, lossless), ``hdmi_video.mp4`` (the same as MP4, where
OpenCV's FFmpeg has an MPEG-4 encoder: the run's summary says when it does not), ``depth_video.gif`` (the depth
panels), ``result.json`` (the run's status, the per-frame table under ``frames``, the frame-start skew between the
cameras, provenance).

In automatic rectification (``--rectification auto``; with ``--scene card --vertical-offset V[,V2,...]`` the rig
knocked mid-run) the goldens are :mod:`sim.analysis.auto_rectification`'s (the golden estimator over the captured
buffers; each pair with the state before and after its search), the table adds ``rectification_shown`` /
``rectification_expected`` and result.json ``auto_rectification_run``; the settled frame must show the expected
state.

The check: the last display frame (the settled one: no capture writes the buffers any more) equals the golden
model's frame of the last pair bit for bit, every image-panel row comes from some camera frame, and the sink saw
no timing violation.
"""

import json
import sys
import time
from pathlib import Path

from .errors import UserError, prepare_out_dir
from .interrupts import whole_step
from .outputs import RunOutputs, write_atomic
from .progress import Progress

#: Files (besides ``frames/*``) a multi-frame run writes into ``--out``.
OUTPUTS = ("frames.csv", "hdmi_video.png", "hdmi_video.mp4", "depth_video.gif", "result.json")


def load_images(left, right, setup):
    """The pair fitted to the sensor; one-line :class:`UserError` for a missing, unreadable, mismatched, too large
    (``golden.image_file.MAX_PIXELS``) pair, or one whose crop to the sensor's aspect is smaller than the frame
    buffer (it would be enlarged beyond what the buffers hold)."""
    from golden.stereo_pair import load_pair
    from sim.testbed.sequence import VIDEO_SUFFIXES
    if any(Path(p).suffix.lower() in VIDEO_SUFFIXES for p in (left, right)):
        raise UserError(f"{left} / {right}: video files run frame after frame: add --frames N")
    g = setup.geometry
    try:
        return load_pair(left, right, g.width, g.height, min_size=(g.buf_width, g.buf_height))
    except (OSError, ValueError) as exc:
        raise UserError(str(exc)) from None


def build_sequence(args, setup):
    """The run's :class:`~sim.testbed.sequence.FrameSequence` from the command line."""
    from sim.testbed.sequence import VIDEO_SUFFIXES, moving_card, repeated_pair, sequence_from_folders, \
        sequence_from_videos
    if args.frames < 1:
        raise UserError(f"--frames must be at least 1, got {args.frames}")
    if getattr(args, "ground_truth", None) is not None and (args.scene is not None or Path(args.left or "").is_dir()
                                                            or Path(args.left or "").suffix.lower() in VIDEO_SUFFIXES):
        raise UserError("--ground-truth with --frames is for two image files (the pair every frame): --scene card "
                        "has its own truth, folders and videos have none")
    if getattr(args, "vertical_offset", None) is not None and args.scene is None:
        raise UserError("--vertical-offset is for --scene card (the test bed renders the misaligned rig)")
    if args.scene is not None:
        if args.left is not None or args.right is not None:
            raise UserError("--scene card renders its own images: give no LEFT/RIGHT")
        return moving_card(setup, args.frames, args.far, args.near, card_offsets(args, setup))
    if args.left is None or args.right is None:
        raise UserError("give LEFT and RIGHT (two image files or two folders), or --scene card")
    left, right = Path(args.left), Path(args.right)
    if left.is_dir() or right.is_dir():
        if not (left.is_dir() and right.is_dir()):
            raise UserError(f"LEFT and RIGHT must both be folders or both be image files ({left}, {right})")
        return sequence_from_folders(left, right, setup, args.frames)
    videos = [p.suffix.lower() in VIDEO_SUFFIXES for p in (left, right)]
    if any(videos):
        if not all(videos):
            raise UserError(f"LEFT and RIGHT must both be video files or both be image files ({left}, {right})")
        return sequence_from_videos(left, right, setup, args.frames)
    l_img, r_img = load_images(left, right, setup)
    sequence = repeated_pair(l_img, r_img, args.frames, setup, sources=[left, right])
    if getattr(args, "ground_truth", None) is not None:
        from golden.image_file import image_size
        from sim.analysis.depth_panel import read_truth
        truth = read_truth(args.ground_truth, image_size(left), setup.geometry, view=args.truth_view)
        sequence.truth = [truth] * len(sequence)
    return sequence


def card_offsets(args, setup):
    """``--vertical-offset V[,V2,...]`` (sensor rows) as the per-frame schedule (``offset_schedule``), or None."""
    from sim.testbed.sequence import offset_schedule
    text = getattr(args, "vertical_offset", None)
    if text is None:
        return None
    try:
        values = [int(v, 0) for v in text.split(",")]
    except ValueError:
        raise UserError(f"--vertical-offset takes integers in sensor rows, comma-separated, not {text!r}") from None
    limit = setup.geometry.height // 4
    if any(abs(v) > limit for v in values):
        raise UserError(f"--vertical-offset: at most +-{limit} sensor rows at this size, got {text}")
    return offset_schedule(args.frames, values)


def progress_bar(simulator):
    """A progress bar for a run on ``simulator`` and its ``progress(stage, fraction)``."""
    bar = Progress(simulator if simulator == "amaranth" else f"{simulator}: build (first run only)")
    return bar, lambda stage, fraction: bar.update(int(1000 * fraction), f"{simulator}: {stage}")


def run_frames(args, setup, started):
    from sim import SimulationFailed
    from sim.system import backend_named, simulate
    from sim.system.frame_files import FrameFiles, skew_figures
    out = prepare_out_dir(args.out)
    sequence = build_sequence(args, setup)
    backend = backend_named(args.simulator, work_dir=Path(args.out) / f".{args.simulator}")
    backend.require(setup, sequence)
    outputs = RunOutputs(out, OUTPUTS, stale=("frames/*.png",)).start()
    writer = FrameFiles(out, setup, sequence, write=write_atomic, guard=whole_step)
    wall = time.perf_counter()
    status, verdict, interrupted = {}, {"ok": False}, False
    bar, progress = progress_bar(args.simulator)
    try:
        result = simulate(setup, sequence, backend, on_frame=writer, progress=progress)
        status, verdict = result.status, result.verdict
    except KeyboardInterrupt:
        interrupted = True
    except SimulationFailed as exc:
        bar.close()
        print(f"stereodepth run: simulation failed: {exc}", file=sys.stderr)
        status = {"failed": str(exc)}
    finally:
        bar.close()
    wall = time.perf_counter() - wall
    files = writer.finish(outputs, complete=not interrupted)
    record = dict(status, interrupted=interrupted, total_wall_s=wall, simulator=args.simulator,
                  frames_in=len(sequence), inputs=sequence.names, frames=writer.rows,
                  settled_equals_last_pair=bool(verdict.get("settled_equals_last_pair")) and not interrupted,
                  image_rows_from_camera_frames=all(r["left_rows_mixed"] <= 1 and r["right_rows_mixed"] <= 1
                                                    for r in writer.rows))
    if "capture_events_s" in status:
        record["skew"] = skew_figures(status, setup)
    if "auto_rectification_run" in verdict:
        record["auto_rectification_run"] = verdict["auto_rectification_run"]
    if "pairs_shown" in verdict:            # the DDR2 build: every display frame from one pair
        record.update({k: verdict[k] for k in ("pairs_shown", "display_frames_from_one_pair",
                                                "display_frames_from_whole_pairs") if k in verdict})
    from stereodepth.provenance import provenance
    record["provenance"] = provenance(list(sequence.sources), dict(vars(args), setup=setup.to_spec()), started)
    outputs.partial("result.json").write_text(json.dumps(record, indent=1, default=str) + "\n")
    files["result"] = outputs.partial("result.json") if interrupted else outputs.commit("result.json")
    ok = verdict["ok"] and not interrupted
    print_summary(record, setup, ok)
    print("wrote:")
    for what, path in files.items():
        print(f"  {path}   {what}")
    if interrupted:
        raise KeyboardInterrupt
    return 0 if ok else 1


def print_summary(result, setup, ok):
    from sim.system.frame_files import rows_text
    g, t = setup.geometry, setup.timing
    rows = result["frames"]
    print(f"whole system, {result['frames_in']} camera frames of {g.width}x{g.height} -> {len(rows)} display "
          f"frames of {t.h_active}x{t.v_active}, on {result['simulator']}: {result['total_wall_s']:.1f} s wall time")
    if "skew" in result:
        skew = result["skew"]
        print(f"  frame-start skew B - A in simulation: max {skew['max_abs_skew_lines']} sensor lines over "
              f"{len(skew['frame_start_skew_us'])} frames; the design's meter: "
              f"{skew['hardware_skew_sync_clocks']} sync clocks, aligned {skew['hardware_aligned']}")
    consistent = sum(1 for r in rows if r["consistent"])
    print(f"  display frames with no mixed depth row: {consistent}/{len(rows)}")
    for r in rows:
        print(f"  frame {r['display_frame']:3d} t {r['t_start_ms']:8.3f} ms  captured {r['cam_a_frames_done']}/"
              f"{r['cam_b_frames_done']}  depth rows {rows_text(r['depth_rows_by_frame']) or '-'} mixed "
              f"{r['depth_rows_mixed']}"
              + (f" withheld {r['depth_rows_withheld']}" if r.get("depth_rows_withheld") else "")
              + f"  centre {r['centre_shown_cm']} cm (truth {r['centre_truth_cm']})"
              + (f"  bad>2 {100 * r['bad2']:.1f} %" if r["bad2"] is not None else "")
              + (f"  rect {r['rectification_shown']} (expected {r['rectification_expected']})"
                 if "rectification_shown" in r else ""))
    if "auto_rectification_run" in result:
        auto = result["auto_rectification_run"]
        print(f"  automatic rectification, rig vertical offset per camera frame {auto['rig_vertical_offset_rows']} "
              f"sensor rows; expected in use {auto['expected_per_camera_frame']}")
        for c in auto["changes"] or [None]:
            print("  the offset in use never changed" if c is None else
                  f"  offset in use {c['from']} -> {c['to']} after camera frame {c['after_camera_frame']}'s search"
                  + (f" ({c['camera_frames_after_knock']} camera frames after the knock)"
                     if c["knock_camera_frame"] is not None else "")
                  + f", first shown on display frame {c['first_display_frame_shown']}")
    if "display_frames_from_whole_pairs" in result:     # the depth maps in the frame store
        print(f"  DDR2 frame store: (images' pair, depth map's pair) per display frame {result['pairs_shown']} (-1: "
              "the empty buffers; None: no map yet); " + ("every display frame one pair's images with one pair's whole map"
                                        if result["display_frames_from_whole_pairs"]
                                        else "NOT every display frame one pair's images with one pair's whole map"))
    elif "pairs_shown" in result:
        print(f"  DDR2 frame store: pair shown per display frame {result['pairs_shown']} (-1: the empty buffers); "
              + ("every display frame equals one pair's golden frame" if result["display_frames_from_one_pair"]
                 else "NOT every display frame equals one pair's golden frame"))
    if "display_missed" in result:
        print(f"  DDR2 frame store: display reads refused in {result['display_missed']} pixel clocks")
    print("  the settled display frame equals the golden frame of the last pair"
          if result["settled_equals_last_pair"] else "  the settled display frame does NOT equal the last pair's")
    print("OK" if ok else "FAILED")
