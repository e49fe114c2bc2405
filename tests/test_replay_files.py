"""The in-simulator route's file formats: the replay ROM files written from a sensor stream (sim/replay/sensor.py)
and the pin recorder's lines read back (sim/replay/pins.py), checked against formats written independently here."""

import numpy as np
import pytest

from sim.models.mt9d112.sensor import SensorStream
from sim.replay.pins import read_recording
from sim.replay.sensor import pack_stream, write_hex


def _stream(n, seed=0):
    rng = np.random.default_rng(seed)
    return SensorStream(fv=rng.integers(0, 2, n).astype(np.uint8), lv=rng.integers(0, 2, n).astype(np.uint8),
                        data=rng.integers(0, 256, n).astype(np.uint8))


def test_stream_to_hex_writes_one_readmemh_word_per_sample(tmp_path):
    stream = _stream(5000)
    path = tmp_path / "cam.hex"
    assert write_hex(pack_stream(stream), path) == 5000
    lines = path.read_text().splitlines()
    assert len(lines) == 5000 and all(len(line) == 3 for line in lines)
    words = [int(line, 16) for line in lines]
    assert words == [(int(f) << 9) | (int(v) << 8) | int(d) for f, v, d in zip(stream.fv, stream.lv, stream.data)]


def _write_recording(path, rows):
    # The recorder's $fwrite("%h %h %h %h\n") of 5-, 2-, 12- and 12-bit values: zero-padded, lower case.
    path.write_text("".join(f"{h:02x} {lo:x} {a:03x} {b:03x}\n" for h, lo, a, b in rows))


def test_read_recording_round_trip(tmp_path):
    rng = np.random.default_rng(1)
    rows = [(int(rng.integers(32)), int(rng.integers(4)), int(rng.integers(4096)), int(rng.integers(4096)))
            for _ in range(3000)]
    rows += [(31, 3, 4095, 4095), (0, 0, 0, 0)]
    path = tmp_path / "bus.txt"
    _write_recording(path, rows)
    assert [tuple(r) for r in read_recording(path)] == rows


@pytest.mark.parametrize("bad_line", ["1x 1 000 000\n", "10 1 0z0 000\n", "10 1 000 00X\n", "10,1 000 000\n"])
def test_read_recording_names_the_first_bad_line(tmp_path, bad_line):
    path = tmp_path / "bus.txt"
    _write_recording(path, [(16, 1, 5, 6)] * 3)
    with open(path, "a") as f:
        f.write(bad_line)
    with pytest.raises(ValueError, match=r"line 4\b"):
        read_recording(path)


def test_read_recording_rejects_a_truncated_file(tmp_path):
    path = tmp_path / "bus.txt"
    _write_recording(path, [(16, 1, 5, 6)] * 3)
    with open(path, "a") as f:
        f.write("10 1 0")
    with pytest.raises(ValueError, match="not whole"):
        read_recording(path)
