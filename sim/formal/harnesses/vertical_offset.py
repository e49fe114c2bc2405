# amaranth: UnusedElaboratable=no
"""VerticalOffsetEstimator: the offset in use is always in -R..R and changes only with ``done``; every read of
the profile memories is inside them and every cost address inside the cost memory, for every offset swept.

Every input is free on every clock (both cameras' write ports and ``frame_done`` strobes, in one domain here):
no assumption at all. The geometry is tiny (2 x 10 buffers, 2-bit grey, R = 2: a height that is no
power of two, so an address one past the last row is a representable, wrong value).
"""

from hdl.vertical_offset import VerticalOffsetEstimator
from sim.formal.runner import FormalHarness
from spec.rectification import RectificationConfig
from spec.sensor import SensorGeometry

TINY = SensorGeometry(width=8, height=40, scale=4, grey_bits=2)
TINY_CONFIG = RectificationConfig(search_rows=2)


class VerticalOffsetHarness(FormalHarness):
    name = "vertical_offset"
    block = "VerticalOffsetEstimator"

    def __init__(self, geometry=TINY, config=TINY_CONFIG):
        super().__init__()
        self.geometry, self.config = geometry, config

    def dut(self):
        return VerticalOffsetEstimator(self.geometry, self.config)

    def build(self, m):
        g, r = self.geometry, self.config.search_rows
        m.submodules.dut = dut = self.dut()
        # The block's ports (the one place to adapt when the signature changes).
        for side in ("left", "right"):
            port = getattr(dut, side)
            for member, shape in (("addr", g.addr_bits), ("data", g.grey_bits), ("en", 1), ("frame_done", 1)):
                m.d.comb += getattr(port, member).eq(self.free(f"{side}_{member}", shape))
        offset, best, done = dut.offset, dut.best, dut.done

        pv = self.past_valid(m)
        self.prove(m, "offset_in_search_range", (offset >= -r) & (offset <= r))
        self.prove(m, "best_in_search_range", (best >= -r) & (best <= r))
        self.prove(m, "offset_changes_only_with_done", ~pv | (offset == self.past(m, offset)) | done)
        self.prove(m, "left_profile_read_in_memory", dut.profile_addr_left < g.buf_height)
        self.prove(m, "right_profile_read_in_memory", dut.profile_addr_right < g.buf_height)
        self.prove(m, "cost_read_in_memory", dut.cost_addr < 2 * r + 1)
        self.prove(m, "zero_after_reset", pv | (offset == 0))
        self.cover(m, "search_done", done)
        self.cover(m, "left_reads_first_row", dut.busy & (dut.profile_addr_left == 0))
        self.cover(m, "left_reads_last_row", dut.busy & (dut.profile_addr_left == g.buf_height - 1))
