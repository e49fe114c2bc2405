"""The 800 x 600 build's screen (docs/display.md, "The 800 x 600 build's screen"): the layout
:meth:`spec.layout.DisplayLayout.full_maps` (camera images at half size, maps 1:1) against the numbers the spec
fixes and the layout checks (:func:`hdl.compositor.check_layout`), the golden frame at that layout
(:func:`golden.disparity.composite_frame`) on small synthetic 8-bit buffers, panel by panel against the golden
pieces, and the compositor RTL drawing it at a small size (block-RAM buffers; the frame store's build takes the
layout too: tests/test_system_ddr2.py runs half-size panels from it).
"""

import dataclasses

import numpy as np
import pytest

from golden.depth import depth_map
from golden.depth_display import centre_readout, depth_colours, depth_picture
from golden.disparity import composite_frame, difference_levels
from golden.segmentation import band_text, segment_picture
from hdl.centre_distance import readout_table
from hdl.compositor import check_layout, check_parameters, segmentation_fits
from hdl.region_scanner import RegionScanner
from hdl.segment_band import band_table
from hdl.stereo_display import check_display
from sim.runners.amaranth import simulate
from spec.depth import DEPTH, DEPTH_800, THREE_PATHS, DepthConfig
from spec.display import (BACKGROUND_RGB, CROSSHAIR_ARM, DIFF_LEVEL_GREY, DIFF_THRESHOLDS, NO_DATA_RGB, TEXT_RGB,
                          diff_thresholds)
from spec.layout import DisplayLayout
from spec.sensor import SENSOR, SENSOR_800, SMALL_SENSOR_800, SensorGeometry
from spec.video import CEA_1080P60, SMALL_TIMING, VideoTiming

from test_compositor import run_amaranth, run_cocotb_display     # tests/ (pytest puts a test's directory on the path)

#: The small averaging geometry (32 x 24 x 8-bit buffers) and a three-path engine for it.
SMALL_800 = SMALL_SENSOR_800
SMALL_800_DEPTH = DepthConfig(disparities=8, lanes=4, uniqueness=60, pixel_bits=8, paths=THREE_PATHS,
                              max_cost=180)


def _rgb(value):
    return np.array([(value >> s) & 0xFF for s in (16, 8, 0)], dtype=np.uint8)


def _bytes(rgb):
    rgb = np.asarray(rgb, dtype=np.int64)
    return np.stack([(rgb >> 16) & 0xFF, (rgb >> 8) & 0xFF, rgb & 0xFF], axis=-1).astype(np.uint8)


def test_full_maps_layout_1080p():
    """The 800 build's 1080p layout: the panels where today's are (images 400 x 300 at half size, maps 800 x 600
    1:1), the bar 4 rows per code for D = 128, labels 0.5 .. 5 m, the readout inside the depth map, the crosshair
    arm 16 buffer pixels (today's 16 screen pixels); it passes the layout checks, the frame store's window check and
    allows the segmentation view; today's layout is the same as before."""
    layout = DisplayLayout.full_maps(CEA_1080P60, SENSOR_800, DEPTH_800)
    assert DisplayLayout.default(CEA_1080P60, SENSOR_800, DEPTH_800) == layout
    assert DisplayLayout.default(CEA_1080P60, SENSOR, DEPTH) == DisplayLayout.centred(CEA_1080P60, SENSOR, DEPTH)
    boxes = {r.source: (r.box.x0, r.box.y0, r.box.x1, r.box.y1, r.scale, r.shrink) for r in layout.regions}
    assert boxes == {"left": (540, 70, 940, 370, 1, 2), "right": (980, 70, 1380, 370, 1, 2),
                     "disparity": (100, 410, 900, 1010, 1, 1), "depth": (940, 410, 1740, 1010, 1, 1)}
    today = DisplayLayout.centred(CEA_1080P60, SENSOR, DEPTH)
    assert [r.box for r in layout.regions] == [r.box for r in today.regions]
    assert (layout.bar.x0, layout.bar.y0, layout.bar.box.y1, layout.bar.step, layout.bar.codes) == (
        1748, 454, 966, 4, 128)
    assert [lab.text for lab in layout.labels] == ["0.5m", "1m", "2m", "3m", "5m"]
    # d(1 m) = 54.56 at scale 2: the tick centred on row 454 + int((127 - 54.56 + 0.5) * 4) = 745
    assert (layout.ticks[1].y0, layout.ticks[1].y1) == (744, 746)
    assert (layout.readout.x0, layout.readout.y0) == (940 + 403, 410 + 303)
    assert layout.readout.box.inside(layout.region("depth").box)
    assert layout.crosshair_arm == 2 * CROSSHAIR_ARM
    assert (layout.band.x0, layout.band.y0, layout.rectification.x0) == (100, 382, 940)
    regions = check_layout(layout, CEA_1080P60, SENSOR_800, DEPTH_800)
    assert regions["left"].shrink == 2 and segmentation_fits(layout)


def test_full_maps_layout_checks():
    """The layout checks refuse a half-size map, a half-size image of odd size, a shrink of 0 and a half-size image
    moved onto the other; the compositor's parameters take the layout (and 8-bit thresholds by default);
    ``full_maps`` refuses odd buffers and a screen too small."""
    layout = DisplayLayout.full_maps(CEA_1080P60, SENSOR_800, DEPTH_800)
    left, right, disp, depth = layout.regions
    bad = [
        dataclasses.replace(layout, regions=(left, right, disp, dataclasses.replace(depth, shrink=2))),
        dataclasses.replace(layout, regions=(left, right, dataclasses.replace(disp, shrink=2), depth)),
        dataclasses.replace(layout, regions=(dataclasses.replace(left, shrink=0), right, disp, depth)),
        dataclasses.replace(layout, regions=(dataclasses.replace(left, scale=2), right, disp, depth)),
        dataclasses.replace(layout, regions=(dataclasses.replace(left, x0=right.x0 - 399), right, disp, depth)),
    ]
    for each in bad:
        with pytest.raises(ValueError):
            check_layout(each, CEA_1080P60, SENSOR_800, DEPTH_800)
    odd = SensorGeometry(width=1602, height=1200, scale=2, grey_bits=8, downscale="average")     # 801 x 600
    with pytest.raises(ValueError, match="1/3"):             # 800 x 600 is not a whole number of 3 x 3 blocks
        check_layout(dataclasses.replace(layout, regions=(dataclasses.replace(left, shrink=3), right, disp, depth)),
                     CEA_1080P60, SENSOR_800, DEPTH_800)
    assert check_parameters(CEA_1080P60, SENSOR_800, layout, DEPTH_800, None, DIFF_LEVEL_GREY)[2] == (16, 32, 64, 128)
    with pytest.raises(ValueError, match="even"):
        DisplayLayout.full_maps(CEA_1080P60, odd, DEPTH_800)
    with pytest.raises(ValueError, match="do not fit"):
        DisplayLayout.full_maps(SMALL_TIMING, SENSOR_800, DEPTH_800)
    with pytest.raises(ValueError, match="do not fit"):
        DisplayLayout.centred(CEA_1080P60, SENSOR_800, DEPTH_800)


def test_diff_thresholds():
    """5-bit grey keeps DIFF_THRESHOLDS; 8-bit grey has them times 8; fewer than 5 bits is refused."""
    assert diff_thresholds(5) == DIFF_THRESHOLDS
    assert diff_thresholds(8) == (16, 32, 64, 128)
    with pytest.raises(ValueError):
        diff_thresholds(4)


def _small_pair():
    """Two 32 x 24 8-bit buffers: a textured right image and the left one, its texture moved 3 pixels (a plane
    at disparity 3), with a difference of exactly 15 and 16 (either side of the first 8-bit threshold) at two
    pixels of the difference map at d = 3."""
    rng = np.random.default_rng(5)
    right = rng.integers(0, 256, size=(24, 32), dtype=np.int64)
    left = np.roll(right, 3, axis=1)
    left[:, :3] = rng.integers(0, 256, size=(24, 3))
    right[5, 10], left[5, 13] = 100, 115                 # |L - R| = 15 at right pixel (10, 5): level 0
    right[6, 10], left[6, 13] = 100, 116                 # 16: level 1
    return left, right


@pytest.mark.parametrize("segment", [False, True], ids=["difference", "segmentation"])
def test_golden_frame_full_maps_small(segment):
    """The golden frame of a small 800-style build (8-bit averaged buffers, three paths) at the full-maps layout,
    panel by panel: the camera images are every second pixel of every second row, 1:1 grey; the difference map
    (8-bit thresholds; 15 -> level 0, 16 -> level 1) or the segmentation view and the depth map 1:1; the bar, the
    ticks and the text boxes inside their boxes; background everywhere else."""
    left, right = _small_pair()
    timing, g, cfg = SMALL_TIMING, SMALL_800, SMALL_800_DEPTH
    layout = DisplayLayout.default(timing, g, cfg)
    assert layout == DisplayLayout.full_maps(timing, g, cfg)
    check_layout(layout, timing, g, cfg)
    frame, codes, _ = composite_frame(left, right, 3, 0, timing, g, depth=cfg, details=True, segment=segment)
    assert (codes == depth_map(left, right, cfg)).all()
    drawn = np.zeros(frame.shape[:2], dtype=bool)

    def region(source):
        r = layout.region(source)
        drawn[r.y0:r.y1, r.x0:r.x1] = True
        return frame[r.y0:r.y1, r.x0:r.x1]

    for source, image in (("left", left), ("right", right)):
        half = region(source)
        assert half.shape[:2] == (12, 16)
        assert (half == image[::2, ::2, None]).all() and not (half == image[1::2, 1::2, None]).all()
    diff = region("disparity")
    if segment:
        assert (diff == _bytes(segment_picture(right, codes, 3, 8, cfg))).all()
    else:
        levels, no_data = difference_levels(left, right, 3, 0, (16, 32, 64, 128))
        assert (levels[5, 10], levels[6, 10]) == (0, 1)
        assert (diff[5, 10] == 0).all() and (diff[6, 10] == 64).all()
        grey = np.array(DIFF_LEVEL_GREY)[levels]
        assert (diff == _bytes(np.where(no_data, NO_DATA_RGB, grey * 0x010101))).all()
    assert (region("depth") == _bytes(depth_picture(codes, cfg, layout.crosshair_arm))).all()
    bar = layout.bar
    drawn[bar.y0:bar.box.y1, bar.x0:bar.box.x1] = True
    colours = depth_colours(cfg)
    for d in range(cfg.disparities):
        top = bar.y0 + (cfg.disparities - 1 - d) * bar.step
        assert (frame[top:top + bar.step, bar.x0:bar.box.x1] == _rgb(int(colours[16 * d]))).all()
    for box in [t for t in layout.ticks] + [b.box for b in layout.labels + (layout.readout,)]:
        area = frame[box.y0:box.y1, box.x0:box.x1]
        drawn[box.y0:box.y1, box.x0:box.x1] = True
        assert ((area == _rgb(TEXT_RGB)).all(axis=-1) | (area == _rgb(BACKGROUND_RGB)).all(axis=-1)).all()
    assert (frame[~drawn] == _rgb(BACKGROUND_RGB)).all()


@pytest.mark.slow
def test_golden_frame_800_1080p():
    """The 800 build's 1080p golden frame by hand, two flat 8-bit images (255 left, 0 right, but right (0, 0) =
    128 and right (1, 1) = 64): the half-size right image shows (0, 0) at (980, 70) and not (1, 1); the difference
    map at d = 10 1:1 from (100, 410), level 4 (255) but 3 (192) at right (0, 0) (|255 - 128| = 127 >= 64) and
    no data in the last 10 columns; the depth map from (940, 410), the crosshair's right arm at buffer
    (402..416, 300) = screen (1342..1356, 710); the bar's top band (d = 127) yellow at rows 454..457."""
    left = np.full((600, 800), 255, dtype=np.uint8)
    right = np.zeros((600, 800), dtype=np.uint8)
    right[0, 0], right[1, 1] = 128, 64
    frame = composite_frame(left, right, 10, 0, CEA_1080P60, SENSOR_800, depth=DEPTH_800)
    bg = _rgb(BACKGROUND_RGB)
    assert (frame[70, 540:940] == 255).all() and (frame[69, 540] == bg).all() and (frame[370, 540] == bg).all()
    assert (frame[70, 980] == 128).all() and (frame[71, 981] == 0).all() and (frame[369, 1379] == 0).all()
    assert (frame[70, 1380] == bg).all()
    assert (frame[410, 100] == 192).all() and (frame[410:1010, 101:890] == 255).all()
    assert (frame[410:1010, 890:900] == _rgb(NO_DATA_RGB)).all() and (frame[410:1010, 900] == bg).all()
    assert (frame[710, 1342:1357] == 255).all() and (frame[710, 1357] != 255).any()
    assert (frame[454:458, 1748:1764] == (253, 231, 37)).all() and (frame[453, 1748:1764] == bg).all()


# --- the compositor RTL at the full-maps layout (half-size camera images), small ------------------------------

#: A small mode with lines long enough for the engine to finish a row while the display shows it 1:1.
WIDE_TIMING = VideoTiming(h_active=112, h_front=4, h_sync=3, h_back=200, v_active=52, v_front=2, v_sync=2,
                          v_back=3, hsync_positive=True, vsync_positive=True)
#: The board's two-path engine (the RTL's) on 8-bit buffers.
SMALL_8BIT_DEPTH = DepthConfig(disparities=8, lanes=4, uniqueness=60, pixel_bits=8)


def test_region_scanner_stride():
    """A 6 x 4 picture at 1/2 size: the scanner gives the addresses and coordinates of pixels (0, 0), (2, 0),
    (4, 0), (0, 2), (2, 2), (4, 2) in display order; a stride that does not divide the picture, or with a scale, is
    refused."""
    dut = RegionScanner(6, 4, 1, stride=2)
    got = []

    async def bench(ctx):
        ctx.set(dut.clear, 1)
        await ctx.tick()
        ctx.set(dut.clear, 0)
        for _ in range(2):                               # two display lines of 3 pixels, a gap between
            for i in range(3):
                ctx.set(dut.active, 1)
                ctx.set(dut.eol, i == 2)
                got.append((ctx.get(dut.addr), ctx.get(dut.xb), ctx.get(dut.yb)))
                await ctx.tick()
            ctx.set(dut.active, 0)
            await ctx.tick().repeat(3)

    simulate(dut, clocks={"sync": 1e8}, testbenches=[bench])
    assert got == [(0, 0, 0), (2, 2, 0), (4, 4, 0), (12, 0, 2), (14, 2, 2), (16, 4, 2)]
    for bad in (dict(stride=4), dict(stride=2, scale_x=2), dict(stride=2, wrap=12)):
        kw = {"scale_x": 1, **bad}
        with pytest.raises(ValueError):
            RegionScanner(6, 4, kw.pop("scale_x"), **kw)


@pytest.mark.slow
@pytest.mark.parametrize("segment", [False, True], ids=["difference", "segmentation"])
def test_full_maps_compositor_amaranth(segment):
    """The compositor RTL (StereoDisplay on two block-RAM buffers, 32 x 24 x 8-bit, the two-path engine) draws the
    full-maps layout equal to the golden frame bit for bit, two frames (the switches moved in the first): the
    half-size camera images, the 8-bit difference map (or segmentation view), the depth map 1:1."""
    layout = DisplayLayout.full_maps(WIDE_TIMING, SMALL_800, SMALL_8BIT_DEPTH)
    run_amaranth(WIDE_TIMING, SMALL_800, [dict(line=20, column=30, disparity=3, rectification=1)], 2, layout,
                 segment=segment, config=SMALL_8BIT_DEPTH)


@pytest.mark.slow
@pytest.mark.parametrize("simulator", ["verilator", "icarus"])
def test_full_maps_compositor_cocotb(simulator, tmp_path):
    """The same on the exported Verilog (cocotb), the segmentation view on."""
    layout = DisplayLayout.full_maps(WIDE_TIMING, SMALL_800, SMALL_8BIT_DEPTH)
    run_cocotb_display(WIDE_TIMING, SMALL_800, [dict(line=20, column=30, disparity=3, rectification=1)], simulator,
                       tmp_path, layout, segment=True, config=SMALL_8BIT_DEPTH)


def test_full_maps_from_the_frame_store():
    """The frame store's windows read a half-size panel's rows with its step (every second row): both builds take
    the layout."""
    layout = DisplayLayout.full_maps(WIDE_TIMING, SMALL_800, SMALL_8BIT_DEPTH)
    assert check_display(WIDE_TIMING, SMALL_800, layout, config=SMALL_8BIT_DEPTH) == layout
    assert check_display(WIDE_TIMING, SMALL_800, layout, config=SMALL_8BIT_DEPTH, memory="ddr2") == layout


def test_readout_and_band_tables_800():
    """The centre readout and the band text at the 800 build's scale (Z = 54.552 m / d): the RTL's ROMs (exact
    fractions) equal the golden texts for every code 0..16 D and every register value; by hand: d = 54 -> 101.02
    -> " 101cm", d = 1 -> "5455cm"; the band around d = 60 is Z(62) = 0.880 m to Z(58) = 0.941 m."""
    table = readout_table(SENSOR_800, DEPTH_800)
    assert len(table) == DEPTH_800.invalid + 1
    for code, text in enumerate(table):
        assert centre_readout(np.full((12, 16), code), SENSOR_800, DEPTH_800) == (code, text)
    assert table[16 * 54] == " 101cm" and table[16] == "5455cm" and table[DEPTH_800.invalid] == "----cm"
    assert band_table(SENSOR_800) == [band_text(d, SENSOR_800) for d in range(128)]
    assert band_text(60, SENSOR_800) == " 0.88- 0.94m"
