"""``stereodepth depth`` run as a user runs it (a subprocess): outputs, the found shift, one-line errors."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from golden.software.pipeline import depth_pipeline
from test_software_scenes import plane_pair

ROOT = Path(__file__).resolve().parents[1]
SHIFT, DISPARITY = 4, 9


def depth(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "stereodepth", "depth", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=120)


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    d = tmp_path_factory.mktemp("pair")
    left, right = plane_pair(100, 150, DISPARITY, SHIFT, seed=41)
    rgb = lambda g: np.stack([g, g, g], axis=-1)
    Image.fromarray(rgb(left)).save(d / "left.png")
    Image.fromarray(rgb(right)).save(d / "right.png")
    Image.fromarray(rgb(right)[:, :140]).save(d / "narrow.png")
    (d / "not_an_image.png").write_text("hello\n")
    Image.fromarray(np.full((100, 150), 128, dtype=np.uint8)).save(d / "flat.png")
    return d, left, right


def test_depth_writes_the_maps_and_reports_the_shift(pair, tmp_path):
    d, left, right = pair
    out = tmp_path / "out"
    run = depth(d / "left.png", d / "right.png", "--max-disparity", 24, "--window", 9, "--out", out)
    assert run.returncode == 0, run.stderr
    assert not [line for line in run.stderr.splitlines() if line and "%|" not in line], run.stderr  # the bar only
    assert f"vertical shift: +{SHIFT} rows" in run.stdout
    assert (out / "vertical_shift.txt").read_text().startswith(f"vertical shift: +{SHIFT} rows")
    for name in ("disparity.png", "distance.png"):
        with Image.open(out / name) as img:
            assert img.format == "PNG" and img.size[0] > 150   # a figure with a colour bar, not the raw map
    disparity = np.load(out / "disparity.npy")
    expected = depth_pipeline(left, right, max_disparity=24, window=9).disparity
    assert np.array_equal(disparity, expected)                # the command is the library
    assert (disparity[:-SHIFT, DISPARITY + 4:] == DISPARITY).all() and (disparity[-SHIFT:] == -1).all()


def test_given_shift_and_camera_overrides(pair, tmp_path):
    d, _, _ = pair
    run = depth(d / "left.png", d / "right.png", "--max-disparity", 24, "--window", 9, "--shift", -2,
                "--camera", "webcam", "--baseline", 10, "--focal", 4, "--pitch", 5, "--out", tmp_path)
    assert run.returncode == 0, run.stderr
    assert "vertical shift: -2 rows" in run.stdout and "given with --shift" in run.stdout


@pytest.mark.parametrize("args, message", [
    (["missing.png", "right.png"], "no such image file"),
    (["not_an_image.png", "right.png"], "cannot read image"),
    (["left.png", "narrow.png"], "must be the same size"),
    (["left.png", "right.png", "--max-disparity", "0"], "--max-disparity must be at least 1"),
    (["left.png", "right.png", "--max-disparity", "150"], "below the image width"),
    (["left.png", "right.png", "--max-disparity", "ten"], "whole number"),
    (["left.png", "right.png", "--window", "0"], "--window must be at least 1"),
    (["left.png", "right.png", "--window", "101"], "larger than the 150x100 image"),
    (["left.png", "right.png", "--pitch", "0"], "--pitch must be a positive length"),
    (["left.png", "right.png", "--baseline", "-6.3"], "--baseline must be a positive length"),
    (["left.png", "right.png", "--focal", "nan"], "--focal must be a positive length"),
    (["left.png", "right.png", "--shift", "100"], "--shift must be between -99 and 99"),
    (["flat.png", "flat.png", "--window", "9"], "give the shift with --shift"),
])
def test_bad_input_is_one_line_exit_2_no_traceback(pair, tmp_path, args, message):
    d, _, _ = pair
    args = [d / a if a.endswith(".png") else a for a in args]
    run = depth(*args, "--out", tmp_path / "out")
    assert run.returncode == 2
    lines = [line for line in run.stderr.splitlines() if line and "%|" not in line]    # not the progress bar
    assert len(lines) == 1 and lines[0].startswith("stereodepth depth: error: "), run.stderr
    assert message in lines[0]
    assert "Traceback" not in run.stderr and run.stdout == ""


def test_unwritable_output_directory_is_a_one_line_error(pair, tmp_path):
    d, _, _ = pair
    blocker = tmp_path / "file"
    blocker.write_text("x")
    run = depth(d / "left.png", d / "right.png", "--max-disparity", 24, "--window", 9, "--out", blocker / "sub")
    assert run.returncode == 2 and len(run.stderr.splitlines()) == 1 and "cannot create output directory" in run.stderr


def test_16_bit_grey_images_are_scaled_to_8_bits(pair, tmp_path):
    from stereodepth.cmd_depth import read_image

    _, left, _ = pair
    Image.fromarray(left.astype(np.uint16) * 257).save(tmp_path / "left16.png")    # 8-bit v -> 16-bit 257 v
    with Image.open(tmp_path / "left16.png") as img:
        assert img.mode.startswith("I")
    assert np.array_equal(read_image(tmp_path / "left16.png"), np.stack([left] * 3, axis=-1))
