"""cocotb tests of the exported two-camera capture path (hdl.capture_path.CapturePath exported through
hdl.export.export_verilog), on Verilator and Icarus. Driven from tests/test_capture.py.

Every check compares the RTL with the golden model (golden/capture.py), which is written from the spec:
the write-port sequence with ``capture_stream`` (counting rules applied to the same samples), the buffers
read back through the ``pix`` ports with ``capture_frame`` (image level).

Parameters (sim.cocotb_runner.test_params()): ``width``, ``height`` (sensor), ``full`` (true: only the
full-resolution stereo-pair test runs, for the slow test).
"""

import cocotb
import numpy as np

from golden.capture import capture_frame, capture_stream
from golden.stereo_pair import load_default_pair
from hdl.params import SensorGeometry
from sim.cocotb_runner import test_params
from sim.mt9d112 import (MT9D112, SENSOR_TIMING, SMALL_SENSOR_TIMING, fault_cases, run_capture_cocotb)
from sim.sensor_config import SensorConfig

PARAMS = test_params()
GEOMETRY = SensorGeometry(width=PARAMS.get("width", 64), height=PARAMS.get("height", 48))
FULL = bool(PARAMS.get("full", False))
TIMING = SENSOR_TIMING if FULL else SMALL_SENSOR_TIMING
CONFIG = SensorConfig(width=GEOMETRY.width, height=GEOMETRY.height)
LEFT, RIGHT = load_default_pair(GEOMETRY.width, GEOMETRY.height)
PCLK = {"a": 24e6, "b": 23.7e6}          # independent camera clocks: different frequencies...
START = {"a": 0.0, "b": 13.7e-9}         # ...and phases


def check_against_golden(log, name, stream, record, buffer, final_image):
    """The RTL's writes and frame statuses equal the golden stream model's; the buffer read back through
    the pix port equals the golden image-level capture of the last (good) frame."""
    gold = capture_stream(stream.fv, stream.lv, stream.data, GEOMETRY)
    bad = [(a, v) for a, v in record.writes if not 0 <= a < GEOMETRY.buf_depth]
    assert not bad, f"{name}: writes outside the buffer: {bad[:5]}"
    expected = [(a, v) for _, a, v in gold.writes]
    assert len(record.writes) == len(expected), \
        f"{name}: {len(record.writes)} writes, golden model {len(expected)}"
    for k, (got, want) in enumerate(zip(record.writes, expected)):
        assert got == want, f"{name}: write {k} is (addr, grey) {got}, golden model {want}"
    assert record.frames == [f.ok for f in gold.frames], \
        f"{name}: frame_ok {record.frames}, golden model {[f.ok for f in gold.frames]}"
    assert record.samples == len(stream)
    want = capture_frame(final_image, GEOMETRY)
    diff = np.argwhere(buffer != want)
    assert diff.size == 0, f"{name}: {len(diff)} pixels differ from the golden frame, first at {diff[0]}"
    log.info("%s: %d writes and %d frame(s) match the golden model; buffer matches", name,
             len(record.writes), len(record.frames))


@cocotb.test(skip=FULL)
async def test_buffers_read_zero_after_power_up(dut):
    """Before any capture both buffers read back as zeros: the compact (loop) memory initialisation of
    hdl.export gives the same contents as Amaranth's word-by-word one."""
    _, buffers = await run_capture_cocotb(dut, GEOMETRY, {}, cameras=["a", "b"])
    for c in "ab":
        assert buffers[c].shape == (GEOMETRY.buf_height, GEOMETRY.buf_width)
        assert not buffers[c].any(), f"buffer {c} is not all zero after power-up"


@cocotb.test()
async def test_stereo_pair_concurrent(dut):
    """Both cameras capture the bundled photograph pair at once, on independent PCLKs (24 MHz and 23.7 MHz,
    offset phase); both buffers, read through the pix ports, equal the golden model bit for bit."""
    streams = {
        "a": MT9D112(CONFIG, timing=TIMING, seed=1, pclk_hz=PCLK["a"]).stream([LEFT]),
        "b": MT9D112(CONFIG, timing=TIMING, seed=2, pclk_hz=PCLK["b"]).stream([RIGHT]),
    }
    records, buffers = await run_capture_cocotb(dut, GEOMETRY, streams, pclk_hz=PCLK, start_delay=START)
    check_against_golden(dut._log, "camera a (left)", streams["a"], records["a"], buffers["a"], LEFT)
    check_against_golden(dut._log, "camera b (right)", streams["b"], records["b"], buffers["b"], RIGHT)


def _bad_stream_test(case_a, case_b):
    async def test(dut):
        cases = fault_cases(GEOMETRY.width, GEOMETRY.height)
        streams = {}
        for c, case, seed in (("a", case_a, 11), ("b", case_b, 12)):
            if case is None:
                continue
            sensor = MT9D112(CONFIG, timing=TIMING, seed=seed)
            streams[c] = sensor.stream([RIGHT, LEFT], faults=[cases[case], None])
        records, buffers = await run_capture_cocotb(dut, GEOMETRY, streams, pclk_hz=PCLK, start_delay=START)
        for c, case in (("a", case_a), ("b", case_b)):
            if case is not None:
                check_against_golden(dut._log, f"{case} (camera {c})", streams[c], records[c], buffers[c], LEFT)
    test.__name__ = f"test_bad_stream_{case_a}" + (f"_and_{case_b}" if case_b else "")
    test.__qualname__ = test.__name__
    test.__doc__ = (f"Bad streams ({case_a} on camera a, {case_b} on camera b, then a good frame each): "
                    "no write outside the buffer, every write and frame status as the golden model, and the "
                    "next good frame captured exactly.")
    return test


_CASES = list(fault_cases(GEOMETRY.width, GEOMETRY.height))
for _a, _b in zip(_CASES[0::2], _CASES[1::2] + [None]):
    globals()[f"test_bad_stream_{_a}"] = cocotb.test(skip=FULL)(_bad_stream_test(_a, _b))
