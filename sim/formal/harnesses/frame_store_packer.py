# amaranth: UnusedElaboratable=no
"""BurstPacker: for any capture strobes and pixel writes -- rows of any length, frames of any number of rows, strobes
at any time, the FIFO ready or not -- an ``END`` entry says ``ok`` only for a frame the capture called ok in which
every row that ended had exactly ``width`` pixels (a short or long row spoils it, even when its bursts are all
there) and no pixel was written after ``height`` rows had ended (a row beyond the height spoils it).

The reference counts the writes of the row in progress itself (from ``row_start``) and the rows that ended (from
``frame_start``, saturating at ``height``), and notes, per frame, whether a row ended with another count or a pixel
came after ``height`` rows; at ``frame_done`` it keeps that note and the capture's
verdict for the ``END`` to come. It is written from docs/frame_store.md ("Camera writers"), not from the packer's
counters. The capture's strobes come one at a time (``frame_start``, ``frame_done``, ``row_start``, ``row_end``
exclusive; a pixel write not with ``frame_start``, ``frame_done`` or ``row_start``), as hdl/capture.py issues them.
"""

from amaranth import Signal

from hdl.frame_store.burst_packer import ENTRY_KINDS, BurstPacker
from hdl.frame_store.layout import FrameStoreLayout
from sim.formal.runner import FormalHarness
from spec.sensor import SensorGeometry

#: 2 rows of 40 pixels: a row's second burst holds 8 of its 32 bytes.
LAYOUT = FrameStoreLayout(width=40, height=2, cameras=1, buffers=3)
GEOMETRY = SensorGeometry(width=160, height=8)


class FrameStorePackerHarness(FormalHarness):
    name = "frame_store_packer"
    block = "BurstPacker"

    def dut(self):
        return BurstPacker(LAYOUT, GEOMETRY)

    def build(self, m):
        lay = LAYOUT
        m.submodules.dut = dut = self.dut()
        st, wr = dut.status, dut.write
        strobes = [st.frame_start, st.frame_done, st.row_start, st.row_end]
        for s, name in zip(strobes, ("frame_start", "frame_done", "row_start", "row_end")):
            m.d.comb += s.eq(self.free(name))
        m.d.comb += [st.frame_ok.eq(self.free("frame_ok")), wr.en.eq(self.free("write")),
                     dut.entry.rdy.eq(self.free("rdy"))]        # the pixels' values (0) matter to no property
        for i, a in enumerate(strobes):
            for b in strobes[i + 1:]:
                self.assume(m, f"one_strobe_{a.name}_{b.name}", ~(a & b))
        self.assume(m, "no_write_with_a_start_or_done", ~(wr.en & (st.frame_start | st.frame_done | st.row_start)))

        in_row = Signal(name="ref_in_row")
        pixels = Signal(range(lay.width + 2), name="ref_pixels")      # saturating at width + 1
        rows = Signal(range(lay.height + 1), name="ref_rows")          # rows ended, saturating at height
        bad = Signal(name="ref_frame_has_a_bad_row")
        done_ok = Signal(name="ref_done_ok")                          # the verdict the next END may give
        done_capture_ok = Signal(name="ref_done_capture_ok")
        row_ends_bad = st.row_end & in_row & (pixels + (wr.en & (pixels <= lay.width)) != lay.width)
        with m.If(st.frame_start):
            m.d.sync += [bad.eq(0), in_row.eq(0), rows.eq(0)]
        with m.If(st.row_end & in_row & (rows != lay.height)):
            m.d.sync += rows.eq(rows + 1)
        with m.If(wr.en & in_row & (rows == lay.height)):              # a pixel of a row beyond the height
            m.d.sync += bad.eq(1)
        with m.If(st.row_start):
            m.d.sync += [in_row.eq(1), pixels.eq(0)]
        with m.If(wr.en & in_row & (pixels <= lay.width)):
            m.d.sync += pixels.eq(pixels + 1)
        with m.If(st.row_end):
            m.d.sync += in_row.eq(0)
            with m.If(row_ends_bad):
                m.d.sync += bad.eq(1)
        with m.If(st.frame_done):
            m.d.sync += [done_ok.eq(st.frame_ok & ~bad), done_capture_ok.eq(st.frame_ok)]

        entry = dut.entry
        sent = entry.en & entry.rdy
        end = sent & (entry.data.kind == ENTRY_KINDS["END"])
        self.prove(m, "end_ok_only_for_a_frame_of_whole_rows_the_capture_called_ok",
                   ~(end & entry.data.ok) | done_ok)
        self.cover(m, "an_ok_end", end & entry.data.ok)
        self.cover(m, "the_end_of_a_frame_the_capture_called_ok_with_a_bad_row", end & done_capture_ok & ~done_ok)
