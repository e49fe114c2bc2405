"""Golden model of the frame pairing (docs/capture.md, "Frame pairs"), written from the spec.

A frame start of one camera *joins* the open pair (takes its tag) when the other camera has started in that pair
and this one has not; otherwise it *opens* a new pair: the pair tag counts up by one, mod ``2**bits``, and only
this camera has started in it. Starts in one clock are taken camera A first, then camera B. At reset the pair
tag is 0 and no camera has started.

Only constants come from ``spec``; nothing is taken from the RTL.
"""

from spec.sensor import ROW_TAG_BITS

__all__ = ["pair_tags"]

CAMERAS = ("a", "b")


def pair_tags(clocks, bits=ROW_TAG_BITS):
    """The tags given to the frame starts of ``clocks``, a sequence with one entry per clock: the cameras that
    start in that clock (a string or set over "a" and "b"; empty for none). Returns one dict per clock, camera ->
    tag, for the cameras that start in it."""
    if bits < 1:
        raise ValueError(f"bits must be at least 1, got {bits}")
    pair, members, out = 0, set(), []
    for starts in clocks:
        unknown = set(starts) - set(CAMERAS)
        if unknown:
            raise ValueError(f"unknown camera(s) {sorted(unknown)}: cameras are 'a' and 'b'")
        given = {}
        for camera in CAMERAS:
            if camera not in starts:
                continue
            other = "b" if camera == "a" else "a"
            if other in members and camera not in members:
                members.add(camera)
            else:
                pair, members = (pair + 1) % (1 << bits), {camera}
            given[camera] = pair
        out.append(given)
    return out
