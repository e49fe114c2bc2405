"""The verdict of a whole-system run, computed once, in the run's check phase: each display frame against its
golden frame, which camera frames its rows came from, the frame a run shows, the settled frame.

:class:`Judge` judges each display frame as the run hands it on (before the caller sees it), and the run as a
whole at the end:

* a still pair (:func:`sim.system.run.still_pair`): the golden frame of the pair with the offset in use and the
  held flag the design showed as the frame started (automatic rectification); when the frame differs, the golden
  frame of the tear that explains it (:func:`sim.testbench.system.result.tear_golden`: a depth map computed while
  a capture overwrote the buffers with the same images). ``verdict``: ``mismatched_pixels``, ``tear`` ((c, torn)
  or None), ``withheld_rows`` (depth rows the row tags withheld: wholly invalid in the frame, valid in the untorn
  golden frame), ``whole`` (no withheld row: the depth map of complete camera frames), ``locked`` (the automatic
  rectification's lock; True in manual mode), ``map_shown`` (False only with the maps in the frame store,
  ``setup.maps == "store"``, for a display frame before the first whole map: its depth panel shows every row not
  ready; such a frame is never chosen, and no tear is looked for in it; a still run with those maps shows its
  second display frame at the earliest, with either policy: the first shows the map of a frame before the run);
* a sequence: the per-row frame sources of ``sim/analysis/frame_sources.py`` against the golden frames of the
  buffers before any capture and of every pair (in automatic rectification both states of each pair,
  :class:`sim.analysis.auto_rectification.AutoGoldens`); a frame whose depth rows are mixed or withheld is
  classified against the golden torn map of the tear its withheld rows point to. ``verdict``: the
  ``source_summary`` keys (``*_rows_by_frame``, ``*_rows_mixed``, ``depth_rows_withheld``, ``consistent``,
  ``equals_pair``, ``depth_frame``) and ``tear`` (its text, or None).

The run's verdict (:meth:`Judge.run_verdict`): for a still pair the frame shown (``chosen``: the first accepted
by the run's policy, :meth:`Judge.enough`), the withheld rows of each frame run, in automatic rectification the
offset found and the display frame it was first used on, and ``ok``; for a sequence the settled frame (the last) against the
last pair's golden frame, ``image_rows_from_camera_frames`` (at most the one row being written mixed in an image
panel), the automatic rectification's record, with the DDR2 build (``setup.memory == "ddr2"``) ``pairs_shown`` and
``display_frames_from_one_pair`` (every display frame equal to one pair's golden frame) -- with the maps in the frame
store (``setup.maps == "store"``) ``pairs_shown`` of (images' pair, map's pair) and ``display_frames_from_whole_pairs``
(every display frame one pair's images with one pair's whole map, the maps never going back; the map's pair None for
a display frame before the first whole map, its depth panel every row not ready: only before every map) -- and
``ok``.
"""

import numpy as np

from golden.capture import capture_frame
from spec.display import DEPTH_NOT_READY_RGB
from sim.analysis.depth_panel import read_depth_panel
from sim.analysis.frame_sources import (EMPTY, frame_sources, source_summary, tear_candidates, torn_depth_rows,
                                        torn_summary)
from sim.testbench.system.result import tear_golden

__all__ = ["Judge", "POLICIES", "tear_text"]

#: How a still pair's run chooses the display frame it shows: ``first`` the first display frame; ``whole`` the
#: first whose depth map has no withheld row (and, in automatic rectification, whose offset has locked).
POLICIES = ("first", "whole")


def tear_text(tear):
    """A tear of ``torn_depth_rows`` for the table: ``"c=10 frames 1/0 torn False"`` (rows from c on of the second
    frame) or ``"rows 10,24 frames 0/1/0"`` (several changes, the frames alternating; ``t`` after a torn row)."""
    if tear[0] == "rows":
        _, changes, first, second = tear
        frames = "/".join(str((first, second)[i % 2]) for i in range(len(changes) + 1))
        return f"rows {','.join(f'{c}{chr(116) if torn else chr(32)}'.strip() for c, torn in changes)} frames {frames}"
    return "c={} frames {}/{} torn {}".format(*tear)


class Judge:
    """The verdict of a run of ``sequence`` on ``setup`` (see the module docstring); ``policy`` (:data:`POLICIES`)
    chooses a still pair's frame."""

    def __init__(self, setup, sequence, policy="first"):
        if policy not in POLICIES:
            raise ValueError(f"policy must be one of {POLICIES}, not {policy!r}")
        self.setup, self.sequence, self.policy = setup, sequence, policy
        self.still = bool(getattr(sequence, "still", False))
        self.auto = None
        self.goldens = {}
        self.buffers = None             # a sequence's grey buffers, made at the first tear
        if not self.still:
            if setup.rectification == "auto":
                from sim.analysis.auto_rectification import AutoGoldens
                self.auto = AutoGoldens(setup, sequence)
                self.goldens = self.auto.after
            else:
                black = np.zeros_like(sequence.pairs[0][0])
                self.goldens = {EMPTY: setup.golden_frame(black, black)}
                self.goldens.update({k: setup.golden_frame(*pair) for k, pair in enumerate(sequence.pairs)})

    # --- one display frame -------------------------------------------------------------------------------------

    def __call__(self, shown):
        """Judge the :class:`~sim.testbench.system.result.DisplayFrame` ``shown``: sets its ``golden`` and
        ``verdict``."""
        if self.still:
            shown.golden, shown.verdict = self._still(shown)
        else:
            shown.verdict = self._sequence(shown)
            k = shown.verdict["equals_pair"]
            shown.golden = self.goldens.get(k) if k is not None else None

    def still_golden(self, settings):
        """The golden frame of the still pair with ``settings`` (the offset in use, held), cached."""
        auto = (settings or {}).get("auto_rectification", {})
        key = ((settings or {}).get("rectification"), bool(auto.get("held", False)))
        if key not in self.goldens:
            self.goldens[key] = self.setup.golden_frame(*self.sequence.pairs[0], in_use=key[0], held=key[1])
        return self.goldens[key]

    def _invalid_rows(self, frame):
        codes, _ = read_depth_panel(frame, self.setup.display_layout, self.setup.depth)
        return (codes == self.setup.depth.invalid).all(axis=1)

    def _not_ready(self, frame):
        """The depth panel's pixels that show ``DEPTH_NOT_READY_RGB`` (a boolean array of the panel)."""
        box = self.setup.display_layout.region("depth")
        panel = np.asarray(frame[box.y0:box.y1, box.x0:box.x1], dtype=np.int64)
        return ((panel[..., 0] << 16) | (panel[..., 1] << 8) | panel[..., 2]) == DEPTH_NOT_READY_RGB

    def _map_shown(self, frame):
        """With the maps in the frame store: the depth panel shows a map (no pixel of it not ready)."""
        if getattr(self.setup, "maps", "ring") != "store":
            return True
        return not self._not_ready(frame).any()

    def _still(self, shown):
        setup, frame, settings = self.setup, shown.frame, shown.settings or {}
        golden = untorn = self.still_golden(settings)
        tear, withheld = None, 0        # a frame equal to its untorn golden frame withholds no row
        map_shown = self._map_shown(frame)
        if not map_shown:
            return golden, {"mismatched_pixels": int(np.any(frame != golden, axis=-1).sum()), "tear": None,
                            "withheld_rows": 0, "whole": False, "locked": False, "map_shown": False}
        if not np.array_equal(frame, golden):
            kwargs = {"in_use": settings.get("rectification"),
                      "held": settings.get("auto_rectification", {}).get("held", False)}
            golden, tear = tear_golden(setup, *self.sequence.pairs[0], frame, golden, **kwargs)
            withheld = int((self._invalid_rows(frame) & ~self._invalid_rows(untorn)).sum())
        locked = setup.rectification != "auto" or bool(settings.get("auto_rectification", {}).get("locked"))
        return golden, {"mismatched_pixels": int(np.any(frame != golden, axis=-1).sum()), "tear": tear,
                        "withheld_rows": withheld, "whole": withheld == 0, "locked": locked, "map_shown": True}

    def _sequence(self, shown):
        setup, frame = self.setup, shown.frame
        layout, g = setup.display_layout, setup.geometry
        done = min(shown.captured.values())
        if self.auto is not None:       # automatic rectification: either state of each pair (auto_rectification)
            return self.auto.row(frame, layout, g, done)
        raw = frame_sources(frame, self.goldens, layout, g, setup.depth)
        sources = source_summary(raw)
        if self._store:
            sources["equals_pairs"] = self._pairs_of(frame)
        elif sources["depth_rows_mixed"] or sources["depth_rows_withheld"]:
            sources.update(self._tear(frame, raw, done))
        return sources

    def _of_empty(self, frame):
        """A still run with the maps in the frame store: whether the frame's left image or its depth map is the
        empty buffers' (their golden frame made once)."""
        if EMPTY not in self.goldens:
            black = np.zeros_like(self.sequence.pairs[0][0])
            self.goldens[EMPTY] = self.setup.golden_frame(black, black)
        empty, layout = self.goldens[EMPTY], self.setup.display_layout
        return any(np.array_equal(frame[b.y0:b.y1, b.x0:b.x1], empty[b.y0:b.y1, b.x0:b.x1])
                   for b in (layout.region("left").box, layout.region("depth").box))

    @property
    def _store(self):
        return getattr(self.setup, "maps", "ring") == "store"

    def _pairs_of(self, frame):
        """With the maps in the frame store: ``(p, q)``, the newest pairs such that the display frame shows pair
        ``p``'s golden frame with pair ``q``'s depth map (its panel and its readout) and ``q <= p``; ``(p, None)``
        when it shows no map (every pixel of the depth panel not ready: before the first whole map; the readout not
        judged, as in a still run's frame before its first map); None when no two pairs make it."""
        layout = self.setup.display_layout
        boxes = [layout.region("depth").box] + ([layout.readout.box] if layout.readout is not None else [])
        keys = sorted(self.goldens)
        for p in reversed(keys):
            outside = self.goldens[p].copy()
            for box in boxes:
                outside[box.y0:box.y1, box.x0:box.x1] = frame[box.y0:box.y1, box.x0:box.x1]
            if not np.array_equal(frame, outside):
                continue
            for q in reversed([k for k in keys if k <= p]):
                if all(np.array_equal(frame[b.y0:b.y1, b.x0:b.x1], self.goldens[q][b.y0:b.y1, b.x0:b.x1])
                       for b in boxes):
                    return p, q
            if self._not_ready(frame).all():
                return p, None
        return None

    def _tear(self, frame, raw, done):
        """The depth rows of a display frame computed across a tear, against the golden torn map (``sim/analysis/
        frame_sources.py``: the tear rows the withheld rows point to, between the camera frames around the one
        being captured, ``done`` frames being complete): ``depth_rows_mixed`` (rows equal to no row of it),
        ``depth_rows_withheld`` (its invalid rows), ``consistent`` and ``tear`` (its text); nothing when no tear
        explains more rows than the pairs' goldens do."""
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

    def enough(self, shown):
        """Whether a still pair's run may end with the judged display frame ``shown`` (the run's policy)."""
        # With the maps in the frame store a display frame shows the map computed in an earlier one: the first
        # frame's may be of the pair before the run's, and while the engine finishes a map of the empty buffers
        # (begun before the captures completed) the images and the map are the empty buffers' for up to a map's
        # display frames more: a frame is the run's when neither its images nor its map are the empty buffers'.
        if self._store and not (shown.index >= 1 and shown.verdict["map_shown"] and not self._of_empty(shown.frame)):
            return False
        if self.policy == "first":
            return True
        return shown.verdict["whole"] and shown.verdict["locked"]

    # --- the run -------------------------------------------------------------------------------------------

    def run_verdict(self, frames, status):
        """The run's verdict from its judged display ``frames`` and the driver's ``status``."""
        # no HDMI timing violation, and (the DDR2 build) no display read the frame store refused
        clean = not status.get("violations") and not status.get("display_missed")
        if self.still:
            return self._still_verdict(frames, clean)
        last = frames[-1].verdict if frames else None
        settled_ok = last is not None and last["equals_pair"] == len(self.sequence) - 1
        # a capture writing a row while the display shows it: at most that one row of each image panel is mixed
        image_rows_ok = all(f.verdict["left_rows_mixed"] <= 1 and f.verdict["right_rows_mixed"] <= 1
                            for f in frames)
        out = {"settled_frame": frames[-1].index if frames else None, "settled_equals_last_pair": settled_ok,
               "image_rows_from_camera_frames": image_rows_ok}
        if self.auto is not None:
            out["auto_rectification_run"] = self._auto_record(frames)
            out["settled_equals_last_pair"] = settled_ok and out["auto_rectification_run"]["settled_shows_expected"]
        out["ok"] = out["settled_equals_last_pair"] and image_rows_ok and clean
        if self._store:
            out.update(self._store_pairs(frames))
            out["ok"] = out["ok"] and out["display_frames_from_whole_pairs"]
        elif self.setup.memory == "ddr2":
            out.update(self._whole_pairs(frames))
            out["ok"] = out["ok"] and out["display_frames_from_one_pair"]
        return out

    @staticmethod
    def _store_pairs(frames):
        """The promise with the maps in the frame store: every display frame shows one pair's images and difference
        map (``p``) and one pair's whole depth map (``q``: the latest whole map, of the pair before or the same),
        the maps' pairs never going back; ``q`` None (no map yet) only before every map. ``pairs_shown``: ``(p, q)``
        of each display frame."""
        shown = [f.verdict.get("equals_pairs") for f in frames]
        whole = bool(frames) and None not in shown
        if whole:
            maps = [q for _, q in shown]
            first = next((i for i, q in enumerate(maps) if q is not None), len(maps))
            whole = None not in maps[first:] and all(a <= b for a, b in zip(maps[first:], maps[first + 1:]))
        return {"pairs_shown": shown, "display_frames_from_whole_pairs": whole}

    @staticmethod
    def _whole_pairs(frames):
        """The DDR2 build's promise (whole camera frames only): every display frame equals the golden frame of one
        pair (or of the empty buffers before the first pair) -- its image panels, difference map and depth map
        all from that pair, no row withheld, none mixed. ``pairs_shown``: the pair of each display frame."""
        shown = [f.verdict.get("equals_pair") for f in frames]
        return {"pairs_shown": shown, "display_frames_from_one_pair": bool(frames) and None not in shown}

    def _still_verdict(self, frames, clean):
        """A still pair's run: the frame it shows (``chosen``, the first the policy accepts, else the last), the
        withheld rows of every frame run, where the maps are (``maps``), ``ok`` (the chosen frame equal to its golden frame, no timing violation
        nor refused display read, and with the ``whole`` policy accepted by it); in automatic rectification the
        offset in use on the chosen frame (``auto_offset``) and the first display frame that used it locked
        (``auto_offset_first_frame``)."""
        chosen = next((f.index for f in frames if self.enough(f)), frames[-1].index if frames else None)
        out = {"chosen": chosen, "policy": self.policy, "display_frames": len(frames), "maps": self.setup.maps,
               "withheld_rows": [f.verdict["withheld_rows"] for f in frames]}
        out["ok"] = chosen is not None and frames[chosen].verdict["mismatched_pixels"] == 0 and clean \
            and (self.policy == "first" or self.enough(frames[chosen]))
        if self.setup.rectification == "auto" and chosen is not None:
            offset = frames[chosen].settings["rectification"]
            out["auto_offset"] = offset
            out["auto_offset_first_frame"] = next((f.index for f in frames if f.verdict["locked"]
                                                   and f.settings["rectification"] == offset), None)
        return out

    def _auto_record(self, frames):
        """The automatic rectification over the run: the golden estimator's state per camera frame, where the
        offset in use changes (and how many camera frames after the rig's last knock before it), the first display
        frame showing each new offset, and whether the settled frame shows the expected state."""
        auto, sequence = self.auto, self.sequence
        rows = [f.verdict for f in frames]
        offsets = [float(v) for v in getattr(sequence, "vertical_offsets", None) or []]
        knocks = [k for k in range(1, len(offsets)) if offsets[k] != offsets[k - 1]]
        changes = []
        for k, old, new in auto.changes():
            knock = max((j for j in knocks if j <= k), default=None)
            shown = next((f.index for f, r in zip(frames, rows) if r["rectification_shown"] == new.text()), None)
            changes.append({"after_camera_frame": k, "from": old.text(), "to": new.text(),
                            "knock_camera_frame": knock,
                            "camera_frames_after_knock": None if knock is None else k - knock + 1,
                            "first_display_frame_shown": shown})
        return {"rig_vertical_offset_rows": offsets, "knocks_before_camera_frame": knocks,
                "expected_per_camera_frame": [s.text() for s in auto.states], "changes": changes,
                "settled_shows_expected": bool(rows) and rows[-1]["rectification_shown"] == auto.states[-1].text()}
