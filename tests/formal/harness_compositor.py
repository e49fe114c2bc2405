"""Compositor: every read stays in its buffer, each port serves one reader per clock, the regions never overlap.

The raster comes from a :class:`~hdl.sync_gen.SyncGenerator` of the same timing (the display path's own, and the
compositor's interface contract: a raster in scan order). The buffers' read data are free (any contents). The
switch registers are free except that they change only in the clock after ``frame_start``, which
:class:`~hdl.switches.SwitchControl` guarantees (proven in ``harness_switches``). The harness computes each
region's pixel, buffer address and shifted read from the raster position with the layout's own numbers and
compares them with the ports through the compositor's pipeline.
"""

from amaranth import Cat, Mux, Signal
from amaranth.lib import wiring

from hdl.compositor import LATENCY, Compositor
from hdl.params import BACKGROUND_RGB, NO_DATA_RGB, SMALL_SENSOR, SMALL_TIMING, DisplayLayout, Region
from hdl.switches import SWITCH_VALUE_BITS
from hdl.sync_gen import SyncGenerator
from sim.formal import FormalHarness

#: Clocks from the raster position to the read addresses, and to the read data.
ADDRESS_LATENCY, DATA_LATENCY = 2, 3


def top_layout(timing, geometry):
    """The three regions side by side from the raster's first line (left, right, disparity at 2x), so that
    the covers are a few hundred clocks deep; the same properties hold for any layout the compositor accepts
    (the slow variant proves the default centred one)."""
    w, h = geometry.buf_width, geometry.buf_height
    return DisplayLayout(regions=(Region("left", 0, 0, 1, w, h), Region("right", w, 0, 1, w, h),
                                  Region("disparity", 2 * w, 0, 2, w, h)))


class CompositorHarness(FormalHarness):
    name = "compositor"
    block = "Compositor"
    engine = "induction"            # closes at k = 8 with the scanner invariants; PDR does not finish in 10 min
    max_steps = 12

    def __init__(self, timing=SMALL_TIMING, geometry=SMALL_SENSOR, layout=None):
        super().__init__()
        self.timing, self.geometry = timing, geometry
        self.layout = layout or top_layout(timing, geometry)

    def dut(self):
        return Compositor(self.timing, self.geometry, self.layout)

    def build(self, m):
        g = self.geometry
        free = {name: self.free(name, width) for name, width in (
            ("disparity", SWITCH_VALUE_BITS), ("rectification", SWITCH_VALUE_BITS),
            ("left_data", g.gray_bits), ("right_data", g.gray_bits))}
        m.submodules.raster = raster = SyncGenerator(self.timing)
        dut = self.dut()
        module = self.open(m, "dut", dut)
        # The block's ports (the one place to adapt when the signature changes).
        wiring.connect(m, raster, dut.timing)
        m.d.comb += [dut.settings.disparity.eq(free["disparity"]),
                     dut.settings.rectification.eq(free["rectification"]),
                     dut.left.data.eq(free["left_data"]), dut.right.data.eq(free["right_data"])]
        ports = {"left": dut.left.addr, "right": dut.right.addr}
        video = dut.video

        pv = self.past_valid(m)
        for name in ("disparity", "rectification"):
            changed = pv & (free[name] != self.past(m, free[name], name=f"past_{name}"))
            self.assume(m, f"{name}_changes_only_after_frame_start",
                        ~changed | self.past(m, raster.frame_start, name=f"past_frame_start_{name}"))

        # Helper invariants: the raster stays in the frame (proven for the generator itself in harness_sync_gen).
        self.prove(m, "raster_x_in_line", raster.x < self.timing.h_total)
        self.prove(m, "raster_y_in_frame", raster.y < self.timing.v_total)
        inside = {r.source: (raster.x >= r.x0) & (raster.x < r.x1) & (raster.y >= r.y0) & (raster.y < r.y1)
                  for r in self.layout.regions}
        self.prove(m, "regions_never_overlap",
                   sum(v.as_unsigned() for v in inside.values()) <= 1)
        for port, address in ports.items():
            self.prove(m, f"{port}_port_address_in_buffer", address < g.buf_depth)
        self._reads(m, raster, free, ports, inside)
        self._video(m, raster, free, video, inside)
        for r in self.layout.regions:
            self._scanner_tracks_raster(m, raster, r, module.submodules[f"scan_{r.source}"])

    def _scanner_tracks_raster(self, m, raster, r, scanner):
        """Helper invariant: a region's running counters (``scan_<region>``) are the raster's progress through
        the region up to the pixel 2 clocks ago (flags 1 clock, counters 1 clock); 0 in vertical blanking."""
        x = self.past(m, raster.x, 2, name=f"scan_{r.source}_x")
        y = self.past(m, raster.y, 2, name=f"scan_{r.source}_y")
        in_rows = (y >= r.y0) & (y < r.y1)
        lines = Signal(range(r.height * r.scale + 1), name=f"scan_{r.source}_lines_done")
        pixels = Signal(range(r.width * r.scale + 1), name=f"scan_{r.source}_pixels_done")
        m.d.comb += [
            lines.eq(Mux(y < r.y0, 0, Mux(y >= r.y1, r.height * r.scale, y - r.y0 + (x >= r.x1 - 1)))),
            pixels.eq(Mux(in_rows & (x >= r.x0) & (x < r.x1 - 1), x - r.x0 + 1, 0)),
        ]
        blank = y >= self.timing.v_active
        lines, pixels = Mux(blank, 0, lines), Mux(blank, 0, pixels)
        yb, xb = lines // r.scale, pixels // r.scale
        row_start = yb * self.geometry.buf_width
        expected = ((scanner.yb == yb) & (scanner.xb == xb) & (scanner.addr == row_start + xb) &
                    (scanner.row_start == row_start))
        if r.scale > 1:
            expected &= (scanner.x_phase == pixels % r.scale) & (scanner.y_phase == lines % r.scale)
        self.prove(m, f"scan_{r.source}_tracks_raster", ~self.past_valid(m, 2) | expected)

    def _pixel(self, m, raster, region, clocks, tag):
        """Buffer coordinates and address of the raster pixel ``clocks`` clocks ago in ``region``."""
        r = self.layout.region(region)
        shift = r.scale.bit_length() - 1
        assert r.scale == 1 << shift, "the harness divides by the scale with a shift"
        x = self.past(m, raster.x, clocks, name=f"{tag}_x")
        y = self.past(m, raster.y, clocks, name=f"{tag}_y")
        xb, yb = ((x - r.x0) >> shift)[:8], ((y - r.y0) >> shift)[:8]
        return xb, yb, (yb * self.geometry.buf_width + xb)

    def _inside(self, m, inside, region, clocks, tag):
        return self.past_valid(m, clocks) & self.past(m, inside[region], clocks, name=f"{tag}_in_{region}")

    def _reads(self, m, raster, free, ports, inside):
        g, n = self.geometry, ADDRESS_LATENCY
        for side in ("left", "right"):
            _, _, address = self._pixel(m, raster, side, n, f"read_{side}")
            self.prove(m, f"{side}_port_reads_{side}_image",
                       ~self._inside(m, inside, side, n, "read") | (ports[side] == address))
        xb, yb, address = self._pixel(m, raster, "disparity", n, "read_disparity")
        d = self.past(m, free["disparity"], n - 1, name="read_disparity_value")
        r = self.past(m, free["rectification"], n - 1, name="read_rectification_value")
        outside = (xb + d >= g.buf_width) | (yb + r >= g.buf_height)
        in_disparity = self._inside(m, inside, "disparity", n, "read")
        self.prove(m, "right_port_reads_disparity_pixel", ~in_disparity | (ports["right"] == address))
        self.prove(m, "left_port_reads_shifted_pixel_or_idles", ~in_disparity |
                   (ports["left"] == Mux(outside, 0, (yb + r) * g.buf_width + xb + d)))
        self.cover(m, "left_image_read_in_second_row",
                   self._inside(m, inside, "left", n, "read") & (ports["left"] == g.buf_width))
        self.cover(m, "shifted_read_leaves_image", in_disparity & outside & (d != 0))

    def _video(self, m, raster, free, video, inside):
        n = LATENCY
        ready = self.past_valid(m, n)
        for name in ("de", "hsync", "vsync"):
            self.prove(m, f"video_{name}_is_raster_{name}_delayed",
                       ~ready | (getattr(video, name) == self.past(m, getattr(raster, name), n, name=f"video_{name}")))
        any_region = sum(v.as_unsigned() for v in inside.values()) != 0
        de = self.past(m, raster.de, n, name="shown_de")
        shown_outside = self.past(m, ~any_region, n, name="shown_outside_regions")
        self.prove(m, "blank_is_black", ~ready | de | (video.rgb == 0))
        self.prove(m, "background_outside_regions", ~(ready & de & shown_outside) | (video.rgb == BACKGROUND_RGB))
        for side in ("left", "right"):
            data = self.past(m, free[f"{side}_data"], n - DATA_LATENCY, name=f"shown_{side}_data")
            grey8 = Cat(data[2:5], data)                      # 5-bit grey repeated from the MSB down to 8 bits
            self.prove(m, f"{side}_image_shows_read_grey",
                       ~self._inside(m, inside, side, n, "shown") | (video.rgb == Cat(grey8, grey8, grey8)))
        xb, yb, _ = self._pixel(m, raster, "disparity", n, "shown_disparity")
        d = self.past(m, free["disparity"], n - 1, name="shown_disparity_value")
        r = self.past(m, free["rectification"], n - 1, name="shown_rectification_value")
        outside = (xb + d >= self.geometry.buf_width) | (yb + r >= self.geometry.buf_height)
        in_disparity = self._inside(m, inside, "disparity", n, "shown")
        self.prove(m, "no_data_colour_exactly_when_shift_leaves_image",
                   ~in_disparity | ((video.rgb == NO_DATA_RGB) == outside))
        self.cover(m, "no_data_shown", in_disparity & outside)
        self.cover(m, "disparity_level_shown", in_disparity & ~outside & (video.rgb != 0))
