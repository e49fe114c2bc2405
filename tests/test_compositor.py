"""The display path (SwitchControl + StereoDisplay: Compositor + DepthEngine + two ReadArbiters, on two
FrameBuffers) against golden.composite_frame, bit for bit, in the Amaranth simulator and in cocotb on Verilator and
Icarus; plus the golden compositor against hand-worked layout facts and the compositor's argument checks.

The buffers hold the bundled stereo pair (golden.stereo_pair) converted to 5-bit grey by the spec's rule
(:func:`grey_buffers`). Frames run back to back while the switches move in the middle of frames (inside the
disparity region, too): every frame must show the settings loaded at its own frame_start.
"""

import dataclasses

import numpy as np
import pytest
from amaranth import Cat, Fragment, Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from golden.capture import capture_frame
from golden.disparity import composite_frame
from golden.stereo_pair import load_default_pair
from hdl.compositor import LATENCY, Compositor
from hdl.stereo_display import StereoDisplay, check_engine_keeps_up
from board.export import export_verilog
from hdl.frame_buffer import FrameBuffer
from spec.board import CLOCKS
from spec.depth import DEPTH, SMALL_DEPTH
from spec.display import BACKGROUND_RGB, NO_DATA_RGB
from spec.layout import Box, ColourBar, DisplayLayout, Region, TextBox
from spec.sensor import SENSOR, SMALL_SENSOR
from spec.video import CEA_1080P60, SMALL_TIMING, VideoTiming
from hdl.switches import SWITCH_VALUE_BITS, SettingsSignature, SwitchControl
from hdl.video_bus import TimingSignature, VideoSignature
from sim.runners.amaranth import simulate
from sim.runners.cocotb import run_cocotb

from cocotb_compositor import check_stream, reference_raster, switch_events  # tests/cocotb (conftest.py)


CLOCK_PS = round(1e12 / CLOCKS.PIXEL_HZ)
#: Amaranth's Verilog compares wide signals with narrow constants; that lint warning is not fatal here.

#: Frames 1, 2, ...: where in the previous frame the switches move, and to what. SMALL_TIMING's disparity
#: region covers lines 17..40, columns 8..39 (the depth map columns 44..75), so lines 17-40 are changes in the
#: middle of both maps.
SMALL_SCHEDULE = [
    dict(line=25, column=30, disparity=22, rectification=3),    # the thesis's setting (all no-data at 16 x 12)
    dict(line=30, column=50, disparity=127, rectification=63),   # the maxima
    dict(line=30, column=50, disparity=2, rectification=-64),    # the negative end (switches 1000000)
    dict(line=30, column=50, disparity=1, rectification=-3),     # the left image read 3 rows higher
    dict(line=20, column=24, disparity=3, rectification=1),
    dict(line=40, column=55, disparity=15),                      # rectification must stay 1
    dict(line=50, column=2, rectification=11),                   # disparity must stay 15
    dict(line=0, column=3, disparity=5, rectification=2),
]


def grey_buffers(geometry):
    """The bundled pair as the camera path stores it: golden.capture.capture_frame (the spec's RGB565
    truncation, pixel (scale*i, scale*j), grey5 = (R5 + (G6 >> 1) + B5) // 3)."""
    left, right = load_default_pair(geometry.width, geometry.height)
    return capture_frame(left, geometry), capture_frame(right, geometry)


class DisplayTestbench(wiring.Component):
    """Test testbench, not part of the design: SwitchControl -> StereoDisplay <- two FrameBuffers, all in ``sync``;
    the buffers' write ports are brought out (``load_*``) so a cocotb testbench can fill them, or ``init_*`` preloads
    them. ``timing``, ``sw``, ``video`` and ``settings`` (the switch registers) are the blocks' own; ``video_word``
    is the video output packed as Cat(vsync, hsync, de, rgb) so a cocotb testbench reads one signal per clock (it
    checks it against the ``video`` ports themselves at intervals)."""

    def __init__(self, timing, geometry, *, layout=None, config=SMALL_DEPTH, init_left=(), init_right=()):
        self.timing_mode, self.geometry, self.layout, self.config = timing, geometry, layout, config
        self.init = (list(init_left), list(init_right))
        super().__init__({
            "timing": In(TimingSignature),
            "sw": In(SWITCH_VALUE_BITS + 1),
            "load_addr": In(geometry.addr_bits),
            "load_left": In(geometry.grey_bits),
            "load_right": In(geometry.grey_bits),
            "load_en": In(1),
            "video": Out(VideoSignature),
            "video_word": Out(27),
            "settings": Out(SettingsSignature),
            "segment": In(1),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.switches = switches = SwitchControl()
        m.submodules.compositor = comp = StereoDisplay(self.timing_mode, self.geometry, self.layout, config=self.config)
        m.submodules.left_buffer = left = FrameBuffer(self.geometry, init=self.init[0])
        m.submodules.right_buffer = right = FrameBuffer(self.geometry, init=self.init[1])
        wiring.connect(m, switches.settings, comp.settings, wiring.flipped(self.settings))
        wiring.connect(m, wiring.flipped(self.timing), comp.timing)
        wiring.connect(m, wiring.flipped(self.video), comp.video)
        wiring.connect(m, comp.left, left.read)
        wiring.connect(m, comp.right, right.read)
        m.d.comb += [
            switches.sw.eq(self.sw),
            comp.segment.eq(self.segment),
            switches.frame_start.eq(self.timing.frame_start),
            self.video_word.eq(Cat(comp.video.vsync, comp.video.hsync, comp.video.de, comp.video.rgb)),
        ]
        for fb, data in ((left, self.load_left), (right, self.load_right)):
            m.d.comb += [fb.write.addr.eq(self.load_addr), fb.write.data.eq(data), fb.write.en.eq(self.load_en)]
        return m


def expected_frames(left, right, settings, timing, geometry, layout=None, config=SMALL_DEPTH, segment=False):
    return np.stack([composite_frame(left, right, d, r, timing, geometry, layout, depth=config, segment=segment)
                     for d, r in settings])


# --- the golden compositor on its own ----------------------------------------------------------------------

def test_golden_layout_1080p():
    """Spot checks of the golden frame against the layout the spec fixes (spec.layout.DisplayLayout docstring)
    and the depth display's colours worked by hand."""
    left = np.full((300, 400), 31, dtype=np.uint8)
    right = np.zeros((300, 400), dtype=np.uint8)
    right[0, 0] = 16
    frame, codes, text = composite_frame(left, right, 10, 0, details=True)
    assert frame.shape == (1080, 1920, 3)
    bg = [(BACKGROUND_RGB >> s) & 0xFF for s in (16, 8, 0)]
    nd = [(NO_DATA_RGB >> s) & 0xFF for s in (16, 8, 0)]
    assert (frame[0, 0] == bg).all() and (frame[69, 540] == bg).all() and (frame[370, 540] == bg).all()
    assert (frame[70, 540:940] == 255).all() and (frame[369, 939] == 255).all()      # left: 31 -> 0xFF
    assert (frame[70, 940] == bg).all() and (frame[70, 979] == bg).all()
    assert (frame[70, 980] == 0x84).all()                                           # right (0, 0): 16 -> 0x84
    assert (frame[70, 981:1380] == 0).all()
    # Disparity map at 2x from (100, 410): |31 - 0| = 31 -> level 4 -> 255; the last 10 buffer columns have
    # no left pixel (x + 10 >= 400) -> 20 display columns of NO_DATA_RGB; right (0, 0) = 16: |31 - 16| = 15
    # -> level 3 -> 192, shown as a 2 x 2 block.
    assert (frame[410:412, 100:102] == 192).all()
    disparity_area = frame[410:1010, 100:880].copy()
    disparity_area[:2, :2] = 255
    assert (disparity_area == 255).all()
    assert (frame[410:1010, 880:900] == nd).all()
    assert (frame[409, 100:900] == bg).all() and (frame[1010, 100:900] == bg).all()
    assert (frame[410:1010, 99] == bg).all() and (frame[410:1010, 900] == bg).all()
    # Depth map at 2x from (940, 410): two flat images match at disparity 0 away from right (0, 0): viridis's
    # first anchor (68, 1, 84); the crosshair's right arm at buffer (202..208, 150) = display (1344..1357,
    # 710..711); no distance for d = 0: "----cm" at (1346, 716), the dashes on its font row 3 (display 722).
    assert (codes[5:, 5:] == 0).all() and text == "----cm"
    assert (frame[420:700, 960:1300] == (68, 1, 84)).all()
    assert (frame[710:712, 1344:1358] == 255).all() and (frame[710:712, 1342:1344] == (68, 1, 84)).all()
    assert (frame[722:724, 1346:1356] == 255).all() and (frame[720:722, 1346:1356] == bg).all()
    # Colour bar [1748, 1764) from row 422, 9 rows per code: code 63 (yellow, the last anchor) on top, code 0
    # at the bottom; the 1 m tick (2 rows) centred on the band of d = 27.28: row 422 + int((63 - 27.28 + 0.5) * 9)
    # = 748.
    assert (frame[422:431, 1748:1764] == (253, 231, 37)).all() and (frame[989:998, 1748:1764] == (68, 1, 84)).all()
    assert (frame[421, 1748:1764] == bg).all() and (frame[998, 1748:1764] == bg).all()
    assert (frame[747:749, 1764:1770] == 255).all() and (frame[746, 1764:1770] == bg).all()
    assert (frame[749, 1764:1770] == bg).all()


def test_segmentation_golden_1080p():
    """The segmentation view at the board's size, by hand: two flat images (grey 31) match at disparity 0 (code 0
    everywhere): with the band around d = 1 (codes 0..48) the view is 0xFFFFFF, around d = 10 (codes 128..192) it
    is dimmed to 0xFF >> 2 = 0x3F; the band text " 2.27- 3.41m" (Z(12) = 2.273 m, Z(8) = 3.410 m) fills
    [100, 244) x [382, 398), its first cell a space; with the segmentation off that box is background."""
    flat = np.full((300, 400), 31, dtype=np.uint8)
    near, codes, _ = composite_frame(flat, flat, 1, 0, details=True, segment=True)
    far = composite_frame(flat, flat, 10, 0, segment=True)
    off = composite_frame(flat, flat, 10, 0)
    bg = [(BACKGROUND_RGB >> s) & 0xFF for s in (16, 8, 0)]
    assert (codes == 0).all()
    assert (near[410:1010, 100:900] == 255).all() and (far[410:1010, 100:900] == 0x3F).all()
    assert (off[410:1010, 100:880] == 0).all()                  # the difference map: |31 - 31| = 0 -> level 0
    assert (off[370:410, 100:900] == bg).all() and (far[382:398, 100:112] == bg).all()
    assert (far[381, 100:244] == bg).all() and (far[398, 100:244] == bg).all()
    lit = (far[382:398, 112:244] == 255).all(axis=-1)
    assert lit.any() and ((far[382:398, 112:244] == bg).all(axis=-1) | lit).all()
    assert (near[382:398, 112:244] != far[382:398, 112:244]).any()      # another band, another text
    outside = far.copy()
    outside[410:1010, 100:900] = off[410:1010, 100:900]
    outside[382:398, 100:244] = off[382:398, 100:244]
    assert (outside == off).all()


def test_engine_keeps_up_check():
    """The depth map may not start before the engine's first row can be ready, nor be shown faster than the
    engine computes rows; the default layouts pass."""
    small = DisplayLayout.centred(SMALL_TIMING, SMALL_SENSOR, SMALL_DEPTH)
    left, right, disp, depth = small.regions
    check_engine_keeps_up(SMALL_TIMING, small, SMALL_SENSOR, SMALL_DEPTH)
    check_engine_keeps_up(CEA_1080P60, DisplayLayout.centred(CEA_1080P60, SENSOR), SENSOR, DEPTH)
    early = dataclasses.replace(small, regions=(left, right, disp, dataclasses.replace(depth, y0=4)))
    fast = dataclasses.replace(small, regions=(left, right, disp, dataclasses.replace(depth, scale=1)))
    for layout in (early, fast):
        with pytest.raises(ValueError):
            check_engine_keeps_up(SMALL_TIMING, layout, SMALL_SENSOR, SMALL_DEPTH)


def test_compositor_argument_checks():
    small = DisplayLayout.centred(SMALL_TIMING, SMALL_SENSOR, SMALL_DEPTH)
    left, right, disp, depth = small.regions
    bad = [
        dataclasses.replace(small, regions=(left, dataclasses.replace(right, x0=left.x0 + 1), disp, depth)),
        dataclasses.replace(small, regions=(left, right, dataclasses.replace(disp, x0=100), depth)),
        dataclasses.replace(small, regions=(left, right, disp)),
        dataclasses.replace(small, regions=(left, right, Region("disparity", 0, 20, 2, 8, 6), depth)),
        dataclasses.replace(small, bar=dataclasses.replace(small.bar, x0=depth.x1 - 1)),       # over the map
        dataclasses.replace(small, bar=dataclasses.replace(small.bar, codes=4)),
        dataclasses.replace(small, readout=dataclasses.replace(small.readout, y0=depth.y0 + 2)),   # too early
        dataclasses.replace(small, readout=dataclasses.replace(small.readout, x0=disp.x0, y0=depth.y0 + 16)),
        dataclasses.replace(small, crosshair_arm=7),
        dataclasses.replace(small, labels=(dataclasses.replace(small.labels[0], x0=small.ticks[0].x0),)),
    ]
    at_origin = (dataclasses.replace(left, x0=40, y0=0), dataclasses.replace(right, x0=60, y0=0),
                 dataclasses.replace(disp, x0=1, y0=0), depth)          # 1 pixel in: switches not settled
    bad.append(dataclasses.replace(small, regions=at_origin))
    for layout in bad:
        with pytest.raises(ValueError):
            Compositor(SMALL_TIMING, SMALL_SENSOR, layout, config=SMALL_DEPTH)
    two_in = dataclasses.replace(small, regions=at_origin[:2] + (dataclasses.replace(disp, x0=2, y0=0), depth))
    Fragment.get(Compositor(SMALL_TIMING, SMALL_SENSOR, two_in, config=SMALL_DEPTH), None)   # 2 pixels in is enough
    with pytest.raises(ValueError):
        Compositor(SMALL_TIMING, SMALL_SENSOR, config=SMALL_DEPTH, thresholds=(2, 4), level_grey=(0, 255))


# --- the RTL against the golden model ----------------------------------------------------------------------

def run_amaranth(timing, geometry, schedule, n_frames, layout=None, segment=False, config=SMALL_DEPTH):
    left, right = grey_buffers(geometry)
    dut = DisplayTestbench(timing, geometry, layout=layout, config=config, init_left=left.ravel().tolist(),
                         init_right=right.ravel().tolist())
    raster = reference_raster(timing)
    events, settings = switch_events(schedule, timing)
    cpf = timing.clocks_per_frame
    total = n_frames * cpf + LATENCY
    names = ("x", "y", "de", "hsync", "vsync", "frame_start")
    ports = [getattr(dut.timing, n) for n in names]
    columns = [raster[n].tolist() for n in names]
    out = {k: np.zeros(total, dtype=np.int64) for k in ("rgb", "de", "hsync", "vsync")}
    registers = []

    async def bench(ctx):
        ctx.set(dut.segment, segment)
        for port, column in zip(ports, columns):      # the end of a previous frame's blanking
            ctx.set(port, column[-1])
        await ctx.tick().repeat(LATENCY + 2)
        previous = [None] * len(ports)
        for c in range(total):
            out["rgb"][c] = ctx.get(dut.video.rgb)
            out["de"][c] = ctx.get(dut.video.de)
            out["hsync"][c] = ctx.get(dut.video.hsync)
            out["vsync"][c] = ctx.get(dut.video.vsync)
            i = c % cpf
            if i == 1 and c < n_frames * cpf:
                registers.append((ctx.get(dut.settings.disparity), ctx.get(dut.settings.rectification)))
            for j, port in enumerate(ports):
                if columns[j][i] != previous[j]:
                    ctx.set(port, columns[j][i])
                    previous[j] = columns[j][i]
            if c in events:
                ctx.set(dut.sw, events[c])
            await ctx.tick()

    simulate(dut, clocks={"sync": CLOCKS.PIXEL_HZ}, testbenches=[bench])
    assert registers == settings[:n_frames]
    check_stream(timing, LATENCY, n_frames, out,
                 expected_frames(left, right, settings[:n_frames], timing, geometry, layout, config, segment=segment))


def test_display_path_amaranth():
    """The last four switch changes of :data:`SMALL_SCHEDULE` in Amaranth's simulator (both registers in the
    middle of the maps, one register moved while the other must keep its value, both at a frame's first line):
    five frames. The whole schedule runs on Verilator and Icarus (:func:`test_display_path_cocotb`) and, slow,
    here (:func:`test_display_path_amaranth_whole_schedule`)."""
    run_amaranth(SMALL_TIMING, SMALL_SENSOR, SMALL_SCHEDULE[-4:], 5)


@pytest.mark.slow
def test_display_path_amaranth_whole_schedule():
    run_amaranth(SMALL_TIMING, SMALL_SENSOR, SMALL_SCHEDULE, len(SMALL_SCHEDULE) + 1)


def test_display_path_other_layout_amaranth():
    """Scales 1, 2 and 3; the disparity map starting 2 pixels into the raster (the earliest the constructor
    allows: the switch registers settle just in time, SETTLE_CLOCKS); the right image touching the active area's
    right edge; the readout away from the depth map, a bar of 1-pixel bands; the depth map on the first line
    the engine's check allows (12: 5 rows fetched in 12-clock blankings, 3 passes); negative sync polarities."""
    timing = VideoTiming(h_active=140, h_front=3, h_sync=4, h_back=5, v_active=60, v_front=1, v_sync=2,
                         v_back=2, hsync_positive=False, vsync_positive=False)
    w, h = SMALL_SENSOR.buf_width, SMALL_SENSOR.buf_height
    layout = DisplayLayout(
        regions=(Region("disparity", 2, 0, 3, w, h), Region("left", 52, 0, 1, w, h),
                 Region("right", 140 - 2 * w, 24, 2, w, h), Region("depth", 70, 12, 2, w, h)),
        bar=ColourBar(104, 12, 3, 1, SMALL_DEPTH.disparities), ticks=(Box(107, 14, 1, 1),),
        labels=(TextBox("5m", 52, 40, 1),), readout=TextBox("0000cm", 52, 50, 1), crosshair_arm=3)
    schedule = [dict(line=30, column=60, disparity=3, rectification=2),
                dict(line=10, column=20, disparity=1, rectification=0)]
    run_amaranth(timing, SMALL_SENSOR, schedule, 3, layout)


#: A small mode with room for the band text above the difference map (a 9-line gap).
SEGMENT_TIMING = VideoTiming(h_active=112, h_front=4, h_sync=3, h_back=5, v_active=60, v_front=2, v_sync=2,
                             v_back=3, hsync_positive=True, vsync_positive=True)
SEGMENT_SCHEDULE = [dict(line=30, column=50, disparity=3, rectification=0),
                    dict(line=20, column=24, disparity=6, rectification=1),
                    dict(line=40, column=10, disparity=127, rectification=-2)]


def test_segmentation_amaranth():
    """The segmentation view in the difference map's place and the band text above it, RTL = golden bit for bit,
    over frames whose disparity register (the band's centre) changes in the middle of the previous frame."""
    layout = DisplayLayout.centred(SEGMENT_TIMING, SMALL_SENSOR, SMALL_DEPTH, gap=9)
    assert layout.band is not None
    run_amaranth(SEGMENT_TIMING, SMALL_SENSOR, SEGMENT_SCHEDULE, len(SEGMENT_SCHEDULE) + 1, layout, segment=True)


def test_segmentation_off_is_the_old_frame():
    """With the segmentation off the band box is all background: the default frame is the frame without it."""
    left, right = grey_buffers(SMALL_SENSOR)
    layout = DisplayLayout.centred(SEGMENT_TIMING, SMALL_SENSOR, SMALL_DEPTH, gap=9)
    old = dataclasses.replace(layout, band=None)
    on, off, without = (composite_frame(left, right, 3, 0, SEGMENT_TIMING, SMALL_SENSOR, lay, depth=SMALL_DEPTH,
                                        segment=seg) for lay, seg in ((layout, True), (layout, False), (old, False)))
    assert (off == without).all() and not (on == off).all()
    with pytest.raises(ValueError, match="segmentation view needs"):
        other = DisplayLayout(regions=tuple(dataclasses.replace(r, y0=r.y0 + 1) if r.source == "disparity" else r
                                            for r in layout.regions), bar=layout.bar, readout=layout.readout)
        composite_frame(left, right, 3, 0, SEGMENT_TIMING, SMALL_SENSOR, other, depth=SMALL_DEPTH, segment=True)


def run_cocotb_display(timing, geometry, schedule, simulator, tmp_path, layout=None, segment=False, config=None):
    left, right = grey_buffers(geometry)
    events, settings = switch_events(schedule, timing)
    config = config or (DEPTH if geometry == SENSOR else SMALL_DEPTH)
    data = tmp_path / "display.npz"
    np.savez(data, left=left, right=right,
             expected=expected_frames(left, right, settings, timing, geometry, layout, config, segment))
    verilog = export_verilog(DisplayTestbench(timing, geometry, layout=layout, config=config), "display_testbench")
    run_cocotb(verilog, name="display_testbench", test_module="cocotb_compositor",
               simulator=simulator,
               params=dict(timing=dataclasses.asdict(timing), latency=LATENCY, data=str(data),
                           schedule=schedule, clock_ps=CLOCK_PS, segment=segment))


@pytest.mark.parametrize("simulator", [pytest.param("verilator", marks=pytest.mark.slow), "icarus"])
def test_segmentation_cocotb(simulator, tmp_path):
    """The segmentation view and its band text on the exported Verilog (Icarus; Verilator in the slow set: its
    build is most of the test, and the same compositor runs on Verilator in :func:`test_display_path_cocotb`)."""
    layout = DisplayLayout.centred(SEGMENT_TIMING, SMALL_SENSOR, SMALL_DEPTH, gap=9)
    run_cocotb_display(SEGMENT_TIMING, SMALL_SENSOR, SEGMENT_SCHEDULE, simulator, tmp_path, layout, segment=True)


@pytest.mark.parametrize("simulator", ["verilator", pytest.param("icarus", marks=pytest.mark.slow)])
def test_display_path_cocotb(simulator, tmp_path):
    """The whole :data:`SMALL_SCHEDULE` on the exported Verilog (Verilator; Icarus in the slow set: the default
    suite runs the compositor on Icarus in :func:`test_segmentation_cocotb`)."""
    run_cocotb_display(SMALL_TIMING, SMALL_SENSOR, SMALL_SCHEDULE, simulator, tmp_path)


@pytest.mark.slow
def test_display_path_1080p_cocotb(tmp_path):
    """The full 1920 x 1080 frame from 400 x 300 buffers (the board's engine, D = 64) on Verilator: (0, 0) from reset, then the thesis's
    (22, 3) set in the middle of the disparity map of frame 0, then the maximum (127, 63)."""
    schedule = [dict(line=500, column=700, disparity=22, rectification=3),
                dict(line=900, column=1000, disparity=127, rectification=63)]
    run_cocotb_display(CEA_1080P60, SENSOR, schedule, "verilator", tmp_path)
