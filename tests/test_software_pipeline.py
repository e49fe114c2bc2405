"""The whole flow of thesis figure 3.8 on scenes with a known vertical shift and disparity."""

import numpy as np
import pytest
from skimage import data

from golden.software.distance import BOARD_CAMERAS, WEBCAM_CAMERAS
from golden.software.pipeline import depth_pipeline, to_grey
from golden.software.sad import sad_disparity
from test_software_scenes import plane_pair, two_plane_pair


def test_grey_is_matlab_rgb2gray():
    rgb = np.array([[[255, 0, 0], [0, 255, 0], [0, 0, 255], [10, 200, 30]]], dtype=np.uint8)
    assert to_grey(rgb).tolist() == [[76, 150, 29, 124]]       # rgb2gray: 76.22, 149.69, 29.07, 123.80
    assert to_grey(rgb[..., 0]).tolist() == [[255, 0, 0, 10]]  # already grey: unchanged


@pytest.mark.parametrize("shift, disparity", [(3, 11), (-5, 24), (0, 7), (6, 2)])
def test_plane_pair_gives_its_shift_disparity_and_distance_exactly(shift, disparity):
    window = 9
    left, right = plane_pair(100, 150, disparity, shift, seed=30 + shift)
    result = depth_pipeline(np.stack([left] * 3, axis=-1), np.stack([right] * 3, axis=-1),
                            max_disparity=32, window=window, camera=BOARD_CAMERAS)
    assert result.shift == shift
    h = left.shape[0]
    valid = np.arange(h) < h - shift if shift >= 0 else np.arange(h) >= -shift
    assert (result.disparity[~valid] == -1).all() and np.isnan(result.distance_m[~valid]).all()
    inner = result.disparity[valid][:, disparity + window // 2:]
    assert (inner == disparity).all()
    z = result.distance_m[valid][:, disparity + window // 2:]
    expected = 0.063 * 3.81e-3 / (disparity * 8.8e-6)
    assert np.allclose(z, expected, rtol=1e-12)


def test_two_plane_scene_with_vertical_offset():
    rect = (40, 110, 80, 160)
    left, right, truth = two_plane_pair(150, 220, 5, 21, rect, vertical_shift=-4)
    result = depth_pipeline(left, right, max_disparity=32, window=9, camera=WEBCAM_CAMERAS)
    assert result.shift == -4
    y0, y1, x0, x1 = rect
    # inside each plane, a window away from the depth edge, the occlusion and the no-data rows
    assert (result.disparity[y0 + 5:y1 - 5, x0 + 5:x1 - 5] == 21).all()
    assert (result.disparity[10:y0 - 5, 40:] == 5).all()
    assert (result.disparity[:4] == -1).all()
    # the nearer plane is nearer, by the ratio of the disparities
    ratio = result.distance_m[20, 100] / result.distance_m[70, 120]
    assert ratio == pytest.approx(21 / 5)
    assert result.distance_m[70, 120] == pytest.approx(0.15 * 3.85e-3 / (21 * 4.1e-6))


def test_without_rectification_a_vertical_offset_spoils_the_disparity():
    """Thesis figure 3.18: the same SAD without the found shift gives wrong disparities."""
    left, right = plane_pair(100, 150, 12, 3, seed=8)
    rectified = depth_pipeline(left, right, max_disparity=32, window=9)
    unrectified = depth_pipeline(left, right, max_disparity=32, window=9, shift=0)
    area = (slice(10, 90), slice(30, 150))
    assert (rectified.disparity[area] == 12).all()
    assert (unrectified.disparity[area] != 12).mean() > 0.5


def test_pipeline_rejects_pairs_of_different_size_and_impossible_shifts():
    a = np.zeros((30, 40), dtype=np.uint8)
    with pytest.raises(ValueError):
        depth_pipeline(a, a[:, :30], max_disparity=5, window=3)
    with pytest.raises(ValueError):
        depth_pipeline(a, a, max_disparity=5, window=3, shift=30)
    with pytest.raises(ValueError, match="too little texture"):
        depth_pipeline(a, a, max_disparity=5, window=3)


@pytest.mark.slow
def test_motorcycle_shifted_by_3_rows_gives_the_disparity_of_the_aligned_pair():
    left, right, _ = data.stereo_motorcycle()
    left, right = to_grey(left), to_grey(right)
    h, m, s, window = left.shape[0], 6, 3, 15
    result = depth_pipeline(left[m:h - m], right[m - s:h - m - s], max_disparity=63, window=window)
    assert result.shift == s
    aligned = sad_disparity(left[m:h - m], right[m:h - m], max_disparity=63, window=window)
    rows = slice(0, h - 2 * m - s - window)          # away from the no-data rows at the bottom
    assert np.array_equal(result.disparity[rows], aligned[rows])
