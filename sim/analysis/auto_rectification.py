"""The golden expectation of a multi-frame run in automatic rectification, independent of the RTL.

The design's estimator (docs/rectification.md) searches once both captures have finished a camera frame, on the
row sums of what they wrote: after camera frame k, the buffers hold pair k (``golden.capture.capture_frame``).
:func:`expected_states` runs ``golden/vertical_offset.py``'s estimator over those buffer pairs from reset, giving
per camera frame the :class:`State` after its search (offset in use, held). The offset in use changes only at a
display frame start after a search, so a display frame showing pair k shows it with the state before camera
frame k's search (the one after frame k - 1; at reset offset 0, not held) or after it: :class:`AutoGoldens` holds
both golden frames per pair, finds the per-row frame sources against either (``sim/analysis/frame_sources.py``,
a row from frame k when it equals that row of one of pair k's goldens) and which state a display frame shows.
"""

from dataclasses import dataclass

import numpy as np

from golden.capture import capture_frame
from golden.vertical_offset import estimate_offsets
from sim.analysis.frame_sources import EMPTY, PANELS, frame_sources, source_summary

__all__ = ["State", "RESET", "expected_states", "AutoGoldens"]


@dataclass(frozen=True)
class State:
    """What the screen shows of the automatic rectification: the ``offset`` in use (buffer rows), ``held``."""
    offset: int
    held: bool

    def text(self):
        return f"{self.offset:+d} {'held' if self.held else 'auto'}"


#: The estimator's state from reset, before any search.
RESET = State(0, False)


def expected_states(setup, sequence):
    """[:class:`State`] after camera frame k's search, for each k, from the pairs as the buffers hold them."""
    g = setup.geometry
    buffers = [(capture_frame(setup.fit(left), g), capture_frame(setup.fit(right), g))
               for left, right in sequence.pairs]
    return [State(d.offset, d.held) for d in estimate_offsets(buffers, setup.auto_rectification)]


class AutoGoldens:
    """The goldens of an automatic-rectification run of ``sequence`` on ``setup`` (see the module docstring):
    ``states`` (per camera frame, after its search), ``before`` / ``after`` (``{pair: golden frame}`` with the
    state before / after its search; both hold :data:`EMPTY`, the zero buffers at reset)."""

    def __init__(self, setup, sequence):
        self.setup, self.states = setup, expected_states(setup, sequence)
        black = np.zeros_like(sequence.pairs[0][0])
        self.state_of = {("before", k): (self.states[k - 1] if k else RESET) for k in range(len(sequence))}
        self.state_of.update({("after", k): s for k, s in enumerate(self.states)})
        self.state_of[("before", EMPTY)] = self.state_of[("after", EMPTY)] = RESET
        frames = {}
        for (when, k), s in self.state_of.items():
            if s not in frames.setdefault(k, {}):
                pair = (black, black) if k == EMPTY else sequence.pairs[k]
                frames[k][s] = setup.golden_frame(*pair, in_use=s.offset, held=s.held)
        self.before = {k: frames[k][self.state_of[("before", k)]] for k in frames}
        self.after = {k: frames[k][self.state_of[("after", k)]] for k in frames}

    def expected(self, frames_done):
        """The state a display frame starting when the slower capture had finished ``frames_done`` camera frames
        shows: the one after the last of those frames' searches."""
        return self.states[frames_done - 1] if frames_done else RESET

    def sources(self, frame, layout, geometry):
        """``frame_sources`` against both goldens of each pair: a row comes from frame k when it equals pair k's
        golden row with either state (per panel the union), ``equals`` likewise."""
        a = frame_sources(frame, self.after, layout, geometry)
        b = frame_sources(frame, self.before, layout, geometry)
        out = {panel: [x | y for x, y in zip(a[panel], b[panel])] for panel in PANELS}
        out["equals"] = sorted(set(a["equals"]) | set(b["equals"]))
        out["shown"] = {self.state_of[("after", k)] for k in a["equals"]} | \
                       {self.state_of[("before", k)] for k in b["equals"]}
        return out

    def row(self, frame, layout, geometry, frames_done):
        """The per-frame table's columns: ``source_summary`` of :meth:`sources` plus ``rectification_shown`` (the
        state of the golden the whole frame equals, e.g. ``"+3 auto"``; None when it equals none) and
        ``rectification_expected`` (:meth:`expected`)."""
        sources = self.sources(frame, layout, geometry)
        shown = sorted(sources["shown"], key=lambda s: (s.offset, s.held))
        return dict(source_summary(sources),
                    rectification_shown=" / ".join(s.text() for s in shown) if shown else None,
                    rectification_expected=self.expected(frames_done).text())

    def changes(self):
        """``[(camera frame, old state, new state)]`` where the offset in use changes after that frame's search."""
        prev, out = RESET, []
        for k, s in enumerate(self.states):
            if s.offset != prev.offset:
                out.append((k, prev, s))
            prev = s
        return out
