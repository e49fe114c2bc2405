"""Equation 2.1 against the thesis's own numbers: table 4.2 (spec.md) and the distances of section 3.3."""

import numpy as np
import pytest

from golden.software.distance import (BOARD_CAMERAS, PRINTED_WEBCAM_PITCH_M, WEBCAM_CAMERAS, CameraParameters,
                                      disparity_from_distance, distance_from_disparity, table_4_2_rounding)

# thesis table 4.2 / spec.md "Reference numbers to reproduce"
TABLE_4_2_Z_M = np.arange(1, 13) * 0.25
TABLE_4_2_CALCULATED = np.array([109, 54, 36, 27, 22, 18, 15, 13, 12, 11, 10, 9])
TABLE_4_2_OBSERVED = np.array([111, 51, 31, 22, 15, 12, 8, 7, 6, 4, 3, 2])


def test_board_cameras_are_the_thesis_values():
    assert BOARD_CAMERAS.baseline_m == 0.063
    assert BOARD_CAMERAS.focal_length_m == 3.81e-3
    assert BOARD_CAMERAS.pixel_pitch_m == pytest.approx(8.8e-6, rel=1e-12)     # 2.2 um x 4


def test_table_4_2_calculated_column_is_reproduced_from_equation_2_1():
    exact = disparity_from_distance(TABLE_4_2_Z_M, BOARD_CAMERAS)
    assert exact[0] == pytest.approx(0.063 * 3.81e-3 / (0.25 * 8.8e-6))
    assert np.array_equal(table_4_2_rounding(exact), TABLE_4_2_CALCULATED)
    assert np.abs(exact - TABLE_4_2_CALCULATED).max() < 0.65


def test_no_standard_rounding_reproduces_table_4_2():
    """The rounding rule is not a choice among equals: nearest, floor and ceil each miss three entries."""
    exact = disparity_from_distance(TABLE_4_2_Z_M, BOARD_CAMERAS)
    misses = {name: list(TABLE_4_2_Z_M[fn(exact).astype(int) != TABLE_4_2_CALCULATED])
              for name, fn in (("nearest", np.rint), ("floor", np.floor), ("ceil", np.ceil))}
    assert misses["nearest"] == [0.5, 1.75, 2.0]
    assert misses["floor"] == [1.25, 2.5, 2.75]
    assert len(misses["ceil"]) >= 3


def test_observed_column_is_within_the_thesis_tolerance_of_8_pixels():
    """Thesis 4.6.7: observed and calculated 'have no difference bigger than 8 pixels' (the largest is 7)."""
    exact = table_4_2_rounding(disparity_from_distance(TABLE_4_2_Z_M, BOARD_CAMERAS))
    assert np.abs(exact - TABLE_4_2_OBSERVED).max() == 7


def test_distance_inverts_equation_2_1_and_marks_zero_and_no_data():
    d = np.array([109, 27, 9, 0, -1])
    z = distance_from_disparity(d, BOARD_CAMERAS)
    assert z[:3] == pytest.approx(0.063 * 3.81e-3 / (d[:3] * 8.8e-6))
    assert z[2] == pytest.approx(3.0, abs=0.04)        # 9 pixels ~ 3 m (table 4.2)
    assert np.isposinf(z[3]) and np.isnan(z[4])
    assert distance_from_disparity(27, BOARD_CAMERAS) == pytest.approx(1.0, abs=0.02)


def test_webcam_pitch_as_printed_contradicts_the_thesis_results_and_the_one_used_does_not():
    """Thesis 3.3: 'the pixel dimensions is calculated as 0.041 cm'; its distance map shows the armchair at
    250-320 cm and the far field at about 5 m."""
    printed = CameraParameters(WEBCAM_CAMERAS.baseline_m, WEBCAM_CAMERAS.focal_length_m, PRINTED_WEBCAM_PITCH_M)
    # literally, disparity 1 (the smallest non-zero) is already nearer than the armchair
    assert distance_from_disparity(1, printed) < 1.5 < 2.5
    # the value used maps 2.5-5 m onto disparities a 640-pixel-wide search can find
    d = disparity_from_distance(np.array([2.5, 3.2, 5.0]), WEBCAM_CAMERAS)
    assert 20 < d.min() and d.max() < 64
    assert WEBCAM_CAMERAS.baseline_m == 0.15 and WEBCAM_CAMERAS.focal_length_m == 3.85e-3


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf")])
def test_camera_parameters_must_be_positive_lengths(bad):
    with pytest.raises(ValueError):
        CameraParameters(bad, 1e-3, 1e-6)
    with pytest.raises(ValueError):
        CameraParameters(0.1, 1e-3, bad)
