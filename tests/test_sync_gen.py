"""SyncGenerator in Amaranth's simulator against a reference raster written from the timing definition.

The reference (:func:`reference_raster`) derives every output from the clock index alone: position in the
frame, then de/hsync/vsync from the CEA-861 line layout. The RTL instead counts and registers the *next*
position. Every clock of whole frames is compared, for the small mode, a negative-polarity mode and random
modes (hypothesis); the 1080p counts are checked against the CEA-861 numbers written out literally.
"""

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from spec.video import CEA_1080P60, SMALL_TIMING, VideoTiming
from hdl.sync_gen import SyncGenerator
from sim.runners.amaranth import simulate

FIELDS = ("x", "y", "de", "hsync", "vsync", "frame_start")


def reference_raster(t, clocks):
    """Expected outputs for clock 0 .. clocks-1 after reset, as an int array (clocks, 6)."""
    n = np.arange(clocks) % t.clocks_per_frame
    y, x = np.divmod(n, t.h_total)
    de = (x < t.h_active) & (y < t.v_active)
    hs = (x >= t.h_active + t.h_front) & (x < t.h_active + t.h_front + t.h_sync)
    # vsync starts with the hsync pulse that ends the v_front-th blank line and lasts v_sync whole lines
    vs_begin = (t.v_active + t.v_front - 1) * t.h_total + t.h_active + t.h_front
    vs = (n >= vs_begin) & (n < vs_begin + t.v_sync * t.h_total)
    return np.stack([x, y, de, hs == t.hsync_positive, vs == t.vsync_positive, n == 0], axis=1).astype(np.int64)


def simulate_sync_gen(timing, clocks):
    """The SyncGenerator's outputs for ``clocks`` clocks from reset, as an int array (clocks, 6)."""
    dut = SyncGenerator(timing)
    rows = []

    async def bench(ctx):
        sigs = [getattr(dut, f) for f in FIELDS]
        for _ in range(clocks):
            rows.append([ctx.get(s) for s in sigs])
            await ctx.tick()

    simulate(dut, clocks={"sync": timing.pixel_hz}, testbenches=[bench])
    return np.array(rows, dtype=np.int64)


def assert_same(got, want):
    if not np.array_equal(got, want):
        bad = np.argwhere(got != want)
        clock, field = bad[0]
        raise AssertionError(f"{len(bad)} mismatches; first at clock {clock}, {FIELDS[field]}: got "
                             f"{got[clock].tolist()}, expected {want[clock].tolist()} (x, y, de, hs, vs, fs)")


def test_small_mode_two_frames_every_clock():
    t = SMALL_TIMING
    clocks = 2 * t.clocks_per_frame + 1
    assert_same(simulate_sync_gen(t, clocks), reference_raster(t, clocks))


def test_negative_polarity_mode_every_clock():
    t = dataclasses.replace(SMALL_TIMING, hsync_positive=False, vsync_positive=False,
                            h_front=1, h_back=9, v_front=1, v_back=5)
    clocks = t.clocks_per_frame + 1
    assert_same(simulate_sync_gen(t, clocks), reference_raster(t, clocks))


modes = st.builds(
    VideoTiming,
    h_active=st.integers(8, 24), h_front=st.integers(0, 5), h_sync=st.integers(1, 5), h_back=st.integers(0, 5),
    v_active=st.integers(2, 8), v_front=st.integers(1, 3), v_sync=st.integers(1, 3), v_back=st.integers(0, 3),
    hsync_positive=st.booleans(), vsync_positive=st.booleans(),
)


@settings(max_examples=12, deadline=None)
@given(modes)
def test_random_modes_every_clock(t):
    clocks = t.clocks_per_frame + t.h_total + 1
    assert_same(simulate_sync_gen(t, clocks), reference_raster(t, clocks))


def test_1080p_parameters_are_cea861_vic16():
    """The shared constants against the CEA-861 numbers for 1920x1080p60, written out here."""
    t = CEA_1080P60
    assert (t.h_active, t.h_front, t.h_sync, t.h_back) == (1920, 88, 44, 148)
    assert (t.v_active, t.v_front, t.v_sync, t.v_back) == (1080, 4, 5, 36)
    assert (t.h_total, t.v_total, t.clocks_per_frame) == (2200, 1125, 2475000)
    assert t.hsync_positive and t.vsync_positive
    assert t.pixel_hz == 148_500_000 and t.frame_hz == 60.0


def test_1080p_first_lines_every_clock():
    """Three whole 1080p lines in the Amaranth simulator (the full frame runs on Verilator, and below as slow)."""
    t = CEA_1080P60
    clocks = 3 * 2200 + 1
    got = simulate_sync_gen(t, clocks)
    assert_same(got, reference_raster(t, clocks))
    hs = got[:, 3]
    leads = np.flatnonzero(np.diff(hs) == 1) + 1
    assert np.diff(leads).tolist() == [2200, 2200]                 # line length
    assert got[:, 2][:2200].sum() == 1920                          # active pixels in a line
    assert hs[:2200].sum() == 44                                   # sync width
    assert leads[0] == 1920 + 88                                   # front porch


@pytest.mark.slow
def test_1080p_full_frame_every_clock():
    t = CEA_1080P60
    clocks = t.clocks_per_frame + 1
    got = simulate_sync_gen(t, clocks)
    assert_same(got, reference_raster(t, clocks))
    frame = got[:t.clocks_per_frame]                              # without frame 1's first clock
    assert frame[:, 2].sum() == 1920 * 1080
    assert frame[:, 4].sum() == 5 * 2200


@pytest.mark.parametrize("bad", [
    dict(h_active=4100),                # h_total = 4192: x does not fit 12 bits
    dict(v_active=2100),                # y does not fit 11 bits
    dict(h_sync=0), dict(v_sync=0), dict(v_front=0), dict(h_back=-1),
])
def test_unsupported_modes_are_rejected(bad):
    with pytest.raises(ValueError):
        SyncGenerator(dataclasses.replace(SMALL_TIMING, **bad))


@pytest.mark.parametrize("start", [(5, 0), (0, 50), (SMALL_TIMING.h_sync_start, SMALL_TIMING.v_sync_start - 1),
                                   (SMALL_TIMING.h_total - 1, SMALL_TIMING.v_total - 1)])
def test_start_position_continues_the_same_raster(start):
    """With start=(x, y) the outputs are the reference raster from that position on."""
    t = SMALL_TIMING
    x0, y0 = start
    offset = y0 * t.h_total + x0
    clocks = t.clocks_per_frame + 1
    dut_rows = []
    dut = SyncGenerator(t, start=start)

    async def bench(ctx):
        for _ in range(clocks):
            dut_rows.append([ctx.get(getattr(dut, f)) for f in FIELDS])
            await ctx.tick()

    simulate(dut, clocks={"sync": t.pixel_hz}, testbenches=[bench])
    want = reference_raster(t, offset + clocks)[offset:]
    assert_same(np.array(dut_rows, dtype=np.int64), want)
