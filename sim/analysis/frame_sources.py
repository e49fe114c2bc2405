"""Which camera frames a displayed frame was made of, row by row (consistency, defined and measured).

Definition. Camera frame k of the run is the pair (left image k, right image k) the two sensors sent as their k-th
frame; frame -1 is the buffers before any capture (all zeros). The golden model's displayed frame of pair k
(``SystemSetup.golden_frame``) is what the screen shows when both buffers hold frame k. A displayed panel row --
one buffer row of the left image, the right image, the difference map or the depth map, ``scale`` display lines
(of a panel at 1 / ``shrink`` size, every ``shrink``-th buffer row, one line) -- *comes from frame k* when it equals that row of the golden frame of pair k bit for bit. A row can come from
several frames (where the scene did not change there) or from none: a depth (or difference) row computed from a
left row of one frame and a right row of another, or from rows of the window of different frames, equals no
golden row -- a *mixed* row. A depth row equal to no golden row whose every code is invalid is not mixed but
*withheld*: the design's row tags invalidated it at a tear (docs/depth.md, "Rows from different camera frames"),
so it shows no frame's depth. A display frame is *consistent* when no depth row is mixed, and it *equals pair k*
when all of it equals the golden frame of pair k.

:func:`frame_sources` measures this for one displayed frame against the goldens of the run's pairs: per panel, per
buffer row, the set of frames the row comes from; :func:`source_summary` condenses it for the per-frame table.

At the tear (docs/depth.md, "Rows from different camera frames"). A depth map computed while a capture overwrites
the buffers reads rows 0..c-1 of camera frame k (the new one, already written) and rows c..H-1 of frame k' (the one
before), row c perhaps torn (part written). Its golden model is the torn map: ``golden.depth.depth_map`` of those
rows with their tags (k above c, k' below, row c's tag None when torn, the same c for both cameras), drawn as the
depth panel draws it (``golden.depth_display.depth_picture``). :func:`torn_depth_rows` finds the hypothesis (c, k,
k', torn) whose torn map the displayed depth panel equals in the most rows; a depth row then comes *from frame k*
(or k') when it equals that row of the torn map and the rule leaves the row valid, is *invalid at the tear* when it
equals it and the rule invalidates the row (``golden.depth.row_flags``: a census window holding rows of two frames or
a torn row), and is *mixed* when it equals no row of the torn map.
"""

import numpy as np

__all__ = ["PANELS", "frame_sources", "source_summary", "EMPTY", "torn_depth_rows", "torn_summary",
           "tear_candidates", "segment_candidates", "segment_map"]

#: The panels, as ``spec.layout`` names their regions.
PANELS = ("left", "right", "disparity", "depth")
#: The index of the "frame" before any capture: the buffers' zeros.
EMPTY = -1


def _row_slices(layout, source, geometry):
    """The display lines and columns of each buffer row the panel shows: every row, ``scale`` lines each; of a
    panel at 1 / ``shrink`` size every ``shrink``-th row, one line each."""
    region = layout.region(source)
    s = region.scale
    return [(slice(region.y0 + r * s, region.y0 + (r + 1) * s), slice(region.x0, region.x1))
            for r in range(geometry.buf_height // region.shrink)]


def frame_sources(frame, goldens, layout, geometry, depth=None):
    """``{panel: [set of frame indices, one per buffer row]}`` of displayed ``frame`` (uint8 RGB) against
    ``goldens`` (``{index: golden frame}``, e.g. :data:`EMPTY` and 0..N-1), plus ``"equals"``: the indices whose
    golden frame equals ``frame`` entirely; with the depth configuration ``depth``, also ``"depth_invalid"``: per
    depth row, whether the panel shows every code of it invalid."""
    out = {}
    for panel in PANELS:
        rows = _row_slices(layout, panel, geometry)
        out[panel] = [{k for k, g in goldens.items() if np.array_equal(frame[ys, xs], g[ys, xs])}
                      for ys, xs in rows]
    out["equals"] = sorted(k for k, g in goldens.items() if np.array_equal(frame, g))
    if depth is not None:
        out["depth_invalid"] = _invalid_rows(frame, layout, depth).tolist()
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
    equals, or None). With ``"depth_invalid"`` in ``sources``: ``depth_rows_withheld``, the depth rows from no
    frame that are wholly invalid, which ``depth_rows_mixed`` then leaves out."""
    out = {}
    for panel in PANELS:
        counts, mixed = _by_frame(sources[panel])
        out[f"{panel}_rows_by_frame"] = counts
        out[f"{panel}_rows_mixed"] = mixed
    if "depth_invalid" in sources:
        withheld = sum(1 for s, bad in zip(sources["depth"], sources["depth_invalid"]) if not s and bad)
        out["depth_rows_withheld"] = withheld
        out["depth_rows_mixed"] -= withheld
    alone = {}
    for s in sources["depth"]:
        if len(s) == 1:
            alone[next(iter(s))] = alone.get(next(iter(s)), 0) + 1
    newest = [max(s) for s in sources["depth"] if s]
    out["depth_frame"] = (max(alone, key=lambda k: (alone[k], k)) if alone else max(newest) if newest else None)
    out["consistent"] = out["depth_rows_mixed"] == 0
    out["equals_pair"] = max(sources["equals"]) if sources["equals"] else None
    return out


def _engine_tags(tags, rectification):
    """Per engine row, the tag of the buffer row it holds: engine row r reads buffer row clamp(r + offset)."""
    h = len(tags)
    return [tags[min(max(r + int(rectification), 0), h - 1)] for r in range(h)]


def _panel_rows(frame, layout, geometry):
    region = layout.region("depth")
    s = region.scale
    panel = np.asarray(frame)[region.y0:region.y1, region.x0:region.x1]
    return panel.reshape(geometry.buf_height, s, region.x1 - region.x0, -1)


def _picture_rows(codes, layout, depth, geometry, shape):
    """The depth panel as the display draws it for ``codes`` (the picture, the crosshair and whatever the layout
    draws over the panel, the readout included: ``golden.depth_display.draw_depth_display``), per buffer row;
    ``shape`` is the displayed frame's (rows, columns)."""
    from golden.depth_display import draw_depth_display
    from golden.disparity import rgb24_to_bytes
    region = layout.region("depth")
    frame = np.zeros(shape[:2], np.int64)
    draw_depth_display(frame, codes, layout, geometry, depth)
    picture = rgb24_to_bytes(frame[region.y0:region.y1, region.x0:region.x1])
    return picture.reshape(geometry.buf_height, region.scale, region.x1 - region.x0, -1)


def _matching_rows(panel, picture):
    return np.all(panel == picture, axis=(1, 2, 3))


def _pair(value):
    return tuple(value) if isinstance(value, (tuple, list)) else (value, value)


def torn_map(buffers, above, below, c, torn, depth, rectification=0):
    """The golden torn map (module docstring): buffer rows 0..c-1 of frame ``above``, c..H-1 of frame ``below``
    (``buffers``: ``{k: (left, right)}`` grey buffers), row c's tag None when ``torn``; ``c`` and ``torn`` may be
    pairs (left, right): each image torn at its own row. Returns the codes and, per engine row, whether the rule
    invalidates it (before the median)."""
    from golden.depth import depth_map, row_flags
    from golden.depth_display import engine_left
    h = buffers[above][0].shape[0]
    images, all_tags = [], []
    for side, (cs, ts) in enumerate(zip(_pair(c), _pair(torn))):
        images.append(np.concatenate([buffers[above][side][:cs], buffers[below][side][cs:]]))
        tags = [above] * cs + [below] * (h - cs)
        if ts and cs < h:
            tags[cs] = None
        all_tags.append(tags)
    left_tags, right_tags = _engine_tags(all_tags[0], rectification), all_tags[1]
    codes = depth_map(engine_left(images[0], rectification), images[1], depth, row_tags=(left_tags, right_tags))
    return codes, row_flags((left_tags, right_tags), h, depth)[0]


def segment_map(buffers, row_frames, torn_rows, depth, rectification=0):
    """The golden map of buffers whose row r holds frame ``row_frames[r]`` in both images (the captures overtaken
    more than once while the engine read the map: it reads its first rows at the display frame's start, then
    waits for the display to reach the depth panel), the rows ``torn_rows`` torn. Returns the codes and, per
    engine row, whether the rule invalidates it."""
    from golden.depth import depth_map, row_flags
    from golden.depth_display import engine_left
    h = len(row_frames)
    images = [np.stack([buffers[row_frames[r]][side][r] for r in range(h)]) for side in (0, 1)]
    tags = [None if r in torn_rows else row_frames[r] for r in range(h)]
    left_tags = _engine_tags(tags, rectification)
    codes = depth_map(engine_left(images[0], rectification), images[1], depth, row_tags=(left_tags, tags))
    return codes, row_flags((left_tags, tags), h, depth)[0]


def _runs(rows):
    runs = []
    for r in sorted(set(int(r) for r in rows)):
        if runs and r == runs[-1][1] + 1:
            runs[-1][1] = r
        else:
            runs.append([r, r])
    return runs


def segment_candidates(withheld, height, depth):
    """The change rows, one per run of withheld rows, that explain them all at once in both images: a run of 2h
    rows b0.. a tag change at b0 + h, a run of 2h + 1 a torn row b0 + h, a run from row 0 a change at b1 - h + 1.
    Returns ``((c, torn), ...)`` in row order, or None when a run fits none of these or there is one run only."""
    h = depth.census_height // 2
    changes = []
    for b0, b1 in _runs(withheld):
        length = b1 - b0 + 1
        if b0 == 0 and length <= 2 * h:
            change = (b1 - h + 1, False)
        elif length in (2 * h, 2 * h + 1):
            change = (b0 + h, length == 2 * h + 1)
        else:
            return None
        if not 1 <= change[0] <= height - 1:
            return None
        changes.append(change)
    return tuple(changes) if len(changes) >= 2 else None


def _invalid_rows(frame, layout, depth):
    """Per depth-panel row of ``frame``: every code the panel shows there is invalid (a bool array)."""
    from sim.analysis.depth_panel import read_depth_panel
    codes, _ = read_depth_panel(frame, layout, depth)
    return (codes == depth.invalid).all(axis=1)


def tear_candidates(withheld, height, depth):
    """Tear rows that explain the withheld depth rows ``withheld`` (row indices) by the rule of docs/depth.md: per
    run of consecutive withheld rows b0..b1, a tag change at c withholds c - h .. c + h - 1 (c = b0 + h, or
    b1 - h + 1 where the run is clamped at the top), a torn row c withholds c - h .. c + h (c = b1 - h), and two
    images torn at c < c' withhold c - h .. c' + h - 1. Returns the tear rows c (1..H-1) and (left, right) pairs,
    for :func:`torn_depth_rows`'s ``candidates``."""
    h = depth.census_height // 2
    runs = _runs(withheld)
    inside = lambda c: 1 <= c <= height - 1          # noqa: E731
    out = []
    for b0, b1 in runs:
        for c in (b0 + h, b1 - h + 1, b1 - h):
            if inside(c) and c not in out:
                out.append(c)
        c, c2 = b0 + h, b1 - h + 1
        if inside(c) and inside(c2) and c < c2:
            out += [(c, c2), (c2, c)]
    return out


def torn_depth_rows(frame, buffers, layout, geometry, depth, *, rectification=0, window=None, candidates=None):
    """The hypothesis (c, k, k', torn) of the module docstring that explains the most rows of ``frame``'s depth
    panel, over k' = the frame before k in ``buffers`` (``{k: (left, right)}``, keys in capture order, e.g.
    :data:`EMPTY`, 0, 1, ...), c = 1..H-1 (or, with ``window``, within ``window`` rows of the first row where the
    panel differs from frame k's untorn map) and torn True/False. If rows are left unexplained, the two images are
    then allowed their own tear rows (the engine fetches the two buffers independently): c and torn become pairs
    (left, right), the second tear searched from the first unexplained row to ``census_height`` + 2 rows below it
    and at the rows the panel's wholly invalid rows point to (:func:`tear_candidates`).
    Rows still unexplained then try several tag changes in both images (:func:`_segments`), ``tear`` then
    ``("rows", ((c, torn), ...), first frame, second frame)``.
    Returns ``{"tear": (c, k, k', torn) or None, "rows": per depth row k, k', "k|k'" (left of k, right of k'
    or the other way: between two tear rows), "invalid" or None (mixed)}``; without a hypothesis explaining more
    rows than the untorn maps do, ``tear`` is None and the rows are labelled by the best untorn map. With
    ``candidates`` (:func:`tear_candidates`: tear rows and (left, right) pairs) only those tears are tried, each
    torn or not in each image, and no second pass."""
    from golden.depth import depth_map
    from golden.depth_display import engine_left
    h = geometry.buf_height
    panel = _panel_rows(frame, layout, geometry)
    panel_shape = np.asarray(frame).shape
    keys = list(buffers)
    best = [-1, None, None]            # rows explained, tear, labels
    withheld = np.flatnonzero(_invalid_rows(frame, layout, depth))      # the panel's wholly invalid rows

    def consider(above, below, c, torn):
        codes, invalid = torn_map(buffers, above, below, c, torn, depth, rectification)
        match = _matching_rows(panel, _picture_rows(codes, layout, depth, geometry, panel_shape))
        lo, hi = min(_pair(c)), max(_pair(c))
        labels = [None if not m else "invalid" if bad else above if y < lo else below if y >= hi
                  else f"{above}|{below}" for y, (m, bad) in enumerate(zip(match, invalid))]
        if int(match.sum()) > best[0]:
            best[:] = [int(match.sum()), (c, above, below, torn), labels]

    first_mismatch = {}
    for k in keys:
        left, right = buffers[k]
        codes = depth_map(engine_left(left, rectification), right, depth)
        match = _matching_rows(panel, _picture_rows(codes, layout, depth, geometry, panel_shape))
        if int(match.sum()) > best[0]:
            best[:] = [int(match.sum()), None, [k if m else None for m in match]]
        first_mismatch[k] = int(np.argmin(match)) if not match.all() else h
    if candidates is not None:
        for above, below in zip(keys[1:], keys[:-1]):
            for c in candidates:
                torns = (False, True) if isinstance(c, int) else ((False, False), (True, False), (False, True),
                                                                  (True, True))
                for torn in torns:
                    consider(above, below, c, torn)
        _segments(best, withheld, frame, buffers, keys, panel, layout, geometry, depth, rectification)
        return {"tear": best[1], "rows": best[2]}
    for above, below in zip(keys[1:], keys[:-1]):
        a = first_mismatch[above]
        cs = range(1, h) if window is None else range(max(1, a - window), min(h, a + window + 1))
        for c in cs:
            for torn in (False, True):
                consider(above, below, c, torn)
    if best[1] is not None and None in best[2]:
        c, above, below, _ = best[1]
        m = best[2].index(None)
        pointed = [c2 for c2 in tear_candidates(withheld, h, depth) if isinstance(c2, int)]
        for c2 in sorted(set(range(max(1, m - 2), min(h, m + depth.census_height + 3))) | set(pointed)):
            for pair in ((c, c2), (c2, c)):
                for torn in ((False, False), (True, False), (False, True), (True, True)):
                    consider(above, below, pair, torn)
    _segments(best, withheld, frame, buffers, keys, panel, layout, geometry, depth, rectification)
    return {"tear": best[1], "rows": best[2]}


def _segments(best, withheld, frame, buffers, keys, panel, layout, geometry, depth, rectification):
    """When rows are still unexplained: the hypothesis of several tag changes in both images at the rows the
    ``withheld`` runs point to (:func:`segment_candidates`), the frames alternating from either; ``best``
    updated."""
    if best[2] is not None and None not in best[2]:
        return
    changes = segment_candidates(withheld, geometry.buf_height, depth)
    if changes is None:
        return
    at = [c for c, _ in changes]
    torn_rows = {c for c, torn in changes if torn}
    for above, below in reversed(list(zip(keys[1:], keys[:-1]))):        # the newest frames first on a tie
        for first, second in ((below, above), (above, below)):
            row_frames = [(first, second)[sum(1 for c in at if c <= r) % 2] for r in range(geometry.buf_height)]
            codes, invalid = segment_map(buffers, row_frames, torn_rows, depth, rectification)
            match = _matching_rows(panel, _picture_rows(codes, layout, depth, geometry, np.asarray(frame).shape))
            if int(match.sum()) > best[0]:
                labels = [None if not m else "invalid" if bad else row_frames[y]
                          for y, (m, bad) in enumerate(zip(match, invalid))]
                best[:] = [int(match.sum()), ("rows", changes, first, second), labels]


def torn_summary(torn):
    """``{"depth_rows_from": {k or "k|k'": count}, "depth_rows_invalid_at_tear": n, "depth_rows_mixed_at_tear": n,
    "tear": (c, k, k', torn) or None}`` of a :func:`torn_depth_rows` result."""
    rows = torn["rows"]
    counts = {}
    for r in rows:
        if r is not None and r != "invalid":
            counts[str(r)] = counts.get(str(r), 0) + 1
    return {"depth_rows_from": counts, "depth_rows_invalid_at_tear": sum(1 for r in rows if r == "invalid"),
            "depth_rows_mixed_at_tear": sum(1 for r in rows if r is None), "tear": torn["tear"]}
