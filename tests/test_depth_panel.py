"""Reading the depth display back from a frame (sim/analysis/depth_panel.py): the codes, the readout, the figures, the
ground-truth files of ``stereodepth run --ground-truth``."""

import numpy as np
import pytest
from PIL import Image

from golden.depth_display import depth_colours
from golden.disparity import composite_frame
from golden.stereo_pair import load_default_pair
from golden.capture import capture_frame
from spec.depth import DEPTH
from spec.layout import DisplayLayout
from spec.sensor import SENSOR
from spec.video import CEA_1080P60
from sim.analysis.depth_panel import colour_codes, depth_summary, read_depth_panel, read_text, read_truth
from sim import UserError

LAYOUT = DisplayLayout.centred(CEA_1080P60, SENSOR, DEPTH)


@pytest.fixture(scope="module")
def golden():
    left, right = load_default_pair(SENSOR.width, SENSOR.height)
    return composite_frame(capture_frame(left, SENSOR), capture_frame(right, SENSOR), 20, 0, details=True)


def test_panel_and_readout_read_back(golden):
    """Every panel pixel but the crosshair's 4 x 7 and the readout's 36 x 8 gives back a code of the golden code's
    colour, within 2/16 pixel of it (at most 5 codes share a colour), and exactly the invalid code where it is
    invalid; the readout's text is the golden one; a cell broken by one pixel reads '?'."""
    frame, codes, text = golden
    got, known = read_depth_panel(frame, LAYOUT, DEPTH)
    assert (~known).sum() == 4 * (LAYOUT.crosshair_arm - 1) + 36 * 8
    colours = depth_colours(DEPTH)
    assert (colours[got[known]] == colours[codes[known]]).all() and (np.abs(got - codes)[known] <= 2).all()
    assert ((got == DEPTH.invalid) == (codes == DEPTH.invalid))[known].all()
    assert (got[known] % DEPTH.fraction != 0).mean() > 0.5                 # the fractions are shown
    assert read_text(frame, LAYOUT.readout) == text and text.strip()[0].isdigit()
    broken = frame.copy()
    box = LAYOUT.readout
    broken[box.y0 + 2, box.x0 + 5 * 12 + 2] = (1, 2, 3)                 # font pixel (1, 1) of the "m" cell
    assert read_text(broken, box)[-1] == "?"


def test_summary_against_a_truth(golden):
    """A truth equal to the engine's sub-pixel disparities: no bad pixel among the valid ones (the read-back is
    within 2/16 pixel); every invalid pixel with a truth counts bad; one pixel off by 1.5 is bad > 1 but not
    bad > 2."""
    frame, codes, _ = golden
    truth = codes / DEPTH.fraction                                # the panel shows sub-pixel disparities
    invalid = codes == DEPTH.invalid
    truth[invalid] = 5.0
    s = depth_summary(frame, LAYOUT, SENSOR, DEPTH, truth)
    _, known = read_depth_panel(frame, LAYOUT, DEPTH)
    n = known.sum()
    assert s["pixels_with_truth"] == n
    assert s["bad2"] == s["bad1"] == (invalid & known).sum() / n
    y, x = np.argwhere(known & ~invalid)[0]
    truth[y, x] += 1.5
    s2 = depth_summary(frame, LAYOUT, SENSOR, DEPTH, truth)
    assert s2["bad1"] > s["bad1"] and s2["bad2"] == s["bad2"]
    assert s["centre_distance_cm"] == int(s["centre_readout"][:-2])


def _write_pfm(path, data):
    h, w = data.shape
    with open(path, "wb") as f:
        f.write(b"Pf\n%d %d\n-1.0\n" % (w, h))
        np.flipud(data).astype("<f4").tofile(f)


def test_ground_truth_files(tmp_path):
    """A 2000 x 1200 map (cropped to 1600 x 1200 like the images, then 1:4): 40 original pixels are 10 buffer
    pixels; PFM inf and PNG 0 are unknown; the same map as PFM and as 16-bit PNG reads the same."""
    truth = np.full((1200, 2000), 40.0)
    truth[:, :200] = 99.0                            # cropped away
    truth[0:8, 200:208] = np.inf
    _write_pfm(tmp_path / "t.pfm", truth)
    png = np.where(np.isfinite(truth), truth * 256, 0).astype(np.uint16)
    Image.fromarray(png).save(tmp_path / "t.png")
    for name in ("t.pfm", "t.png"):
        got = read_truth(tmp_path / name, (2000, 1200), SENSOR)
        assert got.shape == (300, 400)
        assert np.isnan(got[0:2, 0:2]).all() and np.isnan(got).sum() == 4
        assert np.nanmax(got) == np.nanmin(got) == 10.0
    Image.fromarray(np.zeros((1200, 2000), dtype=np.uint8)).save(tmp_path / "grey8.png")
    for args in (("missing.pfm", (2000, 1200)), ("t.pfm", (1600, 1200)), ("grey8.png", (2000, 1200))):
        with pytest.raises(UserError):
            read_truth(tmp_path / args[0], args[1], SENSOR)
    assert len(colour_codes(DEPTH)) == len(set(depth_colours(DEPTH).tolist()))   # the colours are invertible


def test_left_view_ground_truth_is_converted_to_the_right_view(tmp_path):
    """A left-view map (Middlebury's disp0 side), 1600 x 1200: a far half at 40 original pixels, a near right
    half at 80. Seen from the right camera left pixel x lands at x - d: the far half covers right columns
    -40..759, the near one 720..1519 (the nearer wins where both land), and nothing reaches 1520..1599. In
    buffer pixels (1:4): 10 left of column 180, 20 from 180 to 379, unknown from 380 on; read as a right view
    the same file splits at 200 and is known everywhere."""
    truth = np.full((1200, 1600), 40.0)
    truth[:, 800:] = 80.0
    _write_pfm(tmp_path / "disp0.pfm", truth)
    got = read_truth(tmp_path / "disp0.pfm", (1600, 1200), SENSOR, view="left")
    assert (got[:, :179] == 10).all() and (got[:, 181:379] == 20).all() and np.isnan(got[:, 381:]).all()
    as_right = read_truth(tmp_path / "disp0.pfm", (1600, 1200), SENSOR)
    assert (as_right[:, :200] == 10).all() and (as_right[:, 200:] == 20).all()
    with pytest.raises(UserError, match="view"):
        read_truth(tmp_path / "disp0.pfm", (1600, 1200), SENSOR, view="top")


def test_run_rejects_a_bad_ground_truth_in_one_line(tmp_path):
    """``stereodepth run --ground-truth`` with a truth of the wrong size: one line on stderr, exit code 2, before
    any simulation."""
    import subprocess
    import sys
    from golden.stereo_pair import DATA_DIR
    _write_pfm(tmp_path / "small.pfm", np.zeros((10, 10)))
    proc = subprocess.run([sys.executable, "-m", "stereodepth", "run", str(DATA_DIR / "motorcycle_left.png"),
                           str(DATA_DIR / "motorcycle_right.png"), "--small", "--out", str(tmp_path / "out"),
                           "--ground-truth", str(tmp_path / "small.pfm")], capture_output=True, text=True)
    assert proc.returncode == 2
    assert len(proc.stderr.strip().splitlines()) == 1 and "ground truth" in proc.stderr
    assert not (tmp_path / "out" / "result.json").exists()
