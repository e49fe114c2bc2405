"""Which camera frames a displayed frame was made of, row by row (issue 28: consistency, defined and measured).

Definition. Camera frame k of the run is the pair (left image k, right image k) the two sensors sent as their k-th
frame; frame -1 is the buffers before any capture (all zeros). The golden model's displayed frame of pair k
(``SystemSetup.golden_frame``) is what the screen shows when both buffers hold frame k. A displayed panel row --
one buffer row of the left image, the right image, the difference map or the depth map, ``scale`` display lines
-- *comes from frame k* when it equals that row of the golden frame of pair k bit for bit. A row can come from
several frames (where the scene did not change there) or from none: a depth (or difference) row computed from a
left row of one frame and a right row of another, or from rows of the window of different frames, equals no
golden row -- a *mixed* row. A display frame is *consistent* when no depth row is mixed, and it *equals pair k*
when all of it equals the golden frame of pair k.

:func:`frame_sources` measures this for one displayed frame against the goldens of the run's pairs: per panel, per
buffer row, the set of frames the row comes from; :func:`source_summary` condenses it for the per-frame table.
"""

import numpy as np

__all__ = ["PANELS", "frame_sources", "source_summary", "EMPTY"]

#: The panels, as ``spec.layout`` names their regions.
PANELS = ("left", "right", "disparity", "depth")
#: The index of the "frame" before any capture: the buffers' zeros.
EMPTY = -1


def _row_slices(layout, source, geometry):
    region = layout.region(source)
    s = region.scale
    return [(slice(region.y0 + r * s, region.y0 + (r + 1) * s), slice(region.x0, region.x1))
            for r in range(geometry.buf_height)]


def frame_sources(frame, goldens, layout, geometry):
    """``{panel: [set of frame indices, one per buffer row]}`` of displayed ``frame`` (uint8 RGB) against
    ``goldens`` (``{index: golden frame}``, e.g. :data:`EMPTY` and 0..N-1), plus ``"equals"``: the indices whose
    golden frame equals ``frame`` entirely."""
    out = {}
    for panel in PANELS:
        rows = _row_slices(layout, panel, geometry)
        out[panel] = [{k for k, g in goldens.items() if np.array_equal(frame[ys, xs], g[ys, xs])}
                      for ys, xs in rows]
    out["equals"] = sorted(k for k, g in goldens.items() if np.array_equal(frame, g))
    return out


def _key(sources):
    """``"k"`` for a row from frame k only, ``"j-k"`` for one that frames j..k (the oldest and newest) all show."""
    lo, hi = min(sources), max(sources)
    return str(lo) if lo == hi else f"{lo}..{hi}"


def _by_frame(rows):
    """``{key: rows}`` (:func:`_key`) and the count of rows from no frame."""
    counts = {}
    for sources in rows:
        if sources:
            k = _key(sources)
            counts[k] = counts.get(k, 0) + 1
    return counts, sum(1 for sources in rows if not sources)


def source_summary(sources):
    """Per panel ``{"<panel>_rows_by_frame": {"k" or "j..k": count}, "<panel>_rows_mixed": n}`` (a row counted
    under the frame it comes from, or under the range of frames that all show it), ``depth_frame`` (the newest
    frame that the most depth rows come from alone, else the newest frame any depth row comes from, or None),
    ``consistent`` (no mixed depth row) and ``equals_pair`` (the newest pair whose golden frame the display frame
    equals, or None)."""
    out = {}
    for panel in PANELS:
        counts, mixed = _by_frame(sources[panel])
        out[f"{panel}_rows_by_frame"] = counts
        out[f"{panel}_rows_mixed"] = mixed
    alone = {}
    for s in sources["depth"]:
        if len(s) == 1:
            alone[next(iter(s))] = alone.get(next(iter(s)), 0) + 1
    newest = [max(s) for s in sources["depth"] if s]
    out["depth_frame"] = (max(alone, key=lambda k: (alone[k], k)) if alone else max(newest) if newest else None)
    out["consistent"] = out["depth_rows_mixed"] == 0
    out["equals_pair"] = max(sources["equals"]) if sources["equals"] else None
    return out
