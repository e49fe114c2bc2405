"""DisparitySubtractor in the Amaranth simulator against golden.difference_levels (hypothesis), and the golden
model against hand-worked examples from the spec."""


import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from golden.disparity import difference_levels
from hdl.disparity import LATENCY, SETTLE_CLOCKS, DisparitySubtractor
from spec.board import CLOCKS
from spec.display import DIFF_THRESHOLDS, diff_thresholds
from spec.sensor import SensorGeometry
from sim.runners.amaranth import simulate
from sim.testbench.subtractor import set_pixel, subtractor_testbench



# --- the golden model against hand-worked examples ---------------------------------------------------------

def test_golden_hand_example():
    left = np.array([[0, 1, 2, 3],
                     [10, 11, 12, 13],
                     [20, 21, 22, 31]])
    right = np.array([[31, 0, 5, 0],
                      [0, 0, 0, 0],
                      [4, 4, 4, 4]])
    levels, no_data = difference_levels(left, right, 1, 1)
    # Right (x, y) meets left (x + 1, y + 1): |11-31|=20 -> 4, |12-0|=12 -> 3, |13-5|=8 -> 3, x=3: no data;
    # row 1: |21-0|=21 -> 4, |22-0|=22 -> 4, |31-0|=31 -> 4; row 2: y + 1 = 3 is outside: no data.
    assert no_data.tolist() == [[False, False, False, True], [False, False, False, True], [True] * 4]
    assert levels.tolist() == [[4, 3, 3, 0], [4, 4, 4, 0], [0, 0, 0, 0]]
    # Differences 0..31 against the default table 2/4/8/16 (spec: count of thresholds t with |L-R| >= t).
    ramp = np.arange(32)[None, :]
    levels, no_data = difference_levels(ramp, np.zeros_like(ramp), 0, 0)
    assert not no_data.any()
    assert levels[0].tolist() == [0, 0, 1, 1, 2, 2, 2, 2] + [3] * 8 + [4] * 16
    levels, _ = difference_levels(np.zeros_like(ramp), ramp, 0, 0, thresholds=(5,))
    assert levels[0].tolist() == [0] * 5 + [1] * 27


def test_golden_shift_edges():
    img = np.arange(12).reshape(3, 4)
    assert difference_levels(img, img, 4, 0)[1].all()        # x + 4 >= width everywhere
    assert difference_levels(img, img, 0, 3)[1].all()        # y + 3 >= height everywhere
    levels, no_data = difference_levels(img, img, 3, 2)      # only (0, 0) has data: left (3, 2) = 11
    assert np.argwhere(~no_data).tolist() == [[0, 0]]
    assert levels[0, 0] == 3                                  # |11 - 0| = 11 >= 2, 4, 8 but < 16
    with pytest.raises(ValueError):
        difference_levels(img, img, -1, 0)
    with pytest.raises(ValueError):
        difference_levels(img, img[:2], 0, 0)


# --- the RTL against the golden model -------------------------------------------------------------------

def run_subtractor(left, right, disparity, rectification, thresholds, pixels, grey_bits=5):
    """Drive ``pixels`` (a list of (x, y) or None for an idle clock) through the subtractor wired to two
    FrameBuffers preloaded with ``left``/``right`` (``grey_bits`` of grey); return [(level, no_data)] per pixel,
    checking the documented latency, ``next_valid`` / ``next_no_data`` (``out_valid`` / ``no_data`` a clock
    ahead), the right/left addresses and that the left address never leaves the buffer."""
    h, w = right.shape
    geometry = SensorGeometry(width=4 * w, height=4 * h, grey_bits=grey_bits)
    m, sub = subtractor_testbench(geometry, thresholds, left.ravel().tolist(), right.ravel().tolist())
    stream = list(pixels) + [None] * LATENCY
    out, ahead = [], []

    async def bench(ctx):
        ctx.set(sub.settings.disparity, disparity)
        ctx.set(sub.settings.rectification, rectification)
        await ctx.tick().repeat(SETTLE_CLOCKS)      # the documented settle time, no more
        for pixel in stream:
            set_pixel(ctx, sub, pixel, w)
            await ctx.tick()
            out.append((ctx.get(sub.out_valid), ctx.get(sub.level), ctx.get(sub.no_data),
                        ctx.get(sub.left.addr), ctx.get(sub.right.addr)))
            ahead.append((ctx.get(sub.next_valid), ctx.get(sub.next_no_data)))

    simulate(m, clocks={"sync": CLOCKS.PIXEL_HZ}, testbenches=[bench])
    for i in range(1, len(out)):                   # next_valid / next_no_data: out_valid / no_data a clock ahead
        assert ahead[i - 1] == (out[i][0], out[i][2]), f"next_valid / next_no_data at clock {i}"
    depth = w * h
    results = []
    for i, pixel in enumerate(stream):
        if i + LATENCY - 1 < len(out):
            valid = out[i + LATENCY - 1][0]
            assert valid == (pixel is not None), f"out_valid at clock {i} + {LATENCY}"
        if pixel is None:
            continue
        x, y = pixel
        _, _, _, left_addr, right_addr = out[i]                    # addresses one clock after the inputs
        assert right_addr == y * w + x
        if x + disparity < w and 0 <= y + rectification < h:
            assert left_addr == (y + rectification) * w + x + disparity
        else:
            assert left_addr == 0
        _, level, no_data, _, _ = out[i + LATENCY - 1]
        results.append((level, bool(no_data)))
    assert all(o[3] < depth for o in out), "left read address outside the buffer"
    return results


def check_against_golden(left, right, disparity, rectification, thresholds, pixels):
    levels, no_data = difference_levels(left, right, disparity, rectification, thresholds)
    got = run_subtractor(left, right, disparity, rectification, thresholds, pixels)
    want = [(int(levels[y, x]), bool(no_data[y, x])) for x, y in (p for p in pixels if p is not None)]
    assert got == want


def raster(w, h):
    return [(x, y) for y in range(h) for x in range(w)]


def test_real_pair_raster_default_thresholds():
    """The bundled pair captured at 16 x 12, raster order at one pixel per clock, several settings."""
    from golden.capture import capture_frame
    from golden.stereo_pair import load_default_pair
    from spec.sensor import SMALL_SENSOR
    left_rgb, right_rgb = load_default_pair(SMALL_SENSOR.width, SMALL_SENSOR.height)
    left, right = capture_frame(left_rgb, SMALL_SENSOR), capture_frame(right_rgb, SMALL_SENSOR)
    for disparity, rectification in [(0, 0), (3, 1), (15, 11), (16, 0), (0, 12), (22, 3), (127, 63)]:
        check_against_golden(left, right, disparity, rectification, DIFF_THRESHOLDS, raster(16, 12))


@pytest.mark.parametrize("rectification", [0, 1, -1, 11, -11, 12, -12, 63, -64])
def test_signed_rectification_boundaries(rectification):
    """Signed offsets at the boundaries of the 16 x 12 buffers: 0, +-1, +-(h - 1) (the last row with data),
    +-h (one past: every pixel no data) and the switch range's ends; the RTL equals the golden model and no
    read leaves the buffer (run_subtractor)."""
    rng = np.random.default_rng(27)
    left, right = rng.integers(0, 32, (12, 16)), rng.integers(0, 32, (12, 16))
    check_against_golden(left, right, 2, rectification, DIFF_THRESHOLDS, raster(16, 12))


def test_golden_negative_rectification_reads_higher_rows():
    """The golden model by hand: with r = -2 right row y meets left row y - 2; rows 0 and 1 have no data."""
    left = np.arange(5 * 4).reshape(5, 4) % 32
    levels, no_data = difference_levels(left, left, 0, -2, (1,))
    assert no_data[:2].all() and not no_data[2:].any()
    assert (levels[2:] == (left[:3] != left[2:]).astype(np.uint8)).all()
    levels, no_data = difference_levels(np.roll(left, -2, axis=0), left, 0, -2, (1,))
    assert (levels[2:] == 0).all()


@st.composite
def subtractor_cases(draw):
    w = draw(st.integers(1, 12))
    h = draw(st.integers(1, 8))
    images = st.lists(st.integers(0, 31), min_size=w * h, max_size=w * h)
    left = np.array(draw(images)).reshape(h, w)
    right = np.array(draw(images)).reshape(h, w)
    disparity = draw(st.one_of(st.integers(0, w + 1), st.integers(0, 127)))
    rectification = draw(st.one_of(st.integers(-h - 1, h + 1), st.integers(-64, 63)))
    thresholds = tuple(draw(st.lists(st.integers(0, 32), min_size=1, max_size=6)))
    coords = st.tuples(st.integers(0, w - 1), st.integers(0, h - 1))
    order = draw(st.sampled_from(["raster", "random"]))
    pixels = raster(w, h) if order == "raster" else draw(st.lists(coords, min_size=1, max_size=60))
    # Idle clocks sprinkled in: the pipeline must take any valid pattern.
    gaps = draw(st.lists(st.booleans(), min_size=len(pixels), max_size=len(pixels)))
    pixels = [q for p, gap in zip(pixels, gaps) for q in ([None, p] if gap else [p])]
    return left, right, disparity, rectification, thresholds, pixels


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(subtractor_cases())
def test_subtractor_random(case):
    check_against_golden(*case)


@pytest.mark.parametrize("grey_bits", [5, 8])
def test_thresholds_at_the_boundary(grey_bits):
    """Each threshold t of ``spec.display.diff_thresholds`` (2/4/8/16 for 5-bit grey, 16/32/64/128 for 8-bit)
    exactly (|L - R| = t: the level counts it) and one short (t - 1: it does not), L above R and below it, and
    the ends 0 and 2**bits - 1; levels by hand, the golden model and the RTL alike."""
    thresholds = diff_thresholds(grey_bits)
    top = (1 << grey_bits) - 1
    differences = [0] + [v for t in thresholds for v in (t - 1, t)] + [top]
    expected = [0] + [v for level in range(1, len(thresholds) + 1) for v in (level - 1, level)] + [len(thresholds)]
    zeros = np.zeros(len(differences), dtype=np.int64)
    left = np.array([differences, zeros])
    right = np.array([zeros, differences])                  # row 1: R above L
    levels, no_data = difference_levels(left, right, 0, 0, thresholds)
    assert not no_data.any() and levels.tolist() == [expected, expected]
    got = run_subtractor(left, right, 0, 0, thresholds, raster(len(differences), 2), grey_bits=grey_bits)
    assert got == [(level, False) for level in expected * 2]


def test_bad_thresholds():
    for bad in [(), (2, 40), (2.5,), ("2",)]:
        with pytest.raises(ValueError):
            DisparitySubtractor(thresholds=bad)


# --- the pictures (golden frames of the bundled pair) ----------------------------------------------------

def test_disparity_pictures(tmp_path):
    """The matched frame really is the motorcycle's disparity (within 1.5 px of Middlebury's ground truth) and
    the motorcycle fades there: many more of its pixels are black than at the wrong disparity. Each PNG is
    exactly the golden frame for the settings in its name."""
    import re

    from PIL import Image

    from golden.capture import capture_frame
    from golden.disparity import composite_frame
    from golden.stereo_pair import load_default_pair
    from spec.sensor import SENSOR
    from sim.analysis.disparity_pictures import crop_offset, find_settings, write_pictures

    assert crop_offset() == 37                       # golden/data/README.md: columns 37..703
    paths = write_pictures(tmp_path)
    assert [p.name.split("_")[2] for p in paths] == ["matched", "wrong"]
    left_rgb, right_rgb = load_default_pair(SENSOR.width, SENSOR.height)
    left, right = capture_frame(left_rgb, SENSOR), capture_frame(right_rgb, SENSOR)
    s = find_settings(left, right)
    assert abs(s.disparity - s.ground_truth_median) <= 1.5
    assert s.rectification == 0
    assert abs(s.wrong_disparity - s.disparity) >= 10
    assert s.black_right > s.black_wrong + 0.25
    for path in paths:
        d, r = map(int, re.search(r"_d(\d+)_r(\d+)\.png$", path.name).groups())
        with Image.open(path) as img:
            assert "Golden model frame" in img.text["Description"]
            frame = np.asarray(img.convert("RGB"))
        assert np.array_equal(frame, composite_frame(left, right, d, r))
    assert {(int(m[0]), int(m[1])) for m in (re.search(r"_d(\d+)_r(\d+)", p.name).groups() for p in paths)} == \
        {(s.disparity, s.rectification), (s.wrong_disparity, s.rectification)}


def test_the_800_build_settings_search_the_range_scaled_to_its_buffers():
    """``demo --build 800``'s settings: the disparity search covers 0..120 at the 800 x 600 buffers (the thesis's
    0..60 scaled with the width): on the bundled pair the motorcycle's disparity is found within 1.5 pixels of the
    Middlebury truth's median, and on a pair shifted by 90 pixels (beyond 60) the shift is found."""
    import numpy as np
    from sim.analysis.disparity_pictures import bundled_pair_settings, find_settings
    from spec.sensor import SENSOR_800
    s, left, right = bundled_pair_settings(SENSOR_800)
    assert abs(s.disparity - s.ground_truth_median) <= 1.5
    shifted = np.roll(right, 90, axis=1)             # left pixel (x + 90) = right pixel x
    assert find_settings(shifted, right, SENSOR_800).disparity == 90
