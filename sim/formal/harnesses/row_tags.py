# amaranth: UnusedElaboratable=no
"""RowTagTracker: every row's tag is the frame tag at that row's last start, the busy row is the row in progress,
and the row index never leaves the memory, for any strobes in any order (more row starts than rows, row ends
missing or without a start, frames cut mid-row).

The capture's strobes and the reader's row are free on every clock (the row assumed inside the buffer); the camera
and pix domains are both the harness's ``sync`` (the synchronisers become a fixed delay). The tag a frame takes
(``pair.tag``, the pairing's answer) is free too. The reference follows the tracker's docstring on the
synchronisers' outputs: the frame's tag taken at the frame start, the row starts since the frame start
(saturating at the height), the row in progress, and the tag of one watched row (any row, fixed for the trace).
"""

from amaranth import Mux, Signal

from hdl.row_tags import RowTagTracker
from spec.sensor import SMALL_SENSOR
from sim.formal.runner import FormalHarness

BITS = 2


class RowTagTrackerHarness(FormalHarness):
    name = "row_tags"
    block = "RowTagTracker"

    def __init__(self, geometry=SMALL_SENSOR):
        super().__init__()
        self.geometry = geometry

    def dut(self):
        return RowTagTracker(self.geometry, bits=BITS, cam_domain="sync", pix_domain="sync")

    def build(self, m):
        height = self.geometry.buf_height
        strobes = {k: self.free(k) for k in ("frame_start", "row_start", "row_end")}
        row, watched = self.free("read_row", range(height)), self.free("watched_row", range(height))
        start_tag = self.free("start_tag", BITS)
        dut = self.dut()
        module = self.open(m, "dut", dut)
        # The block's ports and its synchronisers' outputs (the one place to adapt to a new signature).
        m.d.comb += [getattr(dut, k).eq(v) for k, v in strobes.items()] + [dut.read.row.eq(row),
                                                                          dut.pair.tag.eq(start_tag)]
        fs, rs, re = (module.submodules[f"sync_{k}"].o for k in ("frame_start", "row_start", "row_end"))
        tag, busy, frame_tag = dut.read.tag, dut.read.busy, dut.frame_tag

        pv = self.past_valid(m)
        self.assume(m, "read_row_in_buffer", row < height)
        self.hold(m, "watched_row_fixed", watched)     # the watched row stays over resets too
        self.assume(m, "watched_row_in_buffer", watched < height)

        ref_frame = Signal(BITS, name="ref_frame")
        ref_index = Signal(range(height + 1), name="ref_index")
        ref_busy, ref_busy_row = Signal(name="ref_busy"), Signal(range(height), name="ref_busy_row")
        ref_tag = Signal(BITS, name="ref_watched_tag", reset_less=True)     # like the memory: kept over resets
        frame_now = Mux(fs, start_tag, ref_frame)
        index_now = Mux(fs, 0, ref_index)
        starts = rs & (index_now < height)
        with m.If(fs):
            m.d.sync += [ref_frame.eq(frame_now), ref_index.eq(0)]
        with m.If(starts):
            m.d.sync += [ref_index.eq(index_now + 1), ref_busy.eq(1), ref_busy_row.eq(index_now)]
            with m.If(index_now == watched):
                m.d.sync += ref_tag.eq(frame_now)
        with m.Elif(fs | re):
            m.d.sync += ref_busy.eq(0)

        past_row = self.past(m, row, name="past_row")
        self.prove(m, "frame_tag_is_the_tag_taken_at_the_frame_start", frame_tag == ref_frame)
        self.prove(m, "frame_start_reported_to_the_pairing", dut.pair.started == fs)
        past_tag = self.past(m, ref_tag, name="past_ref_watched_tag", reset_less=True)
        self.prove(m, "tag_is_frame_at_last_row_start", ~pv | (past_row != watched) | (tag == past_tag))
        self.prove(m, "busy_exactly_for_row_in_progress",
                   ~pv | (busy == self.past(m, ref_busy & (ref_busy_row == row), name="past_ref_busy")))
        self.cover(m, "last_row_tagged_by_a_second_frame", pv & (past_row == height - 1) & (tag == 2)
                   & (watched == height - 1) & (ref_frame == 2))
        self.cover(m, "row_start_beyond_buffer", rs & (ref_index == height))
        self.cover(m, "last_row_busy", busy & (past_row == height - 1))
