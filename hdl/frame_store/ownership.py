"""BufferOwnership: who owns each camera's frame buffers in the frame store (docs/frame_store.md, "Ownership").

Every camera has ``buffers`` buffers. Each is, per camera, in at most one of these roles (a held buffer may also be
the latest pair's):

* **writing**: the camera's writer owns it, from the writer's ``start`` (the frame's start) to its ``finish``;
* **pending**: a finished, complete frame waiting for the other cameras' frames of its pair;
* **latest**: the latest complete pair's frame;
* **held** by reader ``r``: the pair reader ``r`` took at its ``take`` (the start of its display frame or depth map),
  until its next ``take`` or its ``release``;
* free: none of these.

Rules, applied in this order within a clock (each step sees the previous steps' results):

1. A writer's ``finish`` ends its frame: a ``complete`` frame becomes the camera's pending frame (an older pending
   frame of that camera is dropped, freed); an incomplete one is freed. A ``finish`` with no frame does nothing.
2. Pairs: when every camera has a pending frame and, with two cameras, both frames carry the same pair tag, the
   pending frames together become the latest pair (the pair's previous frames are freed unless held) and nothing
   is pending. A frame's tag is the one :class:`hdl.frame_pairing.FramePairing` gives its start (docs/capture.md,
   "Frame pairs": frame *k* of synchronised cameras shares a tag, in whichever order they start). A camera that
   drops a frame leaves the other's frame pending with an older tag, replaced by that camera's next frame, which
   pairs with the dropping camera's next one; a camera that stops leaves the latest pair as it is (readers keep
   reading it whole).
3. A reader's ``take`` holds the latest pair as it was before this clock (registered), or nothing when there is no
   pair yet; ``release`` holds nothing.
4. A writer's ``start`` frees the buffer it was writing (a frame without ``finish`` is abandoned) and takes the
   lowest-numbered free buffer -- one that is not latest, held (after step 3) or pending -- or, when there is none,
   its camera's pending frame (dropped: its pair never formed). With ``buffers >= readers + 2`` one of the two always
   exists, so a writer always gets a buffer, and never one that is latest or held.

So a writer never writes a buffer that a reader holds or that is the latest pair's, and the latest pair and every
held pair are frames their writers finished as complete. A read already sent to the memory before a ``take``
released its buffer is ahead of any write to that buffer in the memory's one command queue.

Under ``platform == "formal"`` the block asserts its own invariants (the roles are disjoint, the pair is whole);
the harness ``sim/formal/harnesses/frame_store.py`` proves them and the rules' consequences.

"""

from amaranth import Cat, Module, Mux, Signal
from amaranth.hdl import Assert
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.frame_pairing import FramePairing
from hdl.signature import ParametricSignature
from spec.sensor import ROW_TAG_BITS

__all__ = ["BufferOwnership", "WriterOwnershipSignature", "ReaderHoldSignature", "check_ownership"]


def check_ownership(cameras, readers, buffers, pair_bits=ROW_TAG_BITS):
    """``ValueError`` unless a :class:`BufferOwnership` can be built: 1 or 2 cameras, a reader, ``readers + 2``
    buffers, a tag bit."""
    if cameras not in (1, 2) or readers < 1:
        raise ValueError(f"cameras must be 1 or 2 and readers at least 1, got {cameras} and {readers}")
    if buffers < readers + 2:
        raise ValueError(f"{readers} reader(s) need at least {readers + 2} buffers per camera, got {buffers}")
    if pair_bits < 1:
        raise ValueError(f"pair_bits must be at least 1, got {pair_bits}")


def _bits(buffers):
    return max(1, (buffers - 1).bit_length())


class WriterOwnershipSignature(ParametricSignature):
    """A camera writer's link to the ownership, as the writer sees it: ``start``, ``finish`` (one-clock pulses),
    ``complete`` (with ``finish``: the frame was written whole) out; ``buffer`` (the buffer it owns) and ``writing``
    (it owns one) in, registered."""

    def __init__(self, buffers):
        super().__init__({"start": Out(1), "finish": Out(1), "complete": Out(1),
                          "buffer": In(_bits(buffers)), "writing": In(1)}, buffers=buffers)


class ReaderHoldSignature(ParametricSignature):
    """A reader's link to the ownership, as the reader sees it: ``take``, ``release`` (pulses) out; ``valid`` (it
    holds a pair) and ``buffer`` (per camera, the held buffer) in, registered."""

    def __init__(self, cameras, buffers):
        super().__init__({"take": Out(1), "release": Out(1), "valid": In(1),
                          "buffer": In(_bits(buffers)).array(cameras)}, cameras=cameras, buffers=buffers)


class BufferOwnership(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    cameras : int
        1 or 2 (two are paired by :class:`hdl.frame_pairing.FramePairing`'s tags).
    pair_bits : int
        The pair tags' width.
    readers : int
        Independent holders (the display with the depth engine is one: both read the pair taken at the display frame's
        start).
    buffers : int
        Buffers per camera, at least ``readers + 2``.

    Attributes
    ----------
    writers : ``In(WriterOwnershipSignature(buffers)).array(cameras)``
    readers : ``In(ReaderHoldSignature(cameras, buffers)).array(readers)``
        (``readers`` the port; the count is ``n_readers``.)

    Clock domain: ``sync`` (the frame store renames it to ``mem``). Latency: ``buffer``/``writing``, ``valid``/``buffer``
    answer one clock after ``start``/``finish``, ``take``/``release``.

    Raises
    ------
    ValueError
        ``cameras`` not 1 or 2, ``readers`` below 1, ``buffers`` below ``readers + 2``, the pairing's check.
    """

    def __init__(self, cameras=2, readers=1, buffers=3, *, pair_bits=ROW_TAG_BITS):
        check_ownership(cameras, readers, buffers, pair_bits)
        self.pair_bits = pair_bits
        self.cameras, self.n_readers, self.buffers = cameras, readers, buffers
        super().__init__({
            "writers": In(WriterOwnershipSignature(buffers)).array(cameras),
            "readers": In(ReaderHoldSignature(cameras, buffers)).array(readers),
        })

    def elaborate(self, platform):
        m = Module()
        bits, nb = _bits(self.buffers), self.buffers
        latest_valid = Signal()
        latest = [Signal(bits, name=f"latest_{c}") for c in range(self.cameras)]
        pending_valid = [Signal(name=f"pending_valid_{c}") for c in range(self.cameras)]
        pending = [Signal(bits, name=f"pending_{c}") for c in range(self.cameras)]

        tags, pending_tags_1 = self._tags(m)
        # 1. finish: the pending frames after this clock's finishes.
        pending_valid_1, pending_1 = [], []
        for c, w in enumerate(self.writers):
            pv, p = Signal(name=f"pending_valid_1_{c}"), Signal(bits, name=f"pending_1_{c}")
            publish = w.finish & w.writing & w.complete
            m.d.comb += [pv.eq(pending_valid[c] | publish), p.eq(Mux(publish, w.buffer, pending[c]))]
            pending_valid_1.append(pv)
            pending_1.append(p)
            if tags:
                m.d.comb += pending_tags_1[c].eq(Mux(publish, tags["frame"][c], tags["pending"][c]))
                m.d.sync += tags["pending"][c].eq(pending_tags_1[c])
        # 2. pairs.
        promote = Signal()
        same_pair = pending_tags_1[0] == pending_tags_1[1] if tags else 1
        m.d.comb += promote.eq(Cat(*pending_valid_1).all() & same_pair)
        latest_valid_2 = latest_valid | promote
        latest_2 = [Mux(promote, pending_1[c], latest[c]) for c in range(self.cameras)]
        pending_valid_2 = [pv & ~promote for pv in pending_valid_1]
        # 3. take / release.
        held_valid_3 = []
        held_3 = []
        for r, reader in enumerate(self.readers):
            hv = Signal(name=f"held_valid_3_{r}")
            m.d.comb += hv.eq(Mux(reader.take, latest_valid, Mux(reader.release, 0, reader.valid)))
            held_valid_3.append(hv)
            held_3.append([Mux(reader.take, latest[c], reader.buffer[c]) for c in range(self.cameras)])
            m.d.sync += reader.valid.eq(hv)
            for c in range(self.cameras):
                m.d.sync += reader.buffer[c].eq(held_3[r][c])
        # 4. start.
        for c, w in enumerate(self.writers):
            free = Signal(nb, name=f"free_{c}")
            for b in range(nb):
                taken = (latest_valid_2 & (latest_2[c] == b)) | (pending_valid_2[c] & (pending_1[c] == b))
                for r in range(self.n_readers):
                    taken |= held_valid_3[r] & (held_3[r][c] == b)
                m.d.comb += free[b].eq(~taken)
            choice = Signal(bits, name=f"choice_{c}")
            with m.If(free.any()):
                for b in reversed(range(nb)):
                    with m.If(free[b]):
                        m.d.comb += choice.eq(b)
            with m.Else():
                m.d.comb += choice.eq(pending_1[c])
            drops_pending = w.start & ~free.any()
            m.d.sync += [
                pending_valid[c].eq(pending_valid_2[c] & ~drops_pending),
                pending[c].eq(pending_1[c]),
                latest[c].eq(latest_2[c]),
            ]
            with m.If(w.start):
                m.d.sync += [w.writing.eq(1), w.buffer.eq(choice)]
            with m.Elif(w.finish):
                m.d.sync += w.writing.eq(0)
        m.d.sync += latest_valid.eq(latest_valid_2)

        if platform == "formal":
            self._invariants(m, latest_valid, latest, pending_valid, pending, tags)
        return m

    def _tags(self, m):
        """Two cameras: the pairing, each writer's frame tag (taken at its start) and each pending frame's; the
        pending tags after this clock's finishes are returned for the caller to drive. One camera: none."""
        if self.cameras == 1:
            return None, [None]
        m.submodules.pairing = pairing = FramePairing(self.pair_bits)
        tags = {"frame": [], "pending": []}
        for c, (w, side) in enumerate(zip(self.writers, (pairing.a, pairing.b))):
            frame, pending = Signal(self.pair_bits, name=f"frame_tag_{c}"), Signal(self.pair_bits, name=f"pending_tag_{c}")
            m.d.comb += side.started.eq(w.start)
            with m.If(w.start):
                m.d.sync += frame.eq(side.tag)
            tags["frame"].append(frame)
            tags["pending"].append(pending)
        return tags, [Signal(self.pair_bits, name=f"pending_tag_1_{c}") for c in range(2)]

    def _invariants(self, m, latest_valid, latest, pending_valid, pending, tags):
        """The roles are disjoint (a held buffer may be the latest); no pair is left pending."""
        for c, w in enumerate(self.writers):
            m.d.comb += [
                Assert(w.buffer < self.buffers, f"writer {c} owns an existing buffer"),
                Assert(~(w.writing & latest_valid & (w.buffer == latest[c])), f"writer {c} writes the latest"),
                Assert(~(w.writing & pending_valid[c] & (w.buffer == pending[c])), f"writer {c} writes pending"),
                Assert(~(latest_valid & pending_valid[c] & (latest[c] == pending[c])), f"camera {c} pending latest"),
            ]
            for r, reader in enumerate(self.readers):
                m.d.comb += [
                    Assert(~(w.writing & reader.valid & (w.buffer == reader.buffer[c])),
                           f"writer {c} writes reader {r}'s buffer"),
                    Assert(~(pending_valid[c] & reader.valid & (pending[c] == reader.buffer[c])),
                           f"camera {c} pending held by reader {r}"),
                ]
        same = tags["pending"][0] == tags["pending"][1] if tags else 1
        m.d.comb += Assert(~(Cat(*pending_valid).all() & same), "a whole pair is left pending")
