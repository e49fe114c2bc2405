"""The test-bed experiment (sim/testbed/experiment.py, stereodepth testbed): found disparities against table 4.2 and
the 1/16-downscale bound, the rectification search, the near field of thesis 4.6.6, the fits of the observed
column re-simulated, the RTL against the golden sweep, and the command line."""

import csv
import math
import subprocess
import sys

import numpy as np
import pytest
from PIL import Image

from sim.testbed import experiment as tb
from spec.display import DIFF_THRESHOLDS
from sim.testbed.scene import VMODCAM, StereoRig, make_object, object_footprint, rectangle
from stereodepth.cli import main



@pytest.fixture(scope="module")
def table():
    """The table series with the thesis's rig (no misalignment), every thesis distance."""
    return tb.run_table()


# --- the bound ----------------------------------------------------------------------------------------------

def test_found_disparities_match_the_calculated_column(table):
    """Zero misalignment: every minimising register value is floor(D) or ceil(D) (D = B f / Z / 8.8 um,
    docs/testbed.md), so the found disparity is within 1 of the thesis's calculated column, which is D
    rounded one way or the other."""
    assert [p.distance_m for p in table] == list(tb.THESIS_DISTANCES_M)
    for p, calculated in zip(table, tb.THESIS_CALCULATED_PX):
        d = 0.063 * 3.81e-3 / (p.distance_m * 4 * 2.2e-6)        # equation 2.1, written out again
        assert abs(calculated - d) < 1                            # the thesis column is D rounded
        lo, hi = p.plateau
        assert math.floor(d) <= lo <= p.found <= hi <= math.ceil(d), (p.distance_m, p.plateau, d)
        assert abs(p.found - calculated) <= 1, (p.distance_m, p.found, calculated)
        assert p.alignment.rectification == 0
        assert p.alignment.disparity_sweep.minimum == 0 or hi > lo  # it really disappears (or two tie)
        # A real minimum: two steps away the object's edges show.
        residual = p.alignment.disparity_sweep.residual
        assert residual[max(0, lo - 2)] > residual[lo] and residual[min(127, hi + 2)] > residual[hi]


def test_table_object_follows_the_common_field():
    """The 19 cm rectangle is used wherever it fits the common field; at 0.25 m (16.8 cm) the small one."""
    assert tb.table_object_name(0.25) == "small_rectangle"
    assert all(tb.table_object_name(z) == "rectangle" for z in tb.THESIS_DISTANCES_M[1:])


@pytest.mark.parametrize("distance, vertical, principal", [(1.0, 12, 0.0), (2.0, 14, 0.0), (1.5, 6, -32.0)])
def test_rectification_and_offsets_are_found(distance, vertical, principal):
    """A vertical misalignment of v sensor rows is undone by the rectification register at v/4 (buffer rows,
    floor or ceil); a principal-point offset of p pixels moves the disparity by p/4."""
    rig = StereoRig(vertical_offset_px=vertical, principal_offset_px=principal)
    p = tb.run_point(distance, "rectangle", rig)
    assert math.floor(vertical / 4) <= p.alignment.rectification <= math.ceil(vertical / 4)
    expected = 0.063 * 3.81e-3 / (distance * 8.8e-6) + principal / 4
    assert p.expected_px == pytest.approx(expected)
    assert math.floor(expected) <= p.plateau[0] <= p.plateau[1] <= math.ceil(expected)
    assert p.alignment.rectification_sweep.minimum < p.alignment.rectification_sweep.residual[0]


@pytest.mark.parametrize("vertical", [-20, 12])
def test_the_automatic_rectification_finds_an_offset_of_either_sign(vertical):
    """The vertical-offset estimator (golden model = RTL) on the edged card at 1 m: the rig's offset in buffer rows
    is in use after ``stable_frames`` (2) frames of the still scene; a blank pair keeps the reset's 0, held."""
    rig = StereoRig(vertical_offset_px=vertical)
    p = tb.run_point(1.0, "rectangle", rig, finish="edged")
    assert (p.auto.offset, p.auto.held, p.auto.lock_frames) == (vertical // 4, False, 2)
    blank = np.full((300, 400), 12, np.uint8)
    assert tb.auto_offset(blank, blank) == tb.AutoOffset(0, 0, True, 4)


def test_toe_in_lowers_the_disparity_like_an_offset():
    rig = StereoRig(convergence_deg=1.0)
    p = tb.run_point(2.0, "rectangle", rig, max_rectification=0)
    # Centre point: 2 F tan(atan(B / 2Z) - 0.5 deg) / 4, about F * 1 deg / 4 = 7.6 pixels less than D.
    f = 3.81e-3 / 2.2e-6
    expected = 2 * f * math.tan(math.atan(0.063 / 4.0) - math.radians(0.5)) / 4
    assert abs(p.found - expected) < 1.5 and p.found < tb.exact_disparity(2.0) - 6


# --- the residual and the sweep ---------------------------------------------------------------------------

def test_residual_is_the_sum_of_levels_over_the_region():
    """Hand-built buffers: a blob shifted by 7 columns and 2 rows; the residual per d is recomputed here with
    plain loops and the spec's threshold rule, independent of golden.disparity."""
    rng = np.random.default_rng(5)
    right = np.full((30, 40), 31, dtype=np.uint8)
    right[8:20, 5:18] = rng.integers(0, 20, (12, 13))
    left = np.full_like(right, 31)
    left[10:22, 12:25] = right[8:20, 5:18]
    footprint = right < 31
    curve = tb.disparity_curve(left, right, footprint, rectification=2, max_disparity=20)
    region = tb.sweep_region(footprint, 20, 2)
    assert region.sum() == footprint.sum() == curve.region_pixels
    for d in range(21):
        want = 0
        for y, x in zip(*np.nonzero(region)):
            diff = abs(int(left[y + 2, x + d]) - int(right[y, x]))
            want += sum(diff >= t for t in DIFF_THRESHOLDS)
        assert curve.residual[d] == want
    assert curve.found == 7 and curve.plateau == (7, 7) and curve.minimum == 0
    r_curve = tb.rectification_curve(left, right, footprint, 7, max_rectification=5)
    assert r_curve.found == 2
    alignment = tb.find_alignment(left, right, footprint, max_disparity=20, max_rectification=5)
    assert (alignment.disparity, alignment.rectification) == (7, 2)


def test_band_crop_gives_the_whole_frame_numbers():
    rig = StereoRig(vertical_offset_px=9)
    scene = rectangle(1.25)
    left, right = tb.capture_pair(scene, rig)
    footprint = object_footprint(scene, rig)
    for r in (0, 2):
        full = tb.disparity_curve(left, right, footprint, r, crop=False)
        assert np.array_equal(full.residual, tb.disparity_curve(left, right, footprint, r).residual)
    full = tb.rectification_curve(left, right, footprint, 22, crop=False)
    assert np.array_equal(full.residual, tb.rectification_curve(left, right, footprint, 22).residual)


# --- the near field (thesis 4.6.6) ------------------------------------------------------------------------

def test_near_field_behaves_as_the_thesis_describes():
    near = {p.object_name: p for p in tb.run_near_field(max_rectification=0)}
    d = tb.exact_disparity(0.25)
    # The 19 cm rectangle is wider than the 16.8 cm common field: no edge is seen by both cameras, every
    # disparity from where its left edge leaves the map to 127 makes it "disappear": no correct answer.
    big = near["rectangle"]
    assert VMODCAM.common_field_width_m(0.25) < 0.19
    assert big.plateau[1] - big.plateau[0] > 20 and abs(big.found - d) > 8
    # The circle (15.5 cm) fits, and so does the small rectangle: both found where eq. 2.1 says.
    for name in ("circle", "small_rectangle"):
        assert near[name].within_bound and near[name].plateau[1] - near[name].plateau[0] <= 1
    # Figure 4.33: at zero disparity the small rectangle's two images are completely separated.
    small = make_object("small_rectangle", 0.25)
    left_cols = np.flatnonzero(object_footprint(small, VMODCAM, "left").any(axis=0))
    right_cols = np.flatnonzero(object_footprint(small, VMODCAM, "right").any(axis=0))
    assert left_cols.min() > right_cols.max()
    big_left = np.flatnonzero(object_footprint(rectangle(0.25), VMODCAM, "left").any(axis=0))
    big_right = np.flatnonzero(object_footprint(rectangle(0.25), VMODCAM, "right").any(axis=0))
    assert big_left.min() <= big_right.max()


# --- explaining the observed column -----------------------------------------------------------------------

def test_fits_of_the_observed_column():
    z = np.array(tb.THESIS_DISTANCES_M)
    obs = np.array(tb.THESIS_OBSERVED_PX)
    d = tb.exact_disparity(z)
    offset = tb.fit_observed("offset")
    focal = tb.fit_observed("offset+focal")
    dist = tb.fit_observed("offset+distance")
    # Straight-line fit of observed against D, independently: slope = focal scale, intercept = -offset.
    slope, intercept = np.polyfit(d, obs, 1)
    assert focal.params["focal_scale"] == pytest.approx(slope)
    assert focal.params["offset_px"] == pytest.approx(-intercept)
    assert offset.params["offset_px"] == pytest.approx(np.mean(d - obs))
    assert np.allclose(dist.predicted, d * z / (z - dist.params["distance_offset_m"]) - dist.params["offset_px"])
    # A constant offset alone cannot explain the near field; one more parameter brings every distance
    # within about the observer's one-pixel resolution.
    assert offset.residual[0] > 5
    assert focal.rms < 0.6 and dist.rms < 0.7 and focal.max_abs < 1.1 and dist.max_abs < 1.1
    for fit in (offset, focal, dist):
        p = fit.params
        assert p["principal_offset_px"] == pytest.approx(-4 * p["offset_px"])
        # The toe-in that makes the same centre offset: 2 F tan(angle / 2) = 4 c.
        f = VMODCAM.focal_px * p.get("focal_scale", 1.0)
        assert 2 * f * math.tan(math.radians(p["convergence_deg"]) / 2) == pytest.approx(4 * p["offset_px"])


@pytest.mark.parametrize("model", ["offset+focal", "offset+distance"])
@pytest.mark.parametrize("index", [0, 3, 11])
def test_fitted_rig_reproduces_the_observed_values(model, index):
    """Render the test bed with the fitted rig: the found disparity is the thesis's observed one +-1."""
    fit = tb.fit_observed(model)
    rig, true_z = tb.fitted_rig_and_distance(fit)
    z = tb.THESIS_DISTANCES_M[index]
    p = tb.run_point(z, tb.table_object_name(z, rig), rig, object_distance_m=true_z(z), max_rectification=0)
    assert abs(p.found - tb.THESIS_OBSERVED_PX[index]) <= 1


# --- the RTL against the golden sweep -----------------------------------------------------------------------

def test_rtl_equals_the_golden_sweep_at_3m():
    """Every row of the object's region at 3 m through the RTL DisparitySubtractor (and two FrameBuffers) at
    the found disparity and one off it: bit for bit the golden levels, and the residual the sweep found."""
    scene = rectangle(3.0)
    left, right = tb.capture_pair(scene)
    footprint = object_footprint(scene)
    curve = tb.disparity_curve(left, right, footprint)
    checks = tb.rtl_crosscheck(left, right, footprint, [(curve.found, 0), (curve.found + 1, 0)])
    assert [c.mismatches for c in checks] == [0, 0]
    assert [c.rtl_residual for c in checks] == [curve.residual[curve.found], curve.residual[curve.found + 1]]
    assert checks[0].rtl_residual == 0 < checks[1].rtl_residual


def test_rtl_rows_with_rectification_and_no_data():
    """A few rows at 0.5 m with a vertical misalignment: shifted reads off the right edge (no data) and a
    non-zero rectification, through the RTL."""
    rig = StereoRig(vertical_offset_px=8)
    scene = rectangle(0.5)
    left, right = tb.capture_pair(scene, rig)
    footprint = object_footprint(scene, rig)
    checks = tb.rtl_crosscheck(left, right, footprint, [(54, 2), (120, 1)], rows=[150, 151])
    assert all(c.ok for c in checks)
    levels, no_data = tb.rtl_difference_rows(left, right, [(120, 1)], [151])[0]
    assert no_data[0, 280:].all() and not no_data[0, :280].any() and levels[0, 280:].max() == 0


# --- command line ---------------------------------------------------------------------------------------------

def _cli(*args):
    """The real command in a fresh interpreter (exit status, stdout, stderr)."""
    return subprocess.run([sys.executable, "-m", "stereodepth", "testbed", *args], capture_output=True, text=True)


@pytest.mark.parametrize("args, message", [
    (["--distances", "0.1"], "outside"),
    (["--distances", "1", "1"], "once"),
    (["--distances", "nan"], "outside"),
    (["--rtl-samples", "-1"], "--rtl-samples"),
    (["--supersample", "0"], "--supersample"),
    (["--max-rectification", "128"], "--max-rectification"),
    (["--vertical-offset", "1e9"], "--vertical-offset"),
])
def test_cli_bad_arguments(args, message, tmp_path, capsys):
    assert main(["testbed", "--out", str(tmp_path / "never"), *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err and err.startswith("stereodepth testbed: error:")
    assert not (tmp_path / "never").exists()


def test_cli_output_directory_is_a_file(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("x")
    result = _cli("--out", str(blocker / "sub"), "--distances", "1")
    assert result.returncode == 2 and result.stderr.count("\n") == 1 and "Traceback" not in result.stderr


def test_cli_small_run(tmp_path):
    out = tmp_path / "tb"
    result = _cli("--out", str(out), "--distances", "3", "1.5", "--rtl-samples", "1", "--no-fit",
                  "--max-rectification", "0", "--quiet")
    assert result.returncode == 0, result.stderr
    with open(out / "table.csv") as f:
        rows = list(csv.DictReader(f))
    assert [r["distance_m"] for r in rows] == ["1.50", "3.00"]
    assert "automatic rectification: offset +0 buffer rows in use at 2/2 distances" in result.stdout
    for r in rows:
        p = tb.run_point(float(r["distance_m"]), "rectangle", max_rectification=0)
        assert int(r["found_px"]) == p.found and r["within_bound"] == "yes"
        assert int(r["thesis_calculated_px"]) in (p.found - 1, p.found, p.found + 1)
        # The engine on the same pair: its readout, the distance it shows and the error against the truth.
        assert r["engine_readout"] == p.engine.readout.strip() and r["engine_readout"].endswith("cm")
        shown = int(r["engine_readout"][:-2]) / 100
        assert float(r["engine_shown_m"]) == shown
        assert abs(float(r["engine_error_pct"]) - 100 * (shown / p.engine.true_m - 1)) < 0.01
        assert abs(float(r["engine_disparity_px"]) - p.expected_px) < 1
        assert (int(r["auto_rectification"]), int(r["auto_lock_frames"]), r["auto_held"]) == \
            (p.auto.offset, p.auto.lock_frames, "yes" if p.auto.held else "no")
    with open(out / "rtl_check.csv") as f:
        rtl = list(csv.DictReader(f))
    assert len(rtl) == 1 and rtl[0]["bit_exact"] == "yes" and rtl[0]["mismatches"] == "0"
    assert rtl[0]["distance_m"] == "3.00" and int(rtl[0]["disparity"]) == int(rows[1]["found_px"])
    with open(out / "near_field.csv") as f:
        near = {r["object"]: r for r in csv.DictReader(f)}
    assert near["rectangle"]["fits_common_field"] == "no" and near["circle"]["fits_common_field"] == "yes"
    with open(out / "fits.csv") as f:
        assert [r["model"] for r in csv.DictReader(f)] == list(tb.FIT_MODELS)
    for name in ("figure_4_35.png", "disparity_maps.png", "near_field.png"):
        with Image.open(out / name) as image:
            assert image.format == "PNG" and min(image.size) > 300


# --- slow: the whole experiment -------------------------------------------------------------------------------

@pytest.mark.slow
@pytest.mark.parametrize("finish, supersample", [("edged", 1), ("textured", 1), ("solid", 2), ("textured", 3)])
def test_bound_holds_for_other_finishes_and_anti_aliasing(finish, supersample):
    for p in tb.run_table(supersample=supersample, finish=finish, max_rectification=0):
        assert p.within_bound, (finish, supersample, p.distance_m, p.plateau, p.expected_px)


@pytest.mark.slow
def test_cli_full_run(tmp_path):
    """The default command: 12 distances, near field, three fits re-simulated, 3 RTL samples."""
    out = tmp_path / "tb"
    result = _cli("--out", str(out), "--quiet")
    assert result.returncode == 0, result.stderr
    with open(out / "table.csv") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 12 and all(r["within_bound"] == "yes" for r in rows)
    for model in ("offset+focal", "offset+distance"):
        diffs = [int(r["thesis_observed_px"]) - int(r[f"resim_{model}_px"]) for r in rows]
        assert max(map(abs, diffs)) <= 1, (model, diffs)
    with open(out / "rtl_check.csv") as f:
        assert [r["bit_exact"] for r in csv.DictReader(f)] == ["yes"] * 3
