# amaranth: UnusedElaboratable=no
"""The averaging capture's RTL against the golden model, bit for bit on Amaranth's simulator: the
``AveragingDownscaler`` (hdl/averaging_downscaler.py) alone and the capture path built with ``downscale="average"``
(hdl/capture.py), against ``golden.capture.average_downscale`` / ``capture_frame`` / ``grey8_of_sum`` (written from
docs/capture.md, "The averaging capture").

* random images at scales 1, 2 and 4, with pixels past the configured size (saturated columns and rows, as the
  capture's counters report them) and idle clocks between pixels: the write sequence equals the golden buffer in
  raster order;
* every block sum of the 2 x 2 block (0..748) and of one pixel (0..187) through the RTL, so every rounding boundary
  (the ties T = 22, 66, ... included), black and white; the constant division's multiplier, offset and shift checked
  exhaustively against the golden formula at scales 1, 2, 4 and 8;
* malformed input: arbitrary valid/column/row on the block's ports and the sensor model's fault cases through the
  capture path: no write outside the buffer, the frames' verdicts as the golden stream model's, the next good frame
  exact, every write inside its row's strobes;
* slow: the exported two-camera path with cocotb on Verilator and Icarus (sim/testbench/capture_average_cocotb.py):
  the stereo pair and every fault case.
"""

import numpy as np
import pytest
from amaranth.sim import Simulator
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from golden.capture import average_downscale, capture_frame, capture_stream, grey8_of_sum, to_rgb565
from golden.stereo_pair import load_default_pair
from hdl.averaging_downscaler import LATENCY, AveragingDownscaler, rounding_reciprocal
from hdl.capture import CameraCapture
from hdl.capture_path import CapturePath
from sim.models.mt9d112.config import SensorConfig
from sim.models.mt9d112.sensor import MT9D112, SMALL_SENSOR_TIMING, Faults, SensorStream, SensorTiming, fault_cases
from sim.runners.cocotb import run_cocotb
from sim.testbench.capture import playback_design, run_capture_amaranth
from spec.sensor import SensorGeometry


def averaging(width, height, scale):
    return SensorGeometry(width=width, height=height, scale=scale, grey_bits=8, downscale="average")


def run_block(geometry, image, *, extra_cols=0, extra_rows=0, idle=(0,)):
    """Raster ``image`` (RGB565 words) through an :class:`AveragingDownscaler`, plus ``extra_cols`` / ``extra_rows``
    of junk reported at the saturated column / row (the width / height), ``idle[k % len(idle)]`` idle clocks after
    pixel k; returns every write ``(addr, data)`` in order."""
    h, w = image.shape
    sequence = []
    for r in range(h + extra_rows):
        for c in range(w + extra_cols):
            value = int(image[r, c]) if r < h and c < w else (r * 131 + c * 17) & 0xFFFF
            sequence.append((1, value, min(c, geometry.width), min(r, geometry.height)))
    return run_ports(geometry, sequence, idle)


def run_ports(geometry, sequence, idle=(0,), **widths):
    """``sequence`` of ``(valid, pixel, column, row)`` on the block's ports, one a clock, ``idle`` clocks between;
    returns the writes."""
    dut = AveragingDownscaler(geometry, **widths)
    writes = []

    async def bench(ctx):
        steps = []
        for k, item in enumerate(sequence):
            steps.append(item)
            steps.extend([(0, 0, 0, 0)] * idle[k % len(idle)])
        for valid, pixel, column, row in steps + [(0, 0, 0, 0)] * LATENCY:
            ctx.set(dut.valid, valid)
            ctx.set(dut.pixel, pixel)
            ctx.set(dut.column, column)
            ctx.set(dut.row, row)
            await ctx.tick()
            if ctx.get(dut.write.en):
                writes.append((ctx.get(dut.write.addr), ctx.get(dut.write.data)))

    sim = Simulator(dut)
    sim.add_clock(1 / 24e6)
    sim.add_testbench(bench)
    sim.run()
    return writes


def golden_writes(geometry, image):
    return [(a, int(v)) for a, v in enumerate(average_downscale(image, geometry).ravel())]


def words_of_weights(weights):
    """RGB565 words whose ``2 R5 + G6 + 2 B5`` are ``weights`` (each 0..187)."""
    weights = np.asarray(weights, dtype=np.int64)
    g6 = np.where(weights <= 63, weights, 62 + (weights & 1))
    half = (weights - g6) // 2                      # R5 + B5, at most 62
    r5 = np.minimum(half, 31)
    b5 = half - r5
    return ((r5 << 11) | (g6 << 5) | b5).astype(np.uint16)


@pytest.mark.parametrize("scale, width, height, extra_cols, extra_rows, idle, seed", [
    (2, 12, 6, 0, 0, (0,), 1),           # pixels back to back
    (2, 13, 7, 3, 2, (1, 0, 2), 2),      # a width and height past the last whole block, junk past the sensor
    (4, 16, 8, 5, 1, (1,), 3),           # middle rows: the line buffer read, added to and written back
    (1, 5, 3, 2, 1, (0, 1), 4),          # one pixel a block: no line buffer
])
def test_random_images_match_golden(scale, width, height, extra_cols, extra_rows, idle, seed):
    geometry = averaging(width, height, scale)
    image = np.random.default_rng(seed).integers(0, 1 << 16, (height, width), dtype=np.uint16)
    writes = run_block(geometry, image, extra_cols=extra_cols, extra_rows=extra_rows, idle=idle)
    assert writes == golden_writes(geometry, image)


@pytest.mark.parametrize("scale", [1, 2])
def test_every_block_sum_through_the_rtl(scale):
    """One buffer row of blocks with sums 0, 1, ..., 187 s^2 (block x sums to x): every grey8 value, every rounding
    boundary and every tie, black (T = 0 -> 0) and white (T = 187 s^2 -> 255)."""
    top = 187 * scale * scale
    geometry = averaging(scale * (top + 1), scale, scale)
    weights = np.zeros((scale, geometry.width), dtype=np.int64)
    for total in range(top + 1):                    # spread T over the block's pixels, each at most 187
        block = np.full(scale * scale, total // (scale * scale))
        block[:total % (scale * scale)] += 1
        weights[:, scale * total:scale * (total + 1)] = block.reshape(scale, scale)
    image = words_of_weights(weights)
    writes = run_block(geometry, image)
    expected = grey8_of_sum(np.arange(top + 1), scale)
    assert [v for _, v in writes] == expected.tolist()
    assert writes == golden_writes(geometry, image)
    assert expected[0] == 0 and expected[-1] == 255


@pytest.mark.parametrize("word", [0x0000, 0xFFFF, 0x07E0, 0x0821])
@pytest.mark.parametrize("scale", [2, 4])
def test_uniform_images(word, scale):
    """All black, all white (255), pure green, the smallest non-zero weight (R5 = G6 = B5 = 1): a uniform image gives
    its one pixel's grey8 everywhere."""
    geometry = averaging(4 * scale, 2 * scale, scale)
    image = np.full((geometry.height, geometry.width), word, dtype=np.uint16)
    writes = run_block(geometry, image)
    assert writes == golden_writes(geometry, image)
    if word == 0xFFFF:
        assert {v for _, v in writes} == {255}


@pytest.mark.parametrize("scale", [1, 2, 4, 8])
def test_constant_division_is_exact(scale):
    """``(T * multiplier + offset) >> shift`` equals the golden ``floor((510 T + 187 s^2) / (374 s^2))`` for every
    block sum T in 0..187 s^2."""
    multiplier, offset, shift = rounding_reciprocal(scale)
    totals = np.arange(187 * scale * scale + 1, dtype=np.int64)
    np.testing.assert_array_equal((totals * multiplier + offset) >> shift, grey8_of_sum(totals, scale))


def test_arbitrary_ports_never_write_outside_the_buffer():
    """Random valid, pixel, column and row over the ports' whole range (rows and columns jumping, past the buffer,
    blocks never finished): every write is inside the buffer."""
    geometry = averaging(10, 6, 2)                  # 5 x 3 buffer; a 4-bit column and a 3-bit row reach 15 and 7
    rng = np.random.default_rng(5)
    n = 3000
    sequence = list(zip(rng.integers(0, 2, n).tolist(), rng.integers(0, 1 << 16, n).tolist(),
                        rng.integers(0, 16, n).tolist(), rng.integers(0, 8, n).tolist()))
    writes = run_ports(geometry, sequence, column_bits=4, row_bits=3)
    assert len(writes) > 100
    assert all(0 <= a < geometry.buf_depth for a, _ in writes)


def test_refusals():
    """An averaging geometry without 8-bit grey and a scale that is not a power of two are refused (one line)."""
    with pytest.raises(ValueError, match="grey_bits must be 8"):
        CameraCapture(SensorGeometry(width=16, height=8, scale=2, downscale="average"))
    with pytest.raises(ValueError, match="power of two"):
        AveragingDownscaler(averaging(12, 12, 3))


# --- The capture path at downscale="average" ---------------------------------------------------------------

TINY = averaging(17, 9, 2)              # 8 x 4 buffer; the last column and row in no block
KEEP = SensorGeometry(width=TINY.width, height=TINY.height, scale=2)      # the same frames, for their verdicts
TIMING = SensorTiming(h_blank=4, v_blank_lines=1, frame_start=2, frame_end=3)
CONFIG = SensorConfig(width=TINY.width, height=TINY.height)


def run_path(stream, read=True):
    records, buffers = run_capture_amaranth(CapturePath(TINY, cameras=("a",)), {"a": stream}, read=read)
    record = records["a"]
    assert [a for a, _ in record.writes if not 0 <= a < TINY.buf_depth] == [], "write outside the buffer"
    check_writes_inside_rows(record)
    return record, buffers.get("a")


def check_writes_inside_rows(record):
    """Row strobes come in start/end pairs, every write lies strictly between a pair's start and its end, and the
    writes between one pair's strobes are to one buffer row, each pixel once."""
    kinds = [kind for kind, _ in record.rows]
    assert kinds == ["start", "end"] * (len(kinds) // 2)
    spans = [(record.rows[k][1], record.rows[k + 1][1]) for k in range(0, len(kinds), 2)]
    rows = {}
    for cycle, (addr, _) in zip(record.write_cycles, record.writes):
        inside = [k for k, (start, end) in enumerate(spans) if start < cycle < end]
        assert inside, f"write at {cycle} outside its row's strobes"
        rows.setdefault(inside[0], []).append(addr)
    for addresses in rows.values():
        assert len({a // TINY.buf_width for a in addresses}) == 1, f"one row's strobes around writes to {addresses}"
        assert len(set(addresses)) == len(addresses), f"a pixel written twice in one row: {addresses}"


def pictures(seed, n=2):
    rng = np.random.default_rng(seed)
    return [rng.integers(0, 256, (TINY.height, TINY.width, 3), dtype=np.uint8) for _ in range(n)]


def test_capture_path_writes_the_golden_frame():
    """Two well-formed frames: each buffer row's writes in raster order inside its own row strobes (one pair per
    buffer row), both frames good, and the buffer the golden frame of the second."""
    first, second = pictures(1)
    stream = MT9D112(CONFIG, timing=TIMING, seed=2).stream([first, second])
    record, buffer = run_path(stream)
    assert record.frames == [True, True]
    per_frame = TINY.buf_depth
    expected = golden_writes(TINY, to_rgb565(first)) + golden_writes(TINY, to_rgb565(second))
    assert record.writes == expected
    assert len(record.rows) == 2 * 2 * TINY.buf_height
    for k, (start, end) in enumerate(zip(record.rows[0::2], record.rows[1::2])):
        row_writes = record.write_cycles[k * TINY.buf_width:(k + 1) * TINY.buf_width]
        assert start[1] < min(row_writes) and max(row_writes) < end[1]
    assert len(record.writes) == 2 * per_frame
    np.testing.assert_array_equal(buffer, capture_frame(second, TINY))


def averaging_fault_cases():
    """The robustness tests' cases and one of the averaging capture's own: a long line in a block's last row (its
    pixels past the width complete a block past the buffer's edge, which must not be written)."""
    return {**fault_cases(TINY.width, TINY.height), "long_last_row": Faults(line_bytes={3: 2 * TINY.width + 6})}


@pytest.mark.parametrize("case", list(averaging_fault_cases()))
def test_bad_frame_then_good_frame(case):
    """A faulty frame (the robustness tests' cases), then a good one: no write outside the buffer, every write inside
    its row's strobes, the frames' verdicts those of the golden stream model, the good frame captured exactly."""
    first, second = pictures(3)
    faults = averaging_fault_cases()[case]
    stream = MT9D112(CONFIG, timing=TIMING, seed=7).stream([first, second], faults=[faults, None])
    record, buffer = run_path(stream)
    assert record.frames == [f.ok for f in capture_stream(stream.fv, stream.lv, stream.data, KEEP).frames]
    np.testing.assert_array_equal(buffer, capture_frame(second, TINY))


@st.composite
def garbage_streams(draw):
    runs = draw(st.lists(st.tuples(st.integers(0, 1), st.integers(0, 1), st.integers(1, 40)),
                         min_size=1, max_size=40))
    seed = draw(st.integers(0, 2**32 - 1))
    fv = np.concatenate([np.full(n, f, np.uint8) for f, _, n in runs] + [np.zeros(6, np.uint8)])
    lv = np.concatenate([np.full(n, v, np.uint8) for _, v, n in runs] + [np.zeros(6, np.uint8)])
    data = np.random.default_rng(seed).integers(0, 256, len(fv), dtype=np.uint8)
    return SensorStream(fv, lv, data)


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(garbage_streams())
def test_garbage_streams_never_write_outside(stream):
    """Random FV/LV/data waveforms: no write outside the buffer, every write inside its row's strobes, the frames'
    verdicts those of the golden stream model."""
    record, _ = run_path(stream, read=False)
    assert record.frames == [f.ok for f in capture_stream(stream.fv, stream.lv, stream.data, KEEP).frames]


@pytest.mark.slow
def test_averaging_capture_cocotb(simulator):
    """cocotb on the exported two-camera path at ``downscale="average"`` (64 x 48 -> 32 x 24, 8-bit): the stereo pair
    and every fault case against the golden model (sim/testbench/capture_average_cocotb.py)."""
    g = averaging(64, 48, 2)
    left, right = load_default_pair(g.width, g.height)
    config = SensorConfig(width=g.width, height=g.height)
    streams = {"a": MT9D112(config, timing=SMALL_SENSOR_TIMING, seed=1).stream([left]),
               "b": MT9D112(config, timing=SMALL_SENSOR_TIMING, seed=2).stream([right])}
    run_cocotb(playback_design(g, streams), name="capture_path", test_module="sim.testbench.capture_average_cocotb",
               simulator=simulator, params={"width": g.width, "height": g.height, "scale": g.scale})
