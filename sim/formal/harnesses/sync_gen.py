# amaranth: UnusedElaboratable=no
"""SyncGenerator: raster counters, data enable and the CEA-861 sync pulses.

The generator has no input but its reset, so no assumption: every property holds from any pattern of resets.
Pulse widths are measured by counters in the harness, independent of the generator's position logic; the
``*_count_tracks_*`` helper assertions tie those counters to the raster position so that k-induction closes.
The harness starts the raster (``start``) a little before the vsync pulse so that the covers are shallow; the
raster is one cycle through every position whatever the start, so the proof covers the whole frame.
"""

from amaranth import Mux, Signal

from spec.video import CEA_1080P60, SMALL_TIMING
from hdl.sync_gen import SyncGenerator
from sim.formal.runner import FormalHarness


class SyncGeneratorHarness(FormalHarness):
    name = "sync_gen_small"
    block = "SyncGenerator"

    def __init__(self, timing=SMALL_TIMING, *, bound=None):
        super().__init__()
        self.timing = timing
        self.bound = bound
        self.start = (timing.h_sync_start - 2, timing.v_sync_start - 1)

    def dut(self):
        return SyncGenerator(self.timing, start=self.start)

    def build(self, m):
        t = self.timing
        m.submodules.dut = dut = self.dut()
        # The block's ports (the one place to adapt when the signature changes).
        x, y, de, hsync, vsync, frame_start = dut.x, dut.y, dut.de, dut.hsync, dut.vsync, dut.frame_start

        def prove(name, test):
            self.prove(m, name, test, bound=self.bound)

        hs_on = hsync if t.hsync_positive else ~hsync         # pulse active, whatever the polarity
        vs_on = vsync if t.vsync_positive else ~vsync
        h_end = t.h_sync_start + t.h_sync
        v_first = t.v_sync_start - 1                          # the line whose hsync leading edge starts vsync

        prove("x_below_h_total", x < t.h_total)
        prove("y_below_v_total", y < t.v_total)
        prove("de_exactly_in_active_area", de == ((x < t.h_active) & (y < t.v_active)))
        prove("frame_start_exactly_at_origin", frame_start == ((x == 0) & (y == 0)))
        prove("hsync_window_and_polarity", hs_on == ((x >= t.h_sync_start) & (x < h_end)))

        # The raster advances one pixel a clock and wraps at the totals.
        pv = self.past_valid(m)
        px, py = self.past(m, x, name="past_x"), self.past(m, y, name="past_y")
        line_end = px == t.h_total - 1
        prove("raster_advances", ~pv | ((x == Mux(line_end, 0, px + 1)) &
                                        (y == Mux(line_end, Mux(py == t.v_total - 1, 0, py + 1), py))))

        # vsync edges coincide with hsync leading edges; the pulse starts on line v_first.
        vs_was = self.past(m, vs_on, name="past_vs_on")
        prove("vsync_edges_at_hsync_leading_edge", ~pv | (vs_on == vs_was) | (x == t.h_sync_start))
        prove("vsync_starts_on_line_v_front_after_active", ~pv | ~(vs_on & ~vs_was) | (y == v_first))

        self._widths(m, prove, x, y, hs_on, vs_on, pv)
        if self.bound is None:          # the frame-level covers are thousands of clocks deep at 1080p
            self.cover(m, "frame_wraps_to_origin", pv & frame_start)
            self.cover(m, "first_active_pixel_after_blanking", pv & de & ~self.past(m, de, name="past_de"))

    def _widths(self, m, prove, x, y, hs_on, vs_on, pv):
        """Pulse widths measured in clocks, for pulses whose leading edge the harness saw."""
        t = self.timing
        for pulse, on, width, position in (
                ("hsync", hs_on, t.h_sync, x - t.h_sync_start),
                ("vsync", vs_on, t.v_sync * t.h_total,
                 (y - (t.v_sync_start - 1)) * t.h_total + x - t.h_sync_start)):
            was = self.past(m, on, name=f"past_{pulse}_on")
            count = Signal(range(width + 2), name=f"{pulse}_count")    # clocks of this pulse before this one
            seen = Signal(name=f"{pulse}_leading_edge_seen")
            with m.If(on & (count <= width)):
                m.d.sync += count.eq(count + 1)
            with m.Elif(~on):
                m.d.sync += count.eq(0)
            with m.If(pv & on & ~was):
                m.d.sync += seen.eq(1)
            trailing = pv & was & ~on & seen
            prove(f"{pulse}_width_cea861", ~trailing | (count == width))
            prove(f"{pulse}_count_tracks_position", ~(seen & on & was) | (count == position[:len(count)]))
            if self.bound is None or pulse == "hsync":
                self.cover(m, f"{pulse}_pulse_complete", trailing)


class SyncGenerator1080pHarness(SyncGeneratorHarness):
    """The same properties on CEA-861 1080p60, checked for ``bound`` clocks from the harness's start (through
    the end of one hsync pulse and into the vsync pulse)."""
    name = "sync_gen_1080p"

    def __init__(self, bound=64):
        super().__init__(CEA_1080P60, bound=bound)
