"""What a multi-frame run writes as it goes: per display frame its PNGs and its row of the table, then the
animations and the MP4; and the figures of the frame-start skew.

:class:`FrameFiles` is handed each judged display frame (``simulate``'s ``on_frame``): it writes
``frames/hdmi_NNN.png`` (the display frame from the pins), ``frames/depth_NNN.png`` (its depth panel at buffer
size with the colour bar) and appends the frame's row to ``frames.csv`` (:data:`COLUMNS`: its start time, the
frames each capture had completed, the verdict's frame sources, the centre distance shown against the truth and,
with a truth, bad > 1 / bad > 2 / density of the depth panel), each frame's files whole or not at all (the
caller's ``guard``). :meth:`FrameFiles.finish` closes the table and writes ``hdmi_video.png`` (animated PNG),
``hdmi_video.mp4`` (where OpenCV's FFmpeg has an MPEG-4 encoder) and ``depth_video.gif``.
"""

import csv
import contextlib
import re
from pathlib import Path

__all__ = ["COLUMNS", "AUTO_COLUMNS", "FrameFiles", "table_row", "rows_text", "write_mp4", "skew_figures"]

#: Columns of ``frames.csv``.
COLUMNS = ("display_frame", "t_start_ms", "cam_a_frames_done", "cam_b_frames_done", "left_rows_by_frame",
           "right_rows_by_frame", "disparity_rows_by_frame", "depth_rows_by_frame", "depth_rows_mixed",
           "depth_rows_withheld", "tear",
           "consistent", "equals_pair", "depth_frame", "centre_shown_cm", "centre_truth_cm", "bad1", "bad2",
           "density")
#: Columns added in automatic rectification (:mod:`sim.analysis.auto_rectification`): the offset in use and mode
#: the display frame shows (the state of the golden it equals) and the one expected from the golden estimator.
AUTO_COLUMNS = ("rectification_shown", "rectification_expected")


def rows_text(counts):
    """``{"0": 3, "0..2": 9, "1|0": 2}`` as ``"0:3 0..2:9 1|0:2"``, in frame order."""
    def order(key):
        lo, hi = (int(v) for v in re.match(r"(-?\d+)(?:\.\.|\|)?(-?\d+)?", key).groups(default=key.split("|")[0]))
        return lo, hi
    return " ".join(f"{k}:{counts[k]}" for k in sorted(counts, key=order))


def table_row(shown, setup, sequence):
    """The table's row of the judged display frame ``shown``: its verdict with its time, the frames captured,
    and the depth panel's figures against the truth of the camera frame its depth rows come from."""
    from sim.analysis.depth_panel import depth_summary
    k = shown.verdict["depth_frame"]
    truth = sequence.truth[k] if k is not None and k >= 0 else None
    depth = depth_summary(shown.frame, setup.display_layout, setup.geometry, setup.depth, truth)
    centre_m = sequence.centre_m[k] if k is not None and k >= 0 else None
    return {"display_frame": shown.index, "t_start_ms": round(shown.t_start_s * 1e3, 4),
            "cam_a_frames_done": shown.captured["a"], "cam_b_frames_done": shown.captured["b"],
            **shown.verdict, "centre_shown_cm": depth.get("centre_distance_cm"),
            "centre_truth_cm": None if centre_m is None else round(100 * centre_m, 1),
            "bad1": depth.get("bad1"), "bad2": depth.get("bad2"), "density": depth.get("density")}


class FrameFiles:
    """Receives the judged display frames of a run of ``sequence`` on ``setup`` into the folder ``out`` (see the
    module docstring). ``write(path, writer)`` writes a file whole (``writer(partial path)``, then renamed);
    ``guard()`` a context in which one frame's files are written without interruption."""

    def __init__(self, out, setup, sequence, *, write, guard=contextlib.nullcontext):
        self.out, self.setup, self.sequence, self.write, self.guard = Path(out), setup, sequence, write, guard
        auto = setup.rectification == "auto"
        self.columns = COLUMNS + (AUTO_COLUMNS if auto else ())
        (self.out / "frames").mkdir(exist_ok=True)
        self.rows, self.hdmi, self.depth = [], [], []
        self.csv_file = open(self.out / "frames.partial.csv", "w", newline="")
        self.csv = csv.DictWriter(self.csv_file, self.columns)
        self.csv.writeheader()

    def __call__(self, shown):
        from sim.analysis.depth_panel import depth_picture_png, panel_picture
        from sim.models.ch7301c.hdmi_sink import write_png
        setup, frame = self.setup, shown.frame
        row = table_row(shown, setup, self.sequence)
        name = f"{shown.index:03d}"
        picture = panel_picture(frame, setup.display_layout)
        with self.guard():                              # a Ctrl-C now leaves this frame's files and row whole
            self.write(self.out / "frames" / f"hdmi_{name}.png", lambda p: write_png(frame, p))
            self.write(self.out / "frames" / f"depth_{name}.png",
                       lambda p: depth_picture_png(picture, p, setup.geometry, setup.depth))
            self.csv.writerow({c: (rows_text(row[c]) if c.endswith("_by_frame") else row.get(c))
                               for c in self.columns})
            self.csv_file.flush()
            self.rows.append(row)
            self.hdmi.append(self.out / "frames" / f"hdmi_{name}.png")
            self.depth.append(self.out / "frames" / f"depth_{name}.png")

    def finish(self, outputs, complete=True):
        """Close the table and write the animations into ``outputs`` (``partial(name)`` / ``commit(name)``);
        returns ``{what: path}``. An interrupted run's (not ``complete``) stay under their partial names: readable,
        and not taken for a whole run's."""
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
