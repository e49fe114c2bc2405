"""The MT9D112 sensor model (sim/models/mt9d112/sensor.py) against the spec: stream structure and blanking, RGB565 packing
by truncation and byte order, configuration (nothing until RGB565 is configured, through the
``sensor_config()`` hook), fault injection, inputs, and the Amaranth driver's clocking.

The model is checked against hand-worked values and the spec's rules, and its streams against the golden
stream model (golden/capture.py), which must read back exactly the image-level golden capture.
"""

import numpy as np
import pytest
from amaranth import ClockDomain, Module, Signal
from amaranth.sim import Simulator
from PIL import Image

from golden.capture import capture_frame, capture_stream, rgb888_to_rgb565
from golden.stereo_pair import load_default_pair
from hdl.capture import CameraSignature
from spec.sensor import SMALL_SENSOR, SensorGeometry
from sim.models.mt9d112.sensor import (MT9D112, SENSOR_TIMING, SMALL_SENSOR_TIMING, Faults, SensorTiming, drive_amaranth,
                         fault_cases, image_to_bytes)
from sim.models.mt9d112.config import SensorConfig
from stereodepth.errors import UserError

G = SensorGeometry(width=16, height=8)
CFG = SensorConfig(width=G.width, height=G.height)
T = SensorTiming(h_blank=5, v_blank_lines=2, frame_start=3, frame_end=4)


def runs(bits):
    """[(value, length), ...] of a 0/1 array."""
    bits = np.asarray(bits)
    edges = np.flatnonzero(np.diff(bits)) + 1
    starts = np.concatenate([[0], edges])
    ends = np.concatenate([edges, [len(bits)]])
    return [(int(bits[s]), int(e - s)) for s, e in zip(starts, ends)]


def random_rgb(seed, g=G):
    return np.random.default_rng(seed).integers(0, 256, (g.height, g.width, 3), dtype=np.uint8)


def test_frame_structure_and_blanking():
    """One frame period: v_blank_lines line times of FV low, then FV high for frame_start + H lines of 2W
    bytes separated by h_blank + frame_end, then FV low."""
    s = MT9D112(CFG, timing=T).frame(random_rgb(0))
    line_time = 2 * G.width + T.h_blank
    assert runs(s.fv) == [(0, T.v_blank_lines * line_time),
                          (1, T.frame_start + G.height * 2 * G.width + (G.height - 1) * T.h_blank + T.frame_end)]
    lv_runs = runs(s.lv)
    high = [n for v, n in lv_runs if v == 1]
    assert high == [2 * G.width] * G.height
    gaps = [n for v, n in lv_runs[1:-1] if v == 0]
    assert gaps == [T.h_blank] * (G.height - 1)              # between lines
    assert lv_runs[0] == (0, T.v_blank_lines * line_time + T.frame_start)
    assert lv_runs[-1] == (0, T.frame_end)
    assert not np.any(s.lv & (1 - s.fv))                     # LV only inside FV


def test_bytes_truncation_and_byte_order():
    """8-bit RGB -> RGB565 by truncation, two bytes per pixel in the configured order."""
    image = np.zeros((G.height, G.width, 3), np.uint8)
    image[0, 0] = (0x87, 0x43, 0x21)   # R5 = 0x10, G6 = 0x10, B5 = 0x04 -> 1000 0|010 000|0 0100 = 0x8204
    image[0, 1] = (0xFF, 0x00, 0x00)   # pure red -> 0xF800
    image[0, 2] = (0x07, 0x03, 0x07)   # below one step of each channel -> 0x0000
    for r_first, expected in ((True, [0x82, 0x04, 0xF8, 0x00, 0, 0]), (False, [0x04, 0x82, 0x00, 0xF8, 0, 0])):
        cfg = SensorConfig(width=G.width, height=G.height, r_byte_first=r_first)
        s = MT9D112(cfg, timing=T).frame(image)
        assert s.data[s.lv == 1][:6].tolist() == expected


def test_blanking_data_is_not_constant():
    """The bus carries junk outside LV, so a capture that samples D outside LV would be caught."""
    s = MT9D112(CFG, timing=T).frame(random_rgb(1))
    junk = s.data[s.lv == 0]
    assert len(np.unique(junk)) > 50


@pytest.mark.parametrize("r_byte_first", [True, False])
def test_golden_reads_model_stream(r_byte_first):
    """The golden stream model, applied to the model's samples, reproduces the golden image-level capture
    of the bundled pair, and every frame is well formed."""
    left, right = load_default_pair(SMALL_SENSOR.width, SMALL_SENSOR.height)
    cfg = SensorConfig(width=SMALL_SENSOR.width, height=SMALL_SENSOR.height, r_byte_first=r_byte_first)
    s = MT9D112(cfg, timing=SMALL_SENSOR_TIMING).stream([left, right])
    gold = capture_stream(s.fv, s.lv, s.data, SMALL_SENSOR, r_byte_first=r_byte_first)
    assert [f.ok for f in gold.frames] == [True, True]
    np.testing.assert_array_equal(gold.buffer, capture_frame(right, SMALL_SENSOR))
    assert len(gold.writes) == 2 * SMALL_SENSOR.buf_depth


def test_nothing_until_configured_for_rgb565():
    """While the register file says "not RGB565" the sensor keeps FV low; once configured it sends the
    frame. The configuration is read at each frame boundary through sensor_config()."""
    class RegisterFile:
        def __init__(self):
            self.reads = 0

        def sensor_config(self):
            self.reads += 1
            return SensorConfig(width=G.width, height=G.height, rgb565=self.reads > 2)

    regs = RegisterFile()
    image = random_rgb(2)
    chunks = list(MT9D112(regs, timing=T).frames([image]))
    assert [c.configured for c in chunks[:3]] == [False, False, True]
    assert not chunks[0].fv.any() and not chunks[1].fv.any() and not chunks[0].lv.any()
    gold = capture_stream(chunks[2].fv, chunks[2].lv, chunks[2].data, G)
    np.testing.assert_array_equal(gold.buffer, capture_frame(image, G))


def test_never_configured_raises_with_max_idle():
    cfg = SensorConfig(width=G.width, height=G.height, rgb565=False)
    with pytest.raises(RuntimeError):
        MT9D112(cfg, timing=T).stream([random_rgb(3)])


def test_config_type_checked():
    with pytest.raises(TypeError):
        MT9D112(object())


def test_default_resolution_and_timing():
    sensor = MT9D112()
    assert (sensor.config().width, sensor.config().height) == (1600, 1200)
    assert sensor.timing == SENSOR_TIMING and sensor.pclk_hz == 24e6


def test_image_inputs(tmp_path):
    """PNG path, other-sized RGB (fitted to the sensor), RGB565 arrays; bad inputs refused."""
    image = random_rgb(4)
    path = tmp_path / "frame.png"
    Image.fromarray(image).save(path)
    sensor = MT9D112(CFG, timing=T)
    np.testing.assert_array_equal(sensor.words(path), rgb888_to_rgb565(image))
    np.testing.assert_array_equal(sensor.words(rgb888_to_rgb565(image)), rgb888_to_rgb565(image))
    assert sensor.words(random_rgb(5, SensorGeometry(width=40, height=30))).shape == (G.height, G.width)
    with pytest.raises(UserError, match="no such image"):
        sensor.words(tmp_path / "missing.png")
    (tmp_path / "bad.png").write_text("not a png")
    with pytest.raises(UserError, match="cannot read"):
        sensor.words(tmp_path / "bad.png")
    with pytest.raises(ValueError):
        sensor.words(np.zeros((3, 3), np.uint16))


def test_faults_shape_the_stream():
    sensor = MT9D112(CFG, timing=T)
    image = random_rgb(6)
    n = 2 * G.width
    high = lambda s: [k for v, k in runs(s.lv & s.fv) if v == 1]       # noqa: E731

    s = sensor.frame(image, Faults(line_bytes={1: 5, 2: n + 3}))
    assert high(s) == [n, 5, n + 3] + [n] * (G.height - 3)
    s = sensor.frame(image, Faults(extra_lines=2))
    assert high(s) == [n] * (G.height + 2)
    s = sensor.frame(image, Faults(fv_drop=(3, 7)))
    assert high(s) == [n, n, n, 7] and s.fv[-1] == 1 and len(runs(s.fv)) == 2   # the chunk ends at the drop
    s = sensor.frame(image, Faults(lv_without_fv=2))
    assert [k for v, k in runs(s.lv & (1 - s.fv)) if v == 1] == [n, n]
    s = sensor.frame(image, Faults(pauses=((0, 0, 1e-6), (2, n, 2e-6))))
    first_byte = int(np.flatnonzero(s.lv)[0])
    assert s.pauses == {first_byte: 1e-6, first_byte + 3 * n + 2 * T.h_blank: 2e-6}
    assert s.duration(24e6) == pytest.approx(len(s) / 24e6 + 3e-6)
    s = sensor.frame(image, Faults(cut_before=(2, 3)))
    assert s.fv[0] == 1 and s.lv[0] == 1 and high(s)[0] == n - 3
    cut = sensor.frame(image, Faults(fv_drop=(3, 7)))
    s = sensor.frame(image, Faults(fv_drop=(3, 7), silence_lines=5))       # restarted: silent 5 lines after the drop
    line = T.line_time(G.width)
    assert len(s) == len(cut) + 5 * line and not s.fv[len(cut):].any() and not s.lv[len(cut):].any()
    assert high(s) == [n, n, n, 7]
    whole = sensor.frame(image)
    s = sensor.frame(image, Faults(silence_lines=2))
    assert len(s) == len(whole) + 2 * line and not s.fv[len(whole):].any() and high(s) == [n] * G.height


def test_fault_cases_are_all_distinct_and_valid():
    cases = fault_cases(G.width, G.height)
    sensor = MT9D112(CFG, timing=T)
    streams = {name: sensor.frame(random_rgb(7), f) for name, f in cases.items()}
    signatures = {(len(s), tuple(runs(s.fv)), tuple(runs(s.lv))) for s in streams.values()}
    assert len(signatures) >= len(cases) - 1       # the pause case differs only in its pauses
    with pytest.raises(ValueError):
        fault_cases(4, 4)


def test_amaranth_driver_clocking():
    """drive_amaranth: sample i is what rising edge i captures (on_sample sees the registered copy of sample
    i-1), there is one PCLK edge per sample, and the run lasts one period per sample plus the pauses
    (measured with a 200 MHz reference clock counting in hardware)."""
    m = Module()
    m.domains.cam = cd = ClockDomain("cam")
    m.domains.ref = ClockDomain("ref")
    pins = CameraSignature.create()
    data, lv, fv = pins.data, pins.lv, pins.fv
    data_r, edges, ref_ticks = Signal(10), Signal(16), Signal(16)
    m.d.cam += [data_r.eq(data | (lv << 8) | (fv << 9)), edges.eq(edges + 1)]
    m.d.ref += ref_ticks.eq(ref_ticks + 1)
    samples = MT9D112(CFG, timing=T).frame(random_rgb(8), Faults(pauses=((1, 0, 0.5e-6),)))
    seen, result = [], {}

    async def bench(ctx):
        await drive_amaranth(ctx, samples, clk=cd.clk, pins=pins, pclk_hz=20e6,
                             on_sample=lambda c: seen.append(c.get(data_r)))
        result["edges"], result["ref"] = ctx.get(edges), ctx.get(ref_ticks)

    sim = Simulator(m)
    sim.add_clock(5e-9, domain="ref")
    sim.add_testbench(bench)
    sim.run()
    words = (samples.data.astype(int) | (samples.lv.astype(int) << 8) | (samples.fv.astype(int) << 9)).tolist()
    assert seen[1:] == words[:-1]
    assert result["edges"] == len(samples)
    expected_ns = len(samples) * 50 + 500
    assert abs(result["ref"] * 5 - expected_ns) <= 5


def test_image_to_bytes_layout():
    words = np.array([[0x1234, 0xABCD]], np.uint16)
    assert image_to_bytes(words, True).tolist() == [[0x12, 0x34, 0xAB, 0xCD]]
    assert image_to_bytes(words, False).tolist() == [[0x34, 0x12, 0xCD, 0xAB]]
