# amaranth: UnusedElaboratable=no
"""Compositor: every frame-buffer and result-ring read stays inside its memory, each read port serves one reader
per clock, the layout's areas never overlap.

The compositor is the small system's (SMALL_TIMING, SMALL_SENSOR's 16 x 12 buffers, SMALL_DEPTH) with the four
panels packed on the first lines (:func:`packed_layout`), so that the covers are a few hundred clocks deep; the
same properties hold for any layout the compositor accepts (the slow variant ``compositor_centred`` proves the
centred one that :meth:`sim.testbench.system.SystemSetup.small` shows). Its raster comes from a
:class:`~hdl.sync_gen.SyncGenerator` of the same timing (the display path's own, and the compositor's interface
contract: a raster in scan order). The buffers' and the result ring's read data and the engine's ``rows_ready``
are free. The switch registers are free except that they change only in the clock after ``frame_start``, which
:class:`~hdl.switches.SwitchControl` guarantees (proven in ``harness_switches``).
"""

from amaranth import Mux, Signal
from amaranth.lib import wiring

from hdl.compositor import Compositor
from spec.depth import SMALL_DEPTH
from spec.display import READOUT_TEXT
from spec.layout import ColourBar, DisplayLayout, Region, TextBox
from spec.sensor import SMALL_SENSOR
from spec.video import SMALL_TIMING
from hdl.switches import SWITCH_VALUE_BITS
from hdl.sync_gen import SyncGenerator
from sim.formal.runner import FormalHarness

#: Clocks from the raster position to the read addresses and requests (compositor pipeline, clock n + 2).
ADDRESS_LATENCY = 2
#: Result-ring rows (the small system's engine).
OUT_ROWS = 4


def packed_layout(geometry=SMALL_SENSOR, config=SMALL_DEPTH, image_shrink=1, map_scale=2):
    """Left and right at 1x (at 1 / ``image_shrink`` size), the difference and depth maps at 2x (``map_scale``) and
    the colour bar side by side from the raster's first line (the disparity map starts 2 pixels after the origin,
    where the switch registers have settled), the readout below the difference map; no tick marks or labels."""
    w, h = geometry.buf_width, geometry.buf_height
    left = Region("left", 2, 0, 1, w, h, image_shrink)
    right = Region("right", left.x1 + 2, 0, 1, w, h, image_shrink)
    disparity = Region("disparity", right.x1 + 2, 0, map_scale, w, h)
    depth = Region("depth", disparity.x1 + 2, 0, map_scale, w, h)
    bar = ColourBar(depth.x1 + 2, 0, 2, max(1, map_scale * h // config.disparities), config.disparities)
    readout = TextBox(READOUT_TEXT, disparity.x0, disparity.y1 + 2, 1)
    return DisplayLayout(regions=(left, right, disparity, depth), bar=bar, readout=readout,
                         crosshair_arm=min(w // 2, h // 2) - 1)


class CompositorHarness(FormalHarness):
    name = "compositor"
    block = "Compositor"
    engine = "induction"            # with the scanner invariants; PDR did not finish in 300 s without them
    max_steps = 12

    def __init__(self, timing=SMALL_TIMING, geometry=SMALL_SENSOR, config=SMALL_DEPTH, layout=None,
                 out_rows=OUT_ROWS):
        super().__init__()
        self.timing, self.geometry, self.config, self.out_rows = timing, geometry, config, out_rows
        self.layout = layout or packed_layout(geometry, config)

    def dut(self):
        return Compositor(self.timing, self.geometry, self.layout, config=self.config, out_rows=self.out_rows)

    def areas(self):
        """The layout's boxes that must not overlap: the four panels, the colour bar, its ticks and labels, and
        the readout unless it lies inside the depth map (:func:`hdl.compositor.check_layout`)."""
        layout = self.layout
        named = {f"region_{r.source}": r.box for r in layout.regions}
        named["bar"] = layout.bar.box
        named.update((f"tick_{i}", t) for i, t in enumerate(layout.ticks))
        named.update((f"label_{i}", t.box) for i, t in enumerate(layout.labels))
        if not layout.readout.box.inside(layout.region("depth").box):
            named["readout"] = layout.readout.box
        return named

    def build(self, m):
        g = self.geometry
        free = {name: self.free(name, width) for name, width in (
            ("disparity", SWITCH_VALUE_BITS), ("rectification", SWITCH_VALUE_BITS),
            ("left_data", g.grey_bits), ("right_data", g.grey_bits))}
        dut = self.dut()
        ring_data = self.free("ring_data", len(dut.depth.data))
        rows_ready = self.free("rows_ready", len(dut.depth.rows_ready))
        m.submodules.raster = raster = SyncGenerator(self.timing)
        module = self.open(m, "dut", dut)
        # The block's ports (the one place to adapt when the signature changes).
        wiring.connect(m, raster, dut.timing)
        m.d.comb += [dut.settings.disparity.eq(free["disparity"]),
                     dut.settings.rectification.eq(free["rectification"]),
                     dut.left.port.data.eq(free["left_data"]), dut.right.port.data.eq(free["right_data"]),
                     dut.depth.data.eq(ring_data), dut.depth.rows_ready.eq(rows_ready)]
        ports = {"left": dut.left, "right": dut.right}

        pv = self.past_valid(m)
        for name in ("disparity", "rectification"):
            changed = pv & (free[name] != self.past(m, free[name], name=f"past_{name}"))
            self.assume(m, f"{name}_changes_only_after_frame_start",
                        ~changed | self.past(m, raster.frame_start, name=f"past_frame_start_{name}"))

        # Helper invariants: the raster stays in the frame (proven for the generator itself in harness_sync_gen).
        self.prove(m, "raster_x_in_line", raster.x < self.timing.h_total)
        self.prove(m, "raster_y_in_frame", raster.y < self.timing.v_total)
        inside = {name: (raster.x >= b.x0) & (raster.x < b.x1) & (raster.y >= b.y0) & (raster.y < b.y1)
                  for name, b in self.areas().items()}
        self.prove(m, "areas_never_overlap", sum(v.as_unsigned() for v in inside.values()) <= 1)

        n = ADDRESS_LATENCY
        was = {s: self.past_valid(m, n) & self.past(m, inside[f"region_{s}"], n, name=f"read_in_{s}")
               for s in ("left", "right", "disparity")}
        for side, port in ports.items():
            self.prove(m, f"{side}_port_address_in_buffer", port.port.addr < g.buf_depth)
            self.prove(m, f"{side}_port_one_reader_per_clock", ~(was[side] & was["disparity"]))
            self.prove(m, f"{side}_request_exactly_for_its_image_or_the_difference_map",
                       ~self.past_valid(m, n) | (port.request == (was[side] | was["disparity"])))
        for source in ("left", "right", "disparity"):
            self._scanner_tracks_raster(m, raster, self.layout.region(source),
                                        module.submodules[f"scan_{source}"])
        ring_size = self.out_rows * g.buf_width
        self.prove(m, "ring_address_in_ring", dut.depth.addr < ring_size)

        shown_second = self.layout.region("left").shrink * g.buf_width      # the second buffer row shown
        self.cover(m, "left_read_in_second_row", was["left"] & (ports["left"].port.addr == shown_second))
        self.cover(m, "difference_map_read_in_second_row",
                   was["disparity"] & ports["right"].request & (ports["right"].port.addr == g.buf_width))
        self.cover(m, "ring_read_in_second_row", self.past(m, inside["region_depth"], n, name="read_in_depth") &
                   (dut.depth.addr == g.buf_width))

    def _scanner_tracks_raster(self, m, raster, r, scanner):
        """Helper invariant: a region's running counters (``scan_<region>``) are the raster's progress through
        the region up to the pixel 2 clocks ago (flags 1 clock, counters 1 clock); 0 in vertical blanking. At
        1 / ``shrink`` size the buffer coordinates are ``shrink`` times the display ones."""
        x = self.past(m, raster.x, 2, name=f"scan_{r.source}_x")
        y = self.past(m, raster.y, 2, name=f"scan_{r.source}_y")
        in_rows = (y >= r.y0) & (y < r.y1)
        lines = Signal(range(r.y1 - r.y0 + 1), name=f"scan_{r.source}_lines_done")
        pixels = Signal(range(r.x1 - r.x0 + 1), name=f"scan_{r.source}_pixels_done")
        m.d.comb += [
            lines.eq(Mux(y < r.y0, 0, Mux(y >= r.y1, r.y1 - r.y0, y - r.y0 + (x >= r.x1 - 1)))),
            pixels.eq(Mux(in_rows & (x >= r.x0) & (x < r.x1 - 1), x - r.x0 + 1, 0)),
        ]
        blank = y >= self.timing.v_active
        lines, pixels = Mux(blank, 0, lines), Mux(blank, 0, pixels)
        yb, xb = lines // r.scale * r.shrink, pixels // r.scale * r.shrink
        row_start = yb * self.geometry.buf_width
        expected = ((scanner.yb == yb) & (scanner.xb == xb) & (scanner.addr == row_start + xb) &
                    (scanner.row_start == row_start))
        if r.scale > 1:
            expected &= (scanner.x_phase == pixels % r.scale) & (scanner.y_phase == lines % r.scale)
        self.prove(m, f"scan_{r.source}_tracks_raster", ~self.past_valid(m, 2) | expected)
