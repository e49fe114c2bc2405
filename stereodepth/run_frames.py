"""``stereodepth run --frames N``: the whole simulated system on a moving scene, camera frame after camera frame.

Inputs (:mod:`sim.testbed.sequence`): LEFT and RIGHT two folders of images (paired in file-name order), two
video files (frame k of each a pair), or two image files (the same pair every frame), or ``--scene card`` (the
synthetic test bed, a textured card moving from ``--far`` to ``--near`` metres over the run). The two sensor
models send N camera frames, one image each, and every display frame from the first after the I2C init to the
first one that starts after both captures have finished frame N is rebuilt from the simulated pins: on Verilator
(the C++ testbench; full size or small), on Amaranth's simulator (small) or on Icarus through cocotb (small; the
frames arrive when the simulation ends).

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

import csv
import json
import re
import sys
import time
from pathlib import Path

import numpy as np

from .errors import UserError, prepare_out_dir
from .interrupts import whole_step
from .outputs import RunOutputs, write_atomic
from .progress import Progress

#: Files (besides ``frames/*``) a multi-frame run writes into ``--out``.
OUTPUTS = ("frames.csv", "hdmi_video.png", "hdmi_video.mp4", "depth_video.gif", "result.json")
#: Columns of ``frames.csv``.
COLUMNS = ("display_frame", "t_start_ms", "cam_a_frames_done", "cam_b_frames_done", "left_rows_by_frame",
           "right_rows_by_frame", "disparity_rows_by_frame", "depth_rows_by_frame", "depth_rows_mixed",
           "depth_rows_withheld", "tear",
           "consistent", "equals_pair", "depth_frame", "centre_shown_cm", "centre_truth_cm", "bad1", "bad2",
           "density")
#: Columns added in automatic rectification (:mod:`sim.analysis.auto_rectification`): the offset in use and mode
#: the display frame shows (the state of the golden it equals) and the one expected from the golden estimator.
AUTO_COLUMNS = ("rectification_shown", "rectification_expected")


def build_sequence(args, setup):
    """The run's :class:`~sim.testbed.sequence.FrameSequence` from the command line."""
    from sim.testbed.sequence import VIDEO_SUFFIXES, moving_card, repeated_pair, sequence_from_folders, \
        sequence_from_videos
    if args.frames < 1:
        raise UserError(f"--frames must be at least 1, got {args.frames}")
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
    from .cmd_run import load_images
    l_img, r_img = load_images(left, right, setup)
    return repeated_pair(l_img, r_img, args.frames, setup, sources=[left, right])


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


def _rows_text(counts):
    """``{"0": 3, "0..2": 9, "1|0": 2}`` as ``"0:3 0..2:9 1|0:2"``, in frame order."""
    def order(key):
        lo, hi = (int(v) for v in re.match(r"(-?\d+)(?:\.\.|\|)?(-?\d+)?", key).groups(default=key.split("|")[0]))
        return lo, hi
    return " ".join(f"{k}:{counts[k]}" for k in sorted(counts, key=order))


class FrameWriter:
    """Receives the display frames: writes each one's files and table row at once, keeps what the end needs."""

    def __init__(self, out, setup, sequence, goldens, auto=None):
        self.out, self.setup, self.sequence, self.goldens, self.auto = out, setup, sequence, goldens, auto
        self.columns = COLUMNS + (AUTO_COLUMNS if auto is not None else ())
        (out / "frames").mkdir(exist_ok=True)
        self.rows, self.hdmi, self.depth = [], [], []
        self.csv_file = open(out / "frames.partial.csv", "w", newline="")
        self.csv = csv.DictWriter(self.csv_file, self.columns)
        self.csv.writeheader()
        self.last_frame = None
        self.buffers = None             # the pairs' grey buffers, made at the first tear

    def __call__(self, shown):
        from sim.analysis.depth_panel import depth_picture_png, depth_summary, panel_picture
        from sim.analysis.frame_sources import frame_sources, source_summary
        from sim.models.ch7301c.hdmi_sink import write_png
        setup, frame = self.setup, shown.frame
        layout, g = setup.display_layout, setup.geometry
        if self.auto is not None:       # automatic rectification: either state of each pair (auto_rectification)
            sources = self.auto.row(frame, layout, g, min(shown.captured["a"], shown.captured["b"]))
        else:
            raw = frame_sources(frame, self.goldens, layout, g, setup.depth)
            sources = source_summary(raw)
            if sources["depth_rows_mixed"] or sources["depth_rows_withheld"]:
                sources.update(self.tear(frame, raw, min(shown.captured["a"], shown.captured["b"])))
        k = sources["depth_frame"]
        truth = self.sequence.truth[k] if k is not None and k >= 0 else None
        depth = depth_summary(frame, layout, g, setup.depth, truth)
        centre_m = self.sequence.centre_m[k] if k is not None and k >= 0 else None
        row = {"display_frame": shown.index, "t_start_ms": round(shown.t_start_s * 1e3, 4),
               "cam_a_frames_done": shown.captured["a"], "cam_b_frames_done": shown.captured["b"],
               **sources, "centre_shown_cm": depth.get("centre_distance_cm"),
               "centre_truth_cm": None if centre_m is None else round(100 * centre_m, 1),
               "bad1": depth.get("bad1"), "bad2": depth.get("bad2"), "density": depth.get("density")}
        name = f"{shown.index:03d}"
        picture = panel_picture(frame, layout)
        with whole_step():                              # a Ctrl-C now leaves this frame's files and row whole
            write_atomic(self.out / "frames" / f"hdmi_{name}.png", lambda p: write_png(frame, p))
            write_atomic(self.out / "frames" / f"depth_{name}.png",
                         lambda p: depth_picture_png(picture, p, g, setup.depth))
            self.csv.writerow({c: (_rows_text(row[c]) if c.endswith("_by_frame") else row.get(c))
                               for c in self.columns})
            self.csv_file.flush()
            self.rows.append(row)
            self.hdmi.append(self.out / "frames" / f"hdmi_{name}.png")
            self.depth.append(self.out / "frames" / f"depth_{name}.png")
            self.last_frame = frame

    def tear(self, frame, raw, done):
        """The depth rows of a display frame computed across a tear, against the golden torn map (``sim/analysis/
        frame_sources.py``: the tear rows the withheld rows point to, between the camera frames around the one
        being captured, ``done`` frames being complete): ``depth_rows_mixed`` (rows equal to no row of it),
        ``depth_rows_withheld`` (its invalid rows), ``consistent`` and ``tear`` ((c, k, k', torn) or None);
        nothing when no tear explains more rows than the pairs' goldens do."""
        from golden.capture import capture_frame
        from sim.analysis.frame_sources import EMPTY, tear_candidates, torn_depth_rows, torn_summary
        setup, g = self.setup, self.setup.geometry
        if self.buffers is None:
            zeros = np.zeros((g.buf_height, g.buf_width), np.uint8)
            self.buffers = {EMPTY: (zeros, zeros), **{
                k: (capture_frame(setup.fit(left), g), capture_frame(setup.fit(right), g))
                for k, (left, right) in enumerate(self.sequence.pairs)}}
        near = {k: b for k, b in self.buffers.items() if done - 2 <= k <= done + 1}
        withheld = [r for r, (s, bad) in enumerate(zip(raw["depth"], raw["depth_invalid"])) if not s and bad]
        torn = torn_depth_rows(frame, near, setup.display_layout, g, setup.depth, rectification=setup.rectification,
                               candidates=tear_candidates(withheld, g.buf_height, setup.depth))
        if torn["tear"] is None:
            return {}
        t = torn_summary(torn)
        mixed = t["depth_rows_mixed_at_tear"]
        return {"depth_rows_by_frame": t["depth_rows_from"], "depth_rows_mixed": mixed,
                "depth_rows_withheld": t["depth_rows_invalid_at_tear"], "consistent": mixed == 0,
                "tear": tear_text(t["tear"])}

    def finish(self, outputs, complete=True):
        """Close the table and write the animations; returns ``{what: path}``. An interrupted run's (not
        ``complete``) stay under their partial names: readable, and not taken for a whole run's."""
        from PIL import Image
        self.csv_file.close()
        files = {"per-frame table": outputs.commit("frames.csv") if complete else outputs.partial("frames.csv")}
        if not self.hdmi:
            return files
        duration = max(20, round(1000 / 15))      # ms a frame: about the cameras' rate

        def animation(paths, name):
            images = [Image.open(p) for p in paths]
            path = outputs.partial(name)
            images[0].save(path, format="PNG" if name.endswith(".png") else "GIF", save_all=True,
                           append_images=images[1:], duration=duration, loop=0)
            return outputs.commit(name) if complete else path
        files["display frames from the pins, animated PNG"] = animation(self.hdmi, "hdmi_video.png")
        mp4 = write_mp4(self.hdmi, outputs.partial("hdmi_video.mp4"), 1000 / duration)
        if mp4 is None:
            files["display frames, MP4"] = "not written: OpenCV has no MPEG-4 encoder here"
        else:
            files["display frames, MP4"] = outputs.commit("hdmi_video.mp4") if complete else mp4
        files["depth panels, animated GIF"] = animation(self.depth, "depth_video.gif")
        files["display frames, one PNG each"] = self.out / "frames" / "hdmi_NNN.png"
        return files


def tear_text(tear):
    """A tear of ``torn_depth_rows`` for the table: ``"c=10 frames 1/0 torn False"`` (rows from c on of the second
    frame) or ``"rows 10,24 frames 0/1/0"`` (several changes, the frames alternating; ``t`` after a torn row)."""
    if tear[0] == "rows":
        _, changes, first, second = tear
        frames = "/".join(str((first, second)[i % 2]) for i in range(len(changes) + 1))
        return f"rows {','.join(f'{c}{chr(116) if torn else chr(32)}'.strip() for c, torn in changes)} frames {frames}"
    return "c={} frames {}/{} torn {}".format(*tear)


def write_mp4(paths, path, fps):
    """The PNG frames ``paths`` as an MPEG-4 video at ``path`` (OpenCV's FFmpeg, codec ``mp4v``); ``path``, or
    None (nothing left behind) when no encoder opens."""
    import cv2
    first = cv2.imread(str(paths[0]))
    height, width = first.shape[:2]
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"mp4v"), fps, (width, height))
    if not writer.isOpened():
        Path(path).unlink(missing_ok=True)
        return None
    try:
        for p in paths:
            writer.write(cv2.imread(str(p)))
    finally:
        writer.release()
    return path


def skew_figures(status, setup):
    """The frame-start skew camera B - camera A per camera frame: in simulation from the captures' ``in_frame``
    (microseconds and sensor line times) and as the design's skew meter measured it (``sync`` clocks)."""
    events = status["capture_events_s"]
    starts = {c: events[c]["frame_start"] for c in ("a", "b")}
    n = min(len(starts["a"]), len(starts["b"]))
    line_s = (setup.sensor_timing.line_time(setup.geometry.width)) / setup.pclk_hz
    skew = [starts["b"][k] - starts["a"][k] for k in range(n)]
    hardware = status.get("hardware_skew", [])
    return {"frame_start_skew_us": [round(s * 1e6, 4) for s in skew],
            "frame_start_skew_lines": [round(s / line_s, 4) for s in skew],
            "max_abs_skew_lines": round(max((abs(s) / line_s for s in skew), default=0.0), 4),
            "sensor_line_us": round(line_s * 1e6, 4),
            "hardware_skew_sync_clocks": [m["skew_sync_clocks"] for m in hardware],
            "hardware_aligned": [m["aligned"] for m in hardware],
            "hardware_skew_lines": [round(m["skew_sync_clocks"] / setup.sys_hz / line_s, 4) for m in hardware]}


def simulate_frames(args, setup, sequence, writer):
    """The multi-frame run on the chosen simulator; returns the status."""
    from sim import SimulationFailed
    from sim.testbench.system.result import SystemTimeout
    from .cmd_run import require_simulator
    require_simulator(args.simulator)
    bar = Progress(f"{args.simulator}: build (first run only)")
    progress = lambda stage, f: bar.update(int(1000 * f), f"{args.simulator}: {stage}")   # noqa: E731
    try:
        if args.simulator == "verilator":
            from sim.testbench.system.frames_verilator import run_verilator_frames
            status, _ = run_verilator_frames(sequence, setup, on_frame=writer, progress=progress)
        elif args.simulator == "amaranth":
            if setup.preset != "small":
                raise UserError("multi-frame runs on the Amaranth simulator are small only: add --small")
            from sim.testbench.system.frames_amaranth import run_amaranth_frames
            status = run_amaranth_frames(sequence, setup, on_frame=writer, progress=progress)
        else:                           # icarus: the cocotb scenario, small only (Python drivers per PCLK)
            if setup.preset != "small":
                raise UserError("multi-frame runs on icarus are small only: add --small")
            from sim.testbench.system.frames_cocotb import run_cocotb_frames
            status, shown = run_cocotb_frames(sequence, setup, args.simulator, Path(args.out) / ".icarus")
            for frame in shown:
                writer(frame)
    except (SystemTimeout, RuntimeError, OSError, AssertionError) as exc:
        raise SimulationFailed(str(exc).splitlines()[0]) from None
    finally:
        bar.close()
    return status


def run_frames(args, setup, started):
    from sim import SimulationFailed
    from sim.analysis.frame_sources import EMPTY
    out = prepare_out_dir(args.out)
    sequence = build_sequence(args, setup)
    outputs = RunOutputs(out, OUTPUTS, stale=("frames/*.png",)).start()
    auto = None
    if setup.rectification == "auto":
        from sim.analysis.auto_rectification import AutoGoldens
        auto = AutoGoldens(setup, sequence)
        goldens = auto.after
    else:
        black = np.zeros_like(sequence.pairs[0][0])
        goldens = {EMPTY: setup.golden_frame(black, black)}
        goldens.update({k: setup.golden_frame(*pair) for k, pair in enumerate(sequence.pairs)})
    writer = FrameWriter(out, setup, sequence, goldens, auto)
    wall = time.perf_counter()
    status, interrupted = {}, False
    try:
        status = simulate_frames(args, setup, sequence, writer)
    except KeyboardInterrupt:
        interrupted = True
    except SimulationFailed as exc:
        print(f"stereodepth run: simulation failed: {exc}", file=sys.stderr)
        status = {"failed": str(exc)}
    wall = time.perf_counter() - wall
    files = writer.finish(outputs, complete=not interrupted)
    last = writer.rows[-1] if writer.rows else None
    # a capture writing a row while the display shows it: at most that one row of each image panel is mixed
    image_rows_ok = all(r["left_rows_mixed"] <= 1 and r["right_rows_mixed"] <= 1 for r in writer.rows)
    settled_ok = last is not None and last["equals_pair"] == len(sequence) - 1 and not interrupted
    result = dict(status, interrupted=interrupted, total_wall_s=wall, simulator=args.simulator,
                  frames_in=len(sequence), inputs=sequence.names, frames=writer.rows,
                  settled_equals_last_pair=settled_ok, image_rows_from_camera_frames=image_rows_ok)
    if "capture_events_s" in status:
        result["skew"] = skew_figures(status, setup)
    if auto is not None:
        result["auto_rectification_run"] = auto_record(auto, sequence, writer.rows)
        settled_ok = settled_ok and result["auto_rectification_run"]["settled_shows_expected"]
        result["settled_equals_last_pair"] = settled_ok
    from stereodepth.provenance import provenance
    result["provenance"] = provenance(list(sequence.sources), dict(vars(args), setup=setup.to_spec()), started)
    outputs.partial("result.json").write_text(json.dumps(result, indent=1, default=str) + "\n")
    files["result"] = outputs.partial("result.json") if interrupted else outputs.commit("result.json")
    ok = settled_ok and image_rows_ok and not status.get("violations") and "failed" not in status
    print_summary(result, setup, ok)
    print("wrote:")
    for what, path in files.items():
        print(f"  {path}   {what}")
    if interrupted:
        raise KeyboardInterrupt
    return 0 if ok else 1


def auto_record(auto, sequence, rows):
    """``result.json``'s ``auto_rectification_run``: the golden estimator's state per camera frame, where the
    offset in use changes (and how many camera frames after the rig's last knock before it), the first display
    frame showing each new offset, and whether the settled frame shows the expected state."""
    offsets = [float(v) for v in getattr(sequence, "vertical_offsets", None) or []]
    knocks = [k for k in range(1, len(offsets)) if offsets[k] != offsets[k - 1]]
    changes = []
    for k, old, new in auto.changes():
        knock = max((j for j in knocks if j <= k), default=None)
        shown = next((r["display_frame"] for r in rows if r["rectification_shown"] == new.text()), None)
        changes.append({"after_camera_frame": k, "from": old.text(), "to": new.text(), "knock_camera_frame": knock,
                        "camera_frames_after_knock": None if knock is None else k - knock + 1,
                        "first_display_frame_shown": shown})
    last = rows[-1] if rows else None
    return {"rig_vertical_offset_rows": offsets, "knocks_before_camera_frame": knocks,
            "expected_per_camera_frame": [s.text() for s in auto.states], "changes": changes,
            "settled_shows_expected": last is not None and last["rectification_shown"] == auto.states[-1].text()}


def print_summary(result, setup, ok):
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
              f"{r['cam_b_frames_done']}  depth rows {_rows_text(r['depth_rows_by_frame']) or '-'} mixed "
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
    print("  the settled display frame equals the golden frame of the last pair"
          if result["settled_equals_last_pair"] else "  the settled display frame does NOT equal the last pair's")
    print("OK" if ok else "FAILED")
