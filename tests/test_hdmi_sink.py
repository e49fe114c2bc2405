"""The HDMI/CH7301C sink model on its own: it accepts a correct stream and catches each kind of fault.

The streams here are built from the timing definition with NumPy (independently of the RTL): a per-clock
raster with ``de``/``hsync``/``vsync`` and the pattern's pixels split into the two CH7301C words by the IDF 0
table of the datasheet. Each negative test breaks one thing and checks that the sink reports exactly that
kind of violation, so the checker itself is shown to work.
"""

import dataclasses

import numpy as np
import pytest
from PIL import Image

from golden.video import pattern_frame
from spec.video import SMALL_TIMING, CEA_1080P60
from sim.models.ch7301c.hdmi_sink import HdmiSink, SinkError

T = SMALL_TIMING


def raster(timing, frames=2, extra=1):
    """Per-clock (hsync, vsync, de, first, second) arrays for ``frames`` frames (+ ``extra`` clocks)."""
    t = timing
    n = frames * t.clocks_per_frame + extra
    pos = np.arange(n) % t.clocks_per_frame
    x, y = pos % t.h_total, pos // t.h_total
    de = (x < t.h_active) & (y < t.v_active)
    hs = (x >= t.h_sync_start) & (x < t.h_sync_start + t.h_sync)
    vs_start = (t.v_sync_start - 1) * t.h_total + t.h_sync_start    # vsync starts with an hsync pulse
    vs = (pos >= vs_start) & (pos < vs_start + t.v_sync * t.h_total)
    img = pattern_frame(t).astype(np.int64)
    r, g, b = (np.zeros(n, dtype=np.int64) for _ in range(3))
    r[de], g[de], b[de] = (img[y[de], x[de], c] for c in range(3))
    first = ((g & 0xF) << 8) | b          # rising edge: D[11:8] = G[3:0], D[7:0] = B[7:0]
    second = (r << 4) | (g >> 4)          # falling edge: D[11:4] = R[7:0], D[3:0] = G[7:4]
    return {
        "hsync": (hs == t.hsync_positive).astype(np.int64),
        "vsync": (vs == t.vsync_positive).astype(np.int64),
        "de": de.astype(np.int64), "first": first, "second": second, "x": x, "y": y,
    }


def run(stream, timing=T, **kwargs):
    sink = HdmiSink(timing, **kwargs)
    sink.feed(zip(*(stream[k].tolist() for k in ("hsync", "vsync", "de", "first", "second"))))
    return sink


def delete(stream, index):
    return {k: np.delete(v, index) for k, v in stream.items()}


def clock_of(stream, x, y, frame=0):
    return frame * T.clocks_per_frame + y * T.h_total + x


def kinds(sink):
    return set(sink.violation_counts)


def test_correct_stream_rebuilds_frames_and_measures_exact_timing():
    sink = run(raster(T, frames=2))
    assert sink.ok, sink.report()
    assert sink.frames_completed == 2
    for frame in sink.frames:
        assert np.array_equal(frame, pattern_frame(T))
    obs = sink.observed
    assert set(obs["line_clocks"]) == {124}
    assert set(obs["hsync_clocks"]) == {3}
    assert set(obs["h_front"]) == {4} and set(obs["h_back"]) == {5}
    assert set(obs["active_pixels"]) == {112}
    assert set(obs["vsync_clocks"]) == {2 * 124} and set(obs["vsync_lines"]) == {2}
    assert set(obs["v_front"]) == {2} and set(obs["v_back"]) == {3}
    assert obs["active_lines"] == {52: 2}
    assert obs["frame_clocks"] == {124 * 59: 2}         # frame 0 -> 1 and frame 1 -> the extra clock


def test_negative_polarity_mode_is_accepted():
    t = dataclasses.replace(T, hsync_positive=False, vsync_positive=False, h_back=7, v_back=4)
    sink = run(raster(t, frames=2), timing=t)
    assert sink.ok, sink.report()
    assert set(sink.observed["h_back"]) == {7} and set(sink.observed["v_back"]) == {4}
    assert np.array_equal(sink.frames[-1], pattern_frame(t))


def test_wrong_line_length_is_reported():
    s = raster(T)
    sink = run(delete(s, clock_of(s, T.h_total - 1, 10)))      # one back-porch clock missing on line 10
    assert "line_clocks" in kinds(sink)
    assert any("line length is 123, expected 124" in v.message for v in sink.violations), sink.report()
    with pytest.raises(SinkError, match="line_clocks"):
        sink.check()


def test_wrong_hsync_width_is_reported():
    s = raster(T)
    s["hsync"][clock_of(s, T.h_sync_start + T.h_sync, 5)] = 1    # pulse one clock too long on line 5
    sink = run(s)
    assert "hsync_clocks" in kinds(sink)
    assert any("hsync width is 4, expected 3" in v.message for v in sink.violations), sink.report()
    assert "h_back" in kinds(sink)         # the back porch got one clock shorter


@pytest.mark.parametrize("signal", ["hsync", "vsync"])
def test_wrong_polarity_is_reported(signal):
    s = raster(T)
    s[signal] = 1 - s[signal]
    sink = run(s)
    assert f"{signal}_polarity" in kinds(sink), sink.report()
    assert any("during active video" in v.message for v in sink.violations if v.kind == f"{signal}_polarity")


def test_sink_expecting_negative_polarity_rejects_positive_pulses():
    t = dataclasses.replace(T, hsync_positive=False)
    sink = run(raster(T), timing=t)
    assert "hsync_polarity" in kinds(sink)


def test_wrong_vsync_width_is_reported():
    s = raster(T)
    start = clock_of(s, T.h_sync_start, T.v_sync_start - 1)
    end = start + T.v_sync * T.h_total
    s["vsync"][end:end + T.h_total] = 1                           # one line too long
    sink = run(s)
    assert "vsync_clocks" in kinds(sink) and "vsync_lines" in kinds(sink)
    assert "v_back" in kinds(sink)


def test_vsync_not_aligned_with_hsync_is_reported():
    s = raster(T)
    start = clock_of(s, T.h_sync_start, T.v_sync_start - 1)
    s["vsync"][start] = 0                                          # leading edge one clock late
    sink = run(s)
    assert "vsync_alignment" in kinds(sink)
    assert "vsync_clocks" in kinds(sink)


def test_wrong_front_porch_and_active_width_are_reported():
    s = raster(T)
    i = clock_of(s, T.h_active, 3)
    s["de"][i] = 1                                                 # de one clock too long on line 3
    sink = run(s, check_blank_data=False)
    assert {"active_pixels", "h_front"} <= kinds(sink)


def test_missing_active_line_is_reported():
    s = raster(T)
    line = slice(clock_of(s, 0, 20), clock_of(s, 0, 21))
    for k in ("de", "first", "second"):
        s[k][line] = 0                                             # line 20 blank
    sink = run(s)
    assert "active_lines" in kinds(sink)
    assert any("frame has 51 active lines" in v.message for v in sink.violations), sink.report()
    assert sink.frames_completed == 1                              # the broken frame is not delivered


def test_data_in_blanking_is_reported():
    s = raster(T)
    s["first"][clock_of(s, T.h_active + 1, 2)] = 0x123
    sink = run(s)
    assert kinds(sink) == {"blank_data"}


def test_swapped_halves_give_a_wrong_frame_not_a_timing_error():
    s = raster(T)
    s["first"], s["second"] = s["second"], s["first"]
    sink = run(s)
    assert sink.ok                                                 # timing is fine ...
    assert not np.array_equal(sink.frames[0], pattern_frame(T))    # ... but the picture is not


def test_one_pixel_shift_gives_a_wrong_frame():
    s = raster(T)
    for k in ("first", "second"):
        s[k] = np.roll(s[k], 1) * s["de"]
    sink = run(s)
    assert not np.array_equal(sink.frames[0], pattern_frame(T))


def test_stream_joined_mid_frame_waits_for_vsync():
    s = raster(T, frames=2)
    start = clock_of(s, 0, 10)
    s = {k: v[start:] for k, v in s.items()}
    sink = run(s, starts_at_frame=False)
    assert sink.ok, sink.report()
    assert sink.frames_completed == 1                              # frame 0 was joined late: dropped
    assert np.array_equal(sink.frames[0], pattern_frame(T))


def test_reports_are_bounded_and_counted():
    s = raster(T)
    s["hsync"] = 1 - s["hsync"]
    sink = run(s, max_reports=3)
    assert sink.violation_counts["hsync_polarity"] > 3
    assert sum(v.kind == "hsync_polarity" for v in sink.violations) == 3
    assert "hsync_polarity x" in sink.report()


def test_write_png_round_trip(tmp_path):
    sink = run(raster(T, frames=1))
    path = sink.write_png(tmp_path / "f.png")
    assert np.array_equal(np.asarray(Image.open(path).convert("RGB")), pattern_frame(T))


def test_write_png_without_frame_raises(tmp_path):
    with pytest.raises(SinkError):
        HdmiSink(T).write_png(tmp_path / "none.png")


@pytest.mark.slow
def test_full_1080p_stream():
    sink = run(raster(CEA_1080P60, frames=1), timing=CEA_1080P60)
    assert sink.ok, sink.report()
    assert np.array_equal(sink.frames[0], pattern_frame(CEA_1080P60))


def _state(sink):
    """Everything a sink holds, frames as bytes (to compare two sinks)."""
    state = {k: v for k, v in vars(sink).items() if k not in ("frames", "_frame", "timing")}
    state["frames"] = [f.tobytes() for f in sink.frames]
    state["_frame"] = None if sink._frame is None else sink._frame.tobytes()
    return state


@pytest.mark.parametrize("seed", range(6))
def test_feed_columns_is_sample_by_sample(seed):
    """feed_columns (runs inside active lines appended at once) leaves the sink exactly as sample() per clock
    does, on a clean stream (seed 0) and on streams with random faults on every pin, fed in chunks of random
    length (so a chunk can start anywhere: inside a line, on an edge)."""
    rng = np.random.default_rng(seed)
    stream = raster(T, frames=3)
    names = ("hsync", "vsync", "de", "first", "second")
    for _ in range(0 if seed == 0 else 40):
        name, i = names[rng.integers(5)], rng.integers(len(stream["de"]))
        stream[name][i] ^= 1 << int(rng.integers(12 if name in ("first", "second") else 1))
    reference = run(stream)
    sink = HdmiSink(T)
    cuts = [0, *sorted(rng.integers(0, len(stream["de"]), 7).tolist()), len(stream["de"])]
    for a, b in zip(cuts, cuts[1:]):
        sink.feed_columns(*(stream[k][a:b] for k in names))
    assert _state(sink) == _state(reference)
    assert seed == 0 or not reference.ok            # the faults are seen
