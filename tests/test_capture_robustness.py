"""A malformed camera stream must never make the capture write outside its buffer or outside the pixel the
counting rules give it, and the next good frame must be captured exactly (spec "Camera driver";
docs/capture.md "Robustness").

Each named case (sim.models.mt9d112.sensor.fault_cases: LV without FV, short / long / odd-length lines, FV dropped
mid-frame, extra lines, PCLK pauses, reset in the middle of a frame, a combination) sends a faulty frame
then a good one through the sensor model into the RTL (Amaranth simulator; the same cases run on Verilator
and Icarus in sim/testbench/capture_cocotb.py). Checked on the write port: every address is inside the
buffer, and the whole write sequence and every frame status equal the golden stream model
(golden/capture.capture_stream); the buffer read back after the good frame equals the golden image-level
capture of that frame. Hypothesis then throws random fault mixes and random garbage streams at it.

The RTL is the same as in the other tests, built small (16 x 8 sensor -> 4 x 2 buffer) to keep this fast.
"""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from golden.capture import capture_frame, capture_stream
from golden.stereo_pair import load_default_pair
from hdl.capture_path import CapturePath
from spec.sensor import SensorGeometry
from sim.testbench.capture import run_capture_amaranth
from sim.models.mt9d112.sensor import MT9D112, Faults, SensorStream, SensorTiming, fault_cases
from sim.models.mt9d112.config import SensorConfig

TINY = SensorGeometry(width=16, height=8)
TINY_TIMING = SensorTiming(h_blank=4, v_blank_lines=1, frame_start=2, frame_end=3)
CONFIG = SensorConfig(width=TINY.width, height=TINY.height)


def run_and_check(stream, final_image=None, r_byte_first=True):
    """Run ``stream`` through camera a of a tiny CapturePath; compare with the golden stream model."""
    path = CapturePath(TINY, cameras=("a",), r_byte_first=r_byte_first)
    records, buffers = run_capture_amaranth(path, {"a": stream}, read=final_image is not None)
    record = records["a"]
    gold = capture_stream(stream.fv, stream.lv, stream.data, TINY, r_byte_first=r_byte_first)
    outside = [(a, v) for a, v in record.writes if not 0 <= a < TINY.buf_depth]
    assert outside == [], "write outside the buffer"
    assert record.writes == [(a, v) for _, a, v in gold.writes]
    assert record.frames == [f.ok for f in gold.frames]
    assert record.samples == len(stream)
    check_row_strobes(record, gold, TINY)
    if final_image is not None:
        np.testing.assert_array_equal(buffers["a"], capture_frame(final_image, TINY))
        np.testing.assert_array_equal(buffers["a"], gold.buffer)
    return gold


#: When a status strobe is seen, in samples after the one it comes from (the observation before the rising edge of
#: sample i sees the clock after edge i - 1): frame_start / row_start 1 clock after the edge that sampled the
#: run's first byte, write.en 3 clocks after the pixel's second byte, row_end 2 clocks after the run's end.
ROW_LATENCY = {"start": 2, "end": 3}
WRITE_LATENCY = 3


def check_row_strobes(record, gold, geometry):
    """The row strobes equal the golden model's row events (rule 7) at their documented latency, and every write
    lies strictly between the start and the end strobe of its buffer row."""
    assert record.rows == [(kind, i + ROW_LATENCY[kind]) for kind, i, _ in gold.rows]
    assert record.write_cycles == [i + WRITE_LATENCY for i, _, _ in gold.writes]
    open_rows = {}                                  # buffer row -> its start strobe's cycle, while it runs
    order = {"end": 0, "write": 1, "start": 2}      # a write in the cycle of a strobe is outside its row
    events = sorted([(c, order[kind], kind, y) for (kind, c), (_, _, y) in zip(record.rows, gold.rows)]
                    + [(c, 1, "write", a // geometry.buf_width) for c, (a, _) in zip(record.write_cycles,
                                                                                      record.writes)])
    for cycle, _, kind, y in events:
        if kind == "start":
            open_rows = {y: cycle}
        elif kind == "end":
            assert y in open_rows, f"row_end of row {y} at {cycle} without its row_start"
            open_rows = {}
        else:
            assert y in open_rows and open_rows[y] < cycle, f"write to row {y} at {cycle} outside its row strobes"


@pytest.mark.parametrize("case", list(fault_cases(TINY.width, TINY.height)))
def test_bad_frame_then_good_frame(case):
    first, second = load_default_pair(TINY.width, TINY.height)
    faults = fault_cases(TINY.width, TINY.height)[case]
    stream = MT9D112(CONFIG, timing=TINY_TIMING, seed=7).stream([first, second], faults=[faults, None])
    gold = run_and_check(stream, final_image=second)
    # The good frame is reported good; the faulty one bad, unless the fault lies outside it (LV without FV
    # is in the blanking, a PCLK pause loses nothing) or it was never seen (in progress at reset).
    expected = {"reset_mid_frame": [True], "lv_without_fv": [True, True], "pclk_pause": [True, True]}
    assert [f.ok for f in gold.frames] == expected.get(case, [False, True])


def test_row_end_follows_a_kept_last_pixel():
    """A kept row whose line ends right after a kept pixel (row 0: 2 bytes, column 0) and a frame cut in kept row 4
    after 10 bytes (columns 0 and 4): the row's last write is in the clock before its ``row_end``
    (:func:`check_row_strobes`)."""
    first, second = load_default_pair(TINY.width, TINY.height)
    faults = Faults(line_bytes={0: 2}, fv_drop=(4, 10))
    stream = MT9D112(CONFIG, timing=TINY_TIMING, seed=3).stream([first, second], faults=[faults, None])
    gold = run_and_check(stream, final_image=second)
    assert [kind for kind, _, _ in gold.rows[:3]] == ["start", "end", "start"]


def test_counters_never_wrap():
    """A line and a frame far longer than the counters' natural range (several times 2^bits): the column
    and row counters saturate, so nothing past the configured size wraps back onto the buffer."""
    first, second = load_default_pair(TINY.width, TINY.height)
    long_line = 4 * (1 << TINY.width.bit_length()) * 2          # bytes: 4x the column counter's range
    extra = 3 * (1 << TINY.height.bit_length())                 # lines: 3x the row counter's range
    faults = Faults(line_bytes={0: long_line, 4: long_line + 1}, extra_lines=extra)
    stream = MT9D112(CONFIG, timing=TINY_TIMING, seed=9).stream([first, second], faults=[faults, None])
    gold = run_and_check(stream, final_image=second)
    assert [f.ok for f in gold.frames] == [False, True]


def test_partial_frame_leaves_old_pixels():
    """FV dropped mid-frame: the rows received are the new frame's, the rest still hold the previous
    frame's (docs/capture.md "Partial frames")."""
    first, second = load_default_pair(TINY.width, TINY.height)
    drop_line = 5                                           # rows 0..4 complete; row 5 cut after 3 pixels
    faults = Faults(fv_drop=(drop_line, 6))
    stream = MT9D112(CONFIG, timing=TINY_TIMING, seed=3).stream([first, second], faults=[None, faults])
    path = CapturePath(TINY, cameras=("a",))
    records, buffers = run_capture_amaranth(path, {"a": stream})
    old, new = capture_frame(first, TINY), capture_frame(second, TINY)
    expected = old.copy()
    expected[0, :] = new[0, :]                              # buffer row 0 = sensor row 0
    expected[1, :] = new[1, :]                              # buffer row 1 = sensor row 4 (complete)
    np.testing.assert_array_equal(buffers["a"], expected)   # sensor row 8 never arrived
    assert records["a"].frames == [True, False]


@pytest.mark.parametrize("r_byte_first", [True, False])
def test_byte_order(r_byte_first):
    """Both byte orders: the sensor configured one way, the capture built the same way."""
    first, _ = load_default_pair(TINY.width, TINY.height)
    config = SensorConfig(width=TINY.width, height=TINY.height, r_byte_first=r_byte_first)
    stream = MT9D112(config, timing=TINY_TIMING).stream([first])
    run_and_check(stream, final_image=first, r_byte_first=r_byte_first)


def test_wrong_byte_order_is_detected():
    """A capture built for the other byte order writes different grey values (the comparison can fail)."""
    first, _ = load_default_pair(TINY.width, TINY.height)
    config = SensorConfig(width=TINY.width, height=TINY.height, r_byte_first=False)
    stream = MT9D112(config, timing=TINY_TIMING).stream([first])
    path = CapturePath(TINY, cameras=("a",), r_byte_first=True)
    _, buffers = run_capture_amaranth(path, {"a": stream})
    assert not np.array_equal(buffers["a"], capture_frame(first, TINY))


# --- Randomised ------------------------------------------------------------------------------------------

def _images(draw, n):
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    return [rng.integers(0, 1 << 16, (TINY.height, TINY.width), dtype=np.uint16) for _ in range(n)]


@st.composite
def faulty_frames(draw):
    n = draw(st.integers(1, 3))
    images = _images(draw, n + 1)
    line_len = 2 * TINY.width
    faults = []
    for k in range(n):
        lines = draw(st.dictionaries(st.integers(0, TINY.height - 1), st.integers(0, line_len + 6),
                                     max_size=3))
        drop = draw(st.none() | st.tuples(st.integers(0, TINY.height - 1), st.integers(0, line_len)))
        pauses = draw(st.lists(st.tuples(st.integers(0, TINY.height - 1), st.integers(0, line_len),
                                         st.sampled_from([0.2e-6, 1e-6])), max_size=2))
        cut = draw(st.none() | st.tuples(st.integers(0, TINY.height - 1), st.integers(0, line_len - 1))) \
            if k == 0 else None
        faults.append(Faults(line_bytes=lines, extra_lines=draw(st.integers(0, 2)), fv_drop=drop,
                             lv_without_fv=draw(st.integers(0, 2)), pauses=tuple(pauses), cut_before=cut))
    return images, faults + [None]


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(faulty_frames())
def test_random_fault_mixes(frames):
    """Random mixes of faults in 1-3 frames, then a good frame: same writes and statuses as the golden
    model, and the good frame captured exactly."""
    images, faults = frames
    stream = MT9D112(CONFIG, timing=TINY_TIMING, seed=5).stream(images, faults=faults)
    run_and_check(stream, final_image=images[-1])


@st.composite
def garbage_streams(draw):
    runs = draw(st.lists(st.tuples(st.integers(0, 1), st.integers(0, 1), st.integers(1, 40)),
                         min_size=1, max_size=40))
    seed = draw(st.integers(0, 2**32 - 1))
    fv = np.concatenate([np.full(n, f, np.uint8) for f, _, n in runs])
    lv = np.concatenate([np.full(n, l, np.uint8) for _, l, n in runs])
    data = np.random.default_rng(seed).integers(0, 256, len(fv), dtype=np.uint8)
    tail = np.zeros(4, np.uint8)                 # let the pipeline drain
    return SensorStream(np.concatenate([fv, tail]), np.concatenate([lv, tail]), np.concatenate([data, tail]))


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(garbage_streams())
def test_random_garbage_streams(stream):
    """Arbitrary FV/LV/D waveforms (not sensor-shaped at all): the RTL follows the counting rules exactly
    and never writes outside the buffer."""
    run_and_check(stream)
