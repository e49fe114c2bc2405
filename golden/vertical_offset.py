"""Golden model of the vertical-offset estimator (automatic rectification), written from docs/rectification.md.

* :func:`row_profiles`: P(y), the sum of each row's grey values.
* :func:`search`: one frame's search: the costs C(o) = sum over the window Y of |D_L(y + o) - D_R(y)| of the
  profile derivatives D(y) = P(y) - P(y - 1), the texture T, the best offset o1 (first minimum), c2 (the best
  at least two offsets away) and whether the minimum is clear (``confident``).
* :class:`OffsetTracker`: the decision over frames (keep the last offset when not confident, a new offset
  only when clearly better than the one in use and agreed on for ``stable_frames`` frames).

Only constants come from ``spec``; nothing is taken from the RTL.
"""

from dataclasses import dataclass

import numpy as np

from spec.rectification import RECTIFICATION

__all__ = ["row_profiles", "search", "Search", "OffsetTracker", "Decision", "estimate_offsets"]


def row_profiles(image):
    """(H,) int64: the sum of the grey values of each row of a 2-D integer image."""
    image = np.asarray(image)
    if image.ndim != 2 or not np.issubdtype(image.dtype, np.integer):
        raise ValueError(f"a grey image is a 2-D integer array, not {image.dtype} {image.shape}")
    return image.astype(np.int64).sum(axis=1)


@dataclass(frozen=True)
class Search:
    """One frame's search: ``costs`` (2R + 1,) for o = -R..R, ``texture``, ``best`` o1, ``c1``, ``c2``,
    ``confident``."""
    costs: np.ndarray
    texture: int
    best: int
    c1: int
    c2: int
    confident: bool

    def cost(self, offset):
        return int(self.costs[offset + (len(self.costs) - 1) // 2])


def search(left_profile, right_profile, width, config=RECTIFICATION):
    """The search of docs/rectification.md on two row profiles of buffers ``width`` pixels wide."""
    pl, pr = np.asarray(left_profile, dtype=np.int64), np.asarray(right_profile, dtype=np.int64)
    if pl.shape != pr.shape or pl.ndim != 1:
        raise ValueError(f"profiles {pl.shape} and {pr.shape} must be two 1-D arrays of one length")
    config.check(len(pl))
    r = config.search_rows
    ys = np.array(config.window(len(pl)))
    dl, dr = np.diff(pl, prepend=0), np.diff(pr, prepend=0)        # D(y) = P(y) - P(y - 1); D(0) unused
    costs = np.array([np.abs(dl[ys + o] - dr[ys]).sum() for o in range(-r, r + 1)], dtype=np.int64)
    texture = int(np.abs(dr[ys]).sum())
    k1 = int(np.argmin(costs))                                     # first minimum in the order -R..R
    c1 = int(costs[k1])
    far = np.abs(np.arange(2 * r + 1) - k1) >= 2
    c2 = int(costs[far].min())
    confident = texture >= (width * len(ys)) >> config.texture_shift and c2 - c1 > c2 >> config.margin_shift
    return Search(costs, texture, k1 - r, c1, c2, bool(confident))


@dataclass(frozen=True)
class Decision:
    """The outputs after one frame: ``offset`` in use, ``confident``, ``held`` (no clear minimum: the last offset
    kept), ``locked`` (confident and the best is the offset in use)."""
    offset: int
    confident: bool
    held: bool
    locked: bool


class OffsetTracker:
    """The decision over frames (docs/rectification.md, "Decision over frames"); starts at offset 0."""

    def __init__(self, config=RECTIFICATION):
        self.config = config
        self.offset, self.candidate, self.count = 0, 0, 0

    def step(self, result):
        """Take one frame's :class:`Search`; return the :class:`Decision`."""
        cfg = self.config
        if not result.confident:
            self.count = 0
            return Decision(self.offset, False, True, False)
        in_use = result.cost(self.offset)
        if result.best == self.offset or in_use - result.c1 <= in_use >> cfg.switch_shift:
            self.count = 0
        else:
            if result.best == self.candidate:
                self.count += 1
            else:
                self.candidate, self.count = result.best, 1
            if self.count >= cfg.stable_frames:
                self.offset, self.count = result.best, 0
        return Decision(self.offset, True, False, result.best == self.offset)


def estimate_offsets(frames, config=RECTIFICATION):
    """[:class:`Decision`] for a sequence of (left, right) grey buffer pairs, from reset."""
    tracker = OffsetTracker(config)
    out = []
    for left, right in frames:
        left, right = np.asarray(left), np.asarray(right)
        out.append(tracker.step(search(row_profiles(left), row_profiles(right), left.shape[1], config)))
    return out
