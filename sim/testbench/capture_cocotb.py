"""cocotb tests of the exported two-camera capture path (hdl.capture_path.CapturePath with the replay modules
of sim.testbench.capture.playback_design beside it, exported through board.export.export_verilog), on Verilator
and Icarus. Driven from tests/test_capture.py.

Every check compares the RTL with the golden model (golden/capture.py), which is written from the spec:
the write-port sequence with ``capture_stream`` (counting rules applied to the same samples), the buffers
read back through the ``pix`` ports with ``capture_frame`` (image level).

Most tests drive the cameras' pins from Python (sim.models.mt9d112.sensor.drive_cocotb, one call per PCLK cycle, so every
write can be recorded); ``test_playback_pair`` switches the cameras to the Verilog replay modules, which
replay the same streams with no Python per cycle (the design must have been built with
``pair_streams()``'s streams, as tests/test_capture.py and bench/bench_capture.py do).

Parameters (sim.runners.cocotb.test_params()): ``width``, ``height`` (sensor), ``timing`` ("small":
SMALL_SENSOR_TIMING, the default; "sensor": the full-size blanking), ``report`` (a path: the stereo-pair
tests write their wall time and cycle counts there as JSON, keyed by test). The slow full-resolution test
selects the two stereo-pair tests with run_cocotb's ``testcase``.
"""

import json
import time
from pathlib import Path

import cocotb
import numpy as np

from golden.capture import capture_frame, capture_stream
from golden.stereo_pair import load_default_pair
from spec.sensor import SensorGeometry
from sim.runners.cocotb import test_params
from sim.testbench.capture import run_capture_cocotb, run_playback_cocotb
from sim.models.mt9d112.sensor import MT9D112, SENSOR_TIMING, SMALL_SENSOR_TIMING, fault_cases
from sim.models.mt9d112.config import SensorConfig

PARAMS = test_params()
GEOMETRY = SensorGeometry(width=PARAMS.get("width", 64), height=PARAMS.get("height", 48))
TIMING = SENSOR_TIMING if PARAMS.get("timing") == "sensor" else SMALL_SENSOR_TIMING
CONFIG = SensorConfig(width=GEOMETRY.width, height=GEOMETRY.height)
LEFT, RIGHT = load_default_pair(GEOMETRY.width, GEOMETRY.height)
PCLK = {"a": 24e6, "b": 23.7e6}          # independent camera clocks: different frequencies...
START = {"a": 0.0, "b": 13.7e-9}         # ...and phases


def report(test, wall, samples):
    """Add this test's wall time and PCLK cycle counts to the JSON report, when one is asked for."""
    if not PARAMS.get("report"):
        return
    path = Path(PARAMS["report"])
    data = json.loads(path.read_text()) if path.exists() else {}
    data[test] = {"wall_s": wall, "samples": samples, "readback_words": 2 * GEOMETRY.buf_depth}
    path.write_text(json.dumps(data, indent=1))


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


@cocotb.test()
async def test_buffers_read_zero_after_power_up(dut):
    """Before any capture both buffers read back as zeros: the compact (loop) memory initialisation of
    board.export gives the same contents as Amaranth's word-by-word one."""
    _, buffers = await run_capture_cocotb(dut, GEOMETRY, {}, cameras=["a", "b"])
    for c in "ab":
        assert buffers[c].shape == (GEOMETRY.buf_height, GEOMETRY.buf_width)
        assert not buffers[c].any(), f"buffer {c} is not all zero after power-up"


def pair_streams():
    """The streams of the stereo-pair tests: the same seeds give the same samples as the playback files."""
    return {"a": MT9D112(CONFIG, timing=TIMING, seed=1, pclk_hz=PCLK["a"]).stream([LEFT]),
            "b": MT9D112(CONFIG, timing=TIMING, seed=2, pclk_hz=PCLK["b"]).stream([RIGHT])}


@cocotb.test()
async def test_stereo_pair_concurrent(dut):
    """Both cameras capture the bundled photograph pair at once, on independent PCLKs (24 MHz and 23.7 MHz,
    offset phase); both buffers, read through the pix ports, equal the golden model bit for bit."""
    streams = pair_streams()
    start = time.perf_counter()
    records, buffers = await run_capture_cocotb(dut, GEOMETRY, streams, pclk_hz=PCLK, start_delay=START)
    report("driver", time.perf_counter() - start, {c: records[c].samples for c in records})
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
    globals()[f"test_bad_stream_{_a}"] = cocotb.test()(_bad_stream_test(_a, _b))


@cocotb.test()
async def test_playback_pair(dut):
    """The stereo pair replayed by the Verilog replay modules (the same samples as the Python driver would
    send) on 24 / 23.7 MHz PCLKs: one good frame per camera, both buffers equal the golden model."""
    streams = pair_streams()
    start = time.perf_counter()
    status, buffers = await run_playback_cocotb(dut, GEOMETRY, ["a", "b"], pclk_hz=PCLK, start_delay=START)
    report("playback", time.perf_counter() - start, {c: len(streams[c]) for c in streams})
    for c, image in (("a", LEFT), ("b", RIGHT)):
        assert status[c] == {"frame_count": 1, "frame_ok": True}, f"camera {c}: {status[c]}"
        want = capture_frame(image, GEOMETRY)
        diff = np.argwhere(buffers[c] != want)
        assert diff.size == 0, f"camera {c}: {len(diff)} pixels differ from the golden frame"
    dut._log.info("playback: both buffers match the golden model")
