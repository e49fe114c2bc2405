"""The capture path end to end: sensor model -> CameraCapture -> FrameBuffer -> pix read port, against the
golden model (golden/capture.py), in Amaranth's simulator and with cocotb on Verilator and Icarus; and the
compact-memory Verilog export (board/export.py).

Default run: SMALL_SENSOR (64 x 48 -> 16 x 12). Full 1600 x 1200 runs are marked slow.
"""

import re

import numpy as np
import pytest

from golden.capture import capture_frame, capture_stream
from golden.stereo_pair import load_default_pair
from hdl.capture_path import CapturePath
from board.export import amaranth_verilog, compact_memory_init, export_verilog
from hdl.frame_buffer import FrameBuffer
from board.memory_init import strip_zero_memory_init
from spec.sensor import SENSOR, SMALL_SENSOR, SensorGeometry
from sim.runners.cocotb import run_cocotb
from sim.testbench.capture import playback_design, run_capture_amaranth
from sim.models.mt9d112.sensor import MT9D112, SENSOR_TIMING, SMALL_SENSOR_TIMING
from sim.models.mt9d112.config import SensorConfig

PCLK = {"a": 24e6, "b": 23.7e6}
START = {"a": 0.0, "b": 13.7e-9}


def assert_matches_golden(geometry, stream, record, buffer, image):
    gold = capture_stream(stream.fv, stream.lv, stream.data, geometry)
    assert all(0 <= a < geometry.buf_depth for a, _ in record.writes)
    assert record.writes == [(a, v) for _, a, v in gold.writes]
    assert record.frames == [f.ok for f in gold.frames]
    np.testing.assert_array_equal(buffer, capture_frame(image, geometry))


def capture_pair_amaranth(geometry, timing):
    left, right = load_default_pair(geometry.width, geometry.height)
    config = SensorConfig(width=geometry.width, height=geometry.height)
    streams = {"a": MT9D112(config, timing=timing, seed=1).stream([left]),
               "b": MT9D112(config, timing=timing, seed=2).stream([right])}
    records, buffers = run_capture_amaranth(CapturePath(geometry), streams, pclk_hz=PCLK, start_delay=START)
    for c, image in (("a", left), ("b", right)):
        assert records[c].frames == [True]
        assert_matches_golden(geometry, streams[c], records[c], buffers[c], image)


def test_stereo_pair_concurrent_amaranth():
    """The photograph pair through two sensor models on independent PCLKs (24 / 23.7 MHz, offset phases),
    both captured concurrently; every write and both buffers (read through pix) match the golden model."""
    capture_pair_amaranth(SMALL_SENSOR, SMALL_SENSOR_TIMING)


def test_golden_capture_is_not_trivial():
    """Guard against a vacuous comparison: the golden buffers of the pair use many grey levels and differ."""
    left, right = load_default_pair(SMALL_SENSOR.width, SMALL_SENSOR.height)
    a, b = capture_frame(left, SMALL_SENSOR), capture_frame(right, SMALL_SENSOR)
    assert len(np.unique(a)) > 10 and (a != b).mean() > 0.3


def pair_design(geometry, timing):
    """The cocotb design: the two-camera CapturePath (compact export) with replay modules loaded with the
    pair streams of sim/testbench/capture_cocotb.py (same images, timing and seeds)."""
    left, right = load_default_pair(geometry.width, geometry.height)
    config = SensorConfig(width=geometry.width, height=geometry.height)
    streams = {"a": MT9D112(config, timing=timing, seed=1).stream([left]),
               "b": MT9D112(config, timing=timing, seed=2).stream([right])}
    return playback_design(geometry, streams)


def test_capture_cocotb(simulator):
    """cocotb on the exported two-camera design: zeros after power-up, the concurrent stereo pair from the
    Python drivers and from the Verilog playback models, and every bad-stream case
    (sim/testbench/capture_cocotb.py)."""
    g = SMALL_SENSOR
    run_cocotb(pair_design(g, SMALL_SENSOR_TIMING), name="capture_path", test_module="sim.testbench.capture_cocotb",
               simulator=simulator, params={"width": g.width, "height": g.height})


# --- board/export.py -----------------------------------------------------------------------------------------

def _word_inits(text):
    return re.findall(r"^\s*(\S+)\[(\d+)\] = (\S+);$", text, flags=re.M)


def test_export_compacts_zero_init_and_changes_nothing_else():
    original = amaranth_verilog(CapturePath(SMALL_SENSOR), "capture_path")
    compact, rewritten = compact_memory_init(original)
    bits = [f"bit{i}" for i in range(SMALL_SENSOR.grey_bits)]
    assert rewritten == bits * 2                    # one 1-bit memory per grey bit, two cameras
    assert len(_word_inits(original)) == 2 * SMALL_SENSOR.grey_bits * SMALL_SENSOR.buf_depth
    assert _word_inits(compact) == []
    # Outside the replaced initial blocks the text is identical, line for line.
    strip_init = re.compile(r"\n\s*initial begin\n(?:\s*bit\d\[\d+\] = 1'h0;\n)+\s*end", re.M)
    strip_loop = re.compile(r"\n\s*integer bit\d__init_i;\n\s*initial begin\n\s*for \(.*\)\n\s*bit\d\[.*\] = "
                            r"1'h0;\n\s*end", re.M)
    assert strip_init.sub("", original) == strip_loop.sub("", compact)
    loops = re.findall(r"for \(bit\d__init_i = 0; bit\d__init_i < (\d+); bit\d__init_i = bit\d__init_i "
                       r"\+ 1\)\n\s*bit\d\[bit\d__init_i\] = 1'h0;", compact)
    assert loops == [str(SMALL_SENSOR.buf_depth)] * 2 * SMALL_SENSOR.grey_bits


def test_strip_removes_only_zero_init():
    original = amaranth_verilog(CapturePath(SMALL_SENSOR), "capture_path")
    stripped, names = strip_zero_memory_init(original)
    assert names == [f"bit{i}" for i in range(SMALL_SENSOR.grey_bits)] * 2 and _word_inits(stripped) == []
    strip_init = re.compile(r"\n\s*initial begin\n(?:\s*bit\d\[\d+\] = 1'h0;\n)+\s*end", re.M)
    assert strip_init.sub("", original) == stripped
    g = SensorGeometry(width=16, height=8)
    ones = amaranth_verilog(FrameBuffer(g, init=[31] * g.buf_depth), "fb")   # uniform but not zero: kept
    assert strip_zero_memory_init(ones) == (ones, [])


def test_export_leaves_non_uniform_init_alone():
    g = SensorGeometry(width=16, height=8)
    init = [0, 31] * (g.buf_depth // 2)            # every bit memory alternates 0 / 1
    text = amaranth_verilog(FrameBuffer(g, init=init), "fb")
    assert compact_memory_init(text) == (text, [])
    one_off = [0] * g.buf_depth
    one_off[-1] = 31                               # every bit memory: zeros but its last word
    text = amaranth_verilog(FrameBuffer(g, init=one_off), "fb")
    assert compact_memory_init(text) == (text, [])
    mixed = [2] * g.buf_depth                      # bit 1 all ones, the others all zeros: each is uniform
    assert compact_memory_init(amaranth_verilog(FrameBuffer(g, init=mixed), "fb"))[1] == [f"bit{i}" for i in range(5)]


def test_export_full_size_buffer_is_compact():
    text = export_verilog(CapturePath(SENSOR, cameras=("a",)), "capture_path")
    assert len(text.splitlines()) < 1500
    assert "bit4__init_i < 120000;" in text


# --- Full resolution (slow) --------------------------------------------------------------------------------

@pytest.mark.slow
def test_full_resolution_capture_cocotb(simulator):
    """1600 x 1200 RGB565 frames of the pair, both cameras at once, captured bit-exactly (about 4.2 M PCLK
    cycles per camera), from the Python drivers (every write checked) and from the replay modules.
    bench/bench_capture.py runs it in Amaranth's simulator on the full-size design for part of the frame (or
    all of it with --amaranth-full)."""
    run_cocotb(pair_design(SENSOR, SENSOR_TIMING), name="capture_path", test_module="sim.testbench.capture_cocotb",
               simulator=simulator,
               testcase="test_stereo_pair_concurrent,test_playback_pair",
               params={"width": SENSOR.width, "height": SENSOR.height, "timing": "sensor"})

