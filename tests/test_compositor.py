"""The display path (SwitchControl + Compositor + two FrameBuffers) against golden.composite_frame, bit for bit,
in the Amaranth simulator and in cocotb on Verilator and Icarus; plus the golden compositor against hand-worked
layout facts and the compositor's argument checks.

The buffers hold the bundled stereo pair (golden.stereo_pair) converted to 5-bit grey by the spec's rule
(:func:`grey_buffers`). Frames run back to back while the switches move in the middle of frames (inside the
disparity region, too): every frame must show the settings loaded at its own frame_start.
"""

import dataclasses
import sys

import numpy as np
import pytest
from amaranth import Cat, Fragment, Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from golden.capture import capture_frame
from golden.disparity import composite_frame
from golden.stereo_pair import load_default_pair
from hdl.compositor import LATENCY, Compositor
from hdl.export import export_verilog
from hdl.forward import forward
from hdl.frame_buffer import FrameBuffer
from hdl.params import (BACKGROUND_RGB, CEA_1080P60, CLOCKS, NO_DATA_RGB, SENSOR, SMALL_SENSOR, SMALL_TIMING,
                        DisplayLayout, Region, VideoTiming)
from hdl.switches import SWITCH_VALUE_BITS, SettingsSignature, SwitchControl
from hdl.video_bus import TimingSignature, VideoSignature
from sim.amaranth_sim import simulate
from sim.cocotb_runner import COCOTB_TEST_DIR, run_cocotb

sys.path.insert(0, str(COCOTB_TEST_DIR))
from cocotb_compositor import check_stream, reference_raster, switch_events  # noqa: E402


CLOCK_PS = round(1e12 / CLOCKS.PIXEL_HZ)
#: Amaranth's Verilog compares wide signals with narrow constants; that lint warning is not fatal here.

#: Frames 1, 2, ...: where in the previous frame the switches move, and to what. SMALL_TIMING's disparity
#: region covers lines 20..43, columns 24..55, so lines 20-43 are changes in the middle of the disparity map.
SMALL_SCHEDULE = [
    dict(line=25, column=30, disparity=22, rectification=3),    # the thesis's setting (all no-data at 16 x 12)
    dict(line=30, column=40, disparity=127, rectification=127),  # the maximum
    dict(line=20, column=24, disparity=3, rectification=1),
    dict(line=43, column=55, disparity=15),                      # rectification must stay 1
    dict(line=50, column=2, rectification=11),                   # disparity must stay 15
    dict(line=0, column=3, disparity=5, rectification=2),
]


def grey_buffers(geometry):
    """The bundled pair as the camera path stores it: golden.capture.capture_frame (the spec's RGB565
    truncation, pixel (scale*i, scale*j), grey5 = (R5 + (G6 >> 1) + B5) // 3)."""
    left, right = load_default_pair(geometry.width, geometry.height)
    return capture_frame(left, geometry), capture_frame(right, geometry)


class DisplayHarness(wiring.Component):
    """Test harness, not part of the design: SwitchControl -> Compositor <- two FrameBuffers, all in ``sync``;
    the buffers' write ports are brought out (``load_*``) so a cocotb bench can fill them, or ``init_*`` preloads
    them. ``timing``, ``sw``, ``video`` and ``settings`` (the switch registers) are the blocks' own; ``video_word``
    is the video output packed as Cat(vsync, hsync, de, rgb) so a cocotb bench reads one signal per clock (it
    checks it against the ``video`` ports themselves at intervals)."""

    def __init__(self, timing, geometry, *, layout=None, init_left=(), init_right=()):
        self.switches = SwitchControl()
        self.compositor = Compositor(timing, geometry, layout)
        self.buffers = (FrameBuffer(geometry, init=list(init_left)), FrameBuffer(geometry, init=list(init_right)))
        super().__init__({
            "timing": In(TimingSignature),
            "sw": In(SWITCH_VALUE_BITS + 1),
            "load_addr": In(geometry.addr_bits),
            "load_left": In(geometry.gray_bits),
            "load_right": In(geometry.gray_bits),
            "load_en": In(1),
            "video": Out(VideoSignature),
            "video_word": Out(27),
            "settings": Out(SettingsSignature),
        })
        for name, obj in (("timing", self.compositor.timing), ("video", self.compositor.video),
                          ("sw", self.switches.sw), ("settings", self.switches.settings)):
            forward(self, name, obj)

    def elaborate(self, platform):
        m = Module()
        m.submodules.switches = switches = self.switches
        m.submodules.compositor = comp = self.compositor
        m.submodules.left_buffer = left = self.buffers[0]
        m.submodules.right_buffer = right = self.buffers[1]
        wiring.connect(m, switches.settings, comp.settings)
        wiring.connect(m, comp.left, left.read)
        wiring.connect(m, comp.right, right.read)
        m.d.comb += [
            switches.frame_start.eq(self.timing.frame_start),
            self.video_word.eq(Cat(comp.video.vsync, comp.video.hsync, comp.video.de, comp.video.rgb)),
        ]
        for fb, data in ((left, self.load_left), (right, self.load_right)):
            m.d.comb += [fb.write.addr.eq(self.load_addr), fb.write.data.eq(data), fb.write.en.eq(self.load_en)]
        return m


def expected_frames(left, right, settings, timing, geometry, layout=None):
    return np.stack([composite_frame(left, right, d, r, timing, geometry, layout) for d, r in settings])


# --- the golden compositor on its own ----------------------------------------------------------------------

def test_golden_layout_1080p():
    """Spot checks of the golden frame against the layout the spec fixes (hdl.params.DisplayLayout docstring)."""
    left = np.full((300, 400), 31, dtype=np.uint8)
    right = np.zeros((300, 400), dtype=np.uint8)
    right[0, 0] = 16
    frame = composite_frame(left, right, 10, 0)
    assert frame.shape == (1080, 1920, 3)
    bg = [(BACKGROUND_RGB >> s) & 0xFF for s in (16, 8, 0)]
    nd = [(NO_DATA_RGB >> s) & 0xFF for s in (16, 8, 0)]
    assert (frame[0, 0] == bg).all() and (frame[69, 540] == bg).all() and (frame[370, 540] == bg).all()
    assert (frame[70, 540:940] == 255).all() and (frame[369, 939] == 255).all()      # left: 31 -> 0xFF
    assert (frame[70, 940] == bg).all() and (frame[70, 979] == bg).all()
    assert (frame[70, 980] == 0x84).all()                                           # right (0, 0): 16 -> 0x84
    assert (frame[70, 981:1380] == 0).all()
    # Disparity map at 2x from (560, 410): |31 - 0| = 31 -> level 4 -> 255; the last 10 buffer columns have
    # no left pixel (x + 10 >= 400) -> 20 display columns of NO_DATA_RGB; right (0, 0) = 16: |31 - 16| = 15
    # -> level 3 -> 192, shown as a 2 x 2 block.
    assert (frame[410:412, 560:562] == 192).all()
    disparity_area = frame[410:1010, 560:1340].copy()
    disparity_area[:2, :2] = 255
    assert (disparity_area == 255).all()
    assert (frame[410:1010, 1340:1360] == nd).all()
    assert (frame[409, 560:1360] == bg).all() and (frame[1010, 560:1360] == bg).all()
    assert (frame[410:1010, 559] == bg).all() and (frame[410:1010, 1360] == bg).all()


def test_compositor_argument_checks():
    small = DisplayLayout.centred(SMALL_TIMING, SMALL_SENSOR)
    left, right, disp = small.regions
    overlapping = DisplayLayout((left, dataclasses.replace(right, x0=left.x0 + 1), disp))
    at_origin = DisplayLayout((dataclasses.replace(left, x0=40, y0=0), dataclasses.replace(right, x0=40, y0=20),
                               dataclasses.replace(disp, x0=1, y0=0)))   # 1 pixel in: switches not settled
    outside = DisplayLayout((left, right, dataclasses.replace(disp, x0=60)))
    missing = DisplayLayout((left, right))
    wrong_size = DisplayLayout((left, right, Region("disparity", 0, 20, 2, 8, 6)))
    for layout in (overlapping, at_origin, outside, missing, wrong_size):
        with pytest.raises(ValueError):
            Compositor(SMALL_TIMING, SMALL_SENSOR, layout)
    two_in = DisplayLayout((at_origin.regions[0], at_origin.regions[1],
                            dataclasses.replace(disp, x0=2, y0=0)))
    Fragment.get(Compositor(SMALL_TIMING, SMALL_SENSOR, two_in), None)     # 2 pixels in is enough
    with pytest.raises(ValueError):
        Compositor(SMALL_TIMING, SMALL_SENSOR, thresholds=(2, 4), level_grey=(0, 255))


# --- the RTL against the golden model ----------------------------------------------------------------------

def run_amaranth(timing, geometry, schedule, n_frames, layout=None):
    left, right = grey_buffers(geometry)
    dut = DisplayHarness(timing, geometry, layout=layout, init_left=left.ravel().tolist(),
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
                 expected_frames(left, right, settings[:n_frames], timing, geometry, layout))


def test_display_path_amaranth():
    run_amaranth(SMALL_TIMING, SMALL_SENSOR, SMALL_SCHEDULE, len(SMALL_SCHEDULE) + 1)


def test_display_path_other_layout_amaranth():
    """Scales 1, 2 and 3; the disparity map starting 2 pixels into the raster (the earliest the constructor
    allows: the switch registers settle just in time, SETTLE_CLOCKS); the right image touching the active area's
    right edge; negative sync polarities."""
    timing = VideoTiming(h_active=100, h_front=3, h_sync=4, h_back=5, v_active=60, v_front=1, v_sync=2,
                         v_back=2, hsync_positive=False, vsync_positive=False)
    w, h = SMALL_SENSOR.buf_width, SMALL_SENSOR.buf_height
    layout = DisplayLayout((Region("disparity", 2, 0, 3, w, h), Region("left", 52, 0, 1, w, h),
                            Region("right", 100 - 2 * w, 24, 2, w, h)))
    schedule = [dict(line=30, column=60, disparity=3, rectification=2),
                dict(line=10, column=20, disparity=1, rectification=0)]
    run_amaranth(timing, SMALL_SENSOR, schedule, 3, layout)


def run_cocotb_display(timing, geometry, schedule, simulator, tmp_path):
    left, right = grey_buffers(geometry)
    events, settings = switch_events(schedule, timing)
    data = tmp_path / "display.npz"
    np.savez(data, left=left, right=right,
             expected=expected_frames(left, right, settings, timing, geometry))
    verilog = export_verilog(DisplayHarness(timing, geometry), "display_harness")   # compact buffer init
    run_cocotb(verilog, name="display_harness", test_module="cocotb_compositor",
               simulator=simulator,
               params=dict(timing=dataclasses.asdict(timing), latency=LATENCY, data=str(data),
                           schedule=schedule, clock_ps=CLOCK_PS))


def test_display_path_cocotb(simulator, tmp_path):
    run_cocotb_display(SMALL_TIMING, SMALL_SENSOR, SMALL_SCHEDULE, simulator, tmp_path)


@pytest.mark.slow
def test_display_path_1080p_cocotb(tmp_path):
    """The full 1920 x 1080 frame from 400 x 300 buffers on Verilator: (0, 0) from reset, then the thesis's
    (22, 3) set in the middle of the disparity map of frame 0, then the maximum (127, 127)."""
    schedule = [dict(line=500, column=700, disparity=22, rectification=3),
                dict(line=900, column=1000, disparity=127, rectification=127)]
    run_cocotb_display(CEA_1080P60, SENSOR, schedule, "verilator", tmp_path)
