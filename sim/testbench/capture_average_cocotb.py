"""cocotb tests of the exported two-camera capture path built with ``downscale="average"`` (8-bit block means,
hdl/averaging_downscaler.py; the design of sim.testbench.capture.playback_design), on Verilator and Icarus. Driven
from tests/test_averaging_capture.py.

The golden model (golden/capture.py, written from docs/capture.md "The averaging capture") defines the image level:
a well-formed frame's writes are its averaged buffer in raster order, and the buffers read back through the ``pix``
ports equal ``capture_frame``. For malformed streams: no write outside the buffer, the frames' verdicts those of the
golden stream model (``capture_stream`` of the same sensor kept, whose frame accounting is the same), the next good
frame captured exactly.

Parameters (sim.runners.cocotb.test_params()): ``width``, ``height`` (sensor), ``scale``.
"""

import cocotb
import numpy as np

from golden.capture import capture_frame, capture_stream
from golden.stereo_pair import load_default_pair
from sim.models.mt9d112.config import SensorConfig
from sim.models.mt9d112.sensor import MT9D112, SMALL_SENSOR_TIMING, fault_cases
from sim.runners.cocotb import test_params
from sim.testbench.capture import run_capture_cocotb
from spec.sensor import SensorGeometry

PARAMS = test_params()
GEOMETRY = SensorGeometry(width=PARAMS.get("width", 64), height=PARAMS.get("height", 48), scale=PARAMS.get("scale", 2),
                          grey_bits=8, downscale="average")
KEEP = SensorGeometry(width=GEOMETRY.width, height=GEOMETRY.height, scale=GEOMETRY.scale)
CONFIG = SensorConfig(width=GEOMETRY.width, height=GEOMETRY.height)
LEFT, RIGHT = load_default_pair(GEOMETRY.width, GEOMETRY.height)
PCLK = {"a": 24e6, "b": 23.7e6}          # independent camera clocks: different frequencies...
START = {"a": 0.0, "b": 13.7e-9}         # ...and phases


def pair_streams():
    """The stereo pair's streams (the playback design's replay files are built from the same seeds)."""
    return {"a": MT9D112(CONFIG, timing=SMALL_SENSOR_TIMING, seed=1, pclk_hz=PCLK["a"]).stream([LEFT]),
            "b": MT9D112(CONFIG, timing=SMALL_SENSOR_TIMING, seed=2, pclk_hz=PCLK["b"]).stream([RIGHT])}


def check(name, stream, record, buffer, final_image, whole_stream_good=False):
    """No write outside the buffer; the frames' verdicts those of the golden stream model; the buffer the golden
    averaging capture of ``final_image``; with ``whole_stream_good``, the writes its averaged buffer in raster
    order."""
    bad = [(a, v) for a, v in record.writes if not 0 <= a < GEOMETRY.buf_depth]
    assert not bad, f"{name}: writes outside the buffer: {bad[:5]}"
    verdicts = [f.ok for f in capture_stream(stream.fv, stream.lv, stream.data, KEEP).frames]
    assert record.frames == verdicts, f"{name}: frame_ok {record.frames}, golden model {verdicts}"
    want = capture_frame(final_image, GEOMETRY)
    if whole_stream_good:
        expected = [(a, int(v)) for a, v in enumerate(want.ravel())]
        assert record.writes == expected, f"{name}: the writes differ from the golden frame's in raster order"
    diff = np.argwhere(buffer != want)
    assert diff.size == 0, f"{name}: {len(diff)} pixels differ from the golden frame, first at {diff[0]}"


@cocotb.test()
async def test_stereo_pair_averaged(dut):
    """Both cameras capture the bundled pair at once on independent PCLKs: every write and both buffers equal the
    golden averaging capture bit for bit."""
    streams = pair_streams()
    records, buffers = await run_capture_cocotb(dut, GEOMETRY, streams, pclk_hz=PCLK, start_delay=START)
    for c, image in (("a", LEFT), ("b", RIGHT)):
        check(f"camera {c}", streams[c], records[c], buffers[c], image, whole_stream_good=True)
    assert len(np.unique(capture_frame(LEFT, GEOMETRY))) > 30      # not a trivial picture


@cocotb.test()
async def test_bad_streams_averaged(dut):
    """Every fault case of the robustness tests, a faulty frame then a good one, two cases at a time (one per
    camera): no write outside the buffer, the golden verdicts, the good frame exact."""
    cases = list(fault_cases(GEOMETRY.width, GEOMETRY.height).items())
    for pair in zip(cases[0::2], cases[1::2] + [None]):
        streams, names = {}, {}
        for c, item, seed in zip("ab", pair, (11, 12)):
            if item is not None:
                names[c], faults = item
                streams[c] = MT9D112(CONFIG, timing=SMALL_SENSOR_TIMING, seed=seed).stream([RIGHT, LEFT],
                                                                                          faults=[faults, None])
        records, buffers = await run_capture_cocotb(dut, GEOMETRY, streams, pclk_hz=PCLK, start_delay=START,
                                                    cameras=["a", "b"])
        for c in streams:
            check(f"{names[c]} (camera {c})", streams[c], records[c], buffers[c], LEFT)
        dut._log.info("%s: as the golden model", " and ".join(names.values()))
