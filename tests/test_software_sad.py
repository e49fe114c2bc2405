"""Shift-and-subtract, SAD aggregation (eq. 3.16) and winner-take-all against their definitions, SciPy, and
synthetic scenes with a known disparity."""

import numpy as np
import pytest
from scipy import ndimage

from golden.software.sad import (SAD_WINDOWS, box_sum, sad_cost_volume, sad_disparity, shift_and_subtract,
                                 winner_take_all)
from test_software_scenes import plane_pair, texture, two_plane_pair


@pytest.mark.parametrize("window", [1, 2, 3, 4, 7, 9, 10])
def test_box_sum_equals_the_window_sum_by_loops(window):
    rng = np.random.default_rng(window)
    img = rng.integers(0, 256, size=(13, 17))
    got = box_sum(img, window)
    h, w = img.shape
    for y in range(h):
        for x in range(w):
            y0, x0 = y - window // 2, x - window // 2
            expected = img[max(0, y0):max(0, y0 + window), max(0, x0):max(0, x0 + window)].sum()
            assert got[y, x] == expected


@pytest.mark.parametrize("window", SAD_WINDOWS)
def test_box_sum_equals_scipy_uniform_filter_inside_the_image(window):
    img = texture(90, 110, 5).astype(np.int64)
    theirs = ndimage.uniform_filter(img.astype(np.float64), size=window) * window * window
    m = window // 2 + 1
    assert np.allclose(box_sum(img, window)[m:-m, m:-m], theirs[m:-m, m:-m], rtol=0, atol=1e-6)


def test_shift_and_subtract_and_cost_volume_follow_equation_3_16():
    left, right = texture(30, 40, 1), texture(30, 40, 2)
    c = shift_and_subtract(left, right, 6)
    assert c[4, 10] == abs(int(left[4, 10]) - int(right[4, 4]))
    assert c[4, 2] == abs(int(left[4, 2]) - int(right[4, 0]))       # right extended by its first column
    vol = sad_cost_volume(left, right, max_disparity=8, window=5)
    for d, y, x in [(0, 10, 10), (3, 15, 20), (8, 2, 30), (5, 29, 39)]:
        s = sum(abs(int(left[i, j]) - int(right[i, j - d]))
                for i in range(max(0, y - 2), min(30, y + 3)) for j in range(max(0, x - 2), min(40, x + 3)))
        assert vol[d, y, x] == s
    assert np.isinf(vol[8, :, :8]).all() and np.isfinite(vol[8, :, 8:]).all()


def test_streaming_wta_equals_argmin_of_the_whole_cost_volume():
    left, right = texture(40, 60, 3), texture(40, 60, 4)
    for window in (3, 8):
        expected = winner_take_all(sad_cost_volume(left, right, 12, window))
        assert np.array_equal(sad_disparity(left, right, 12, window), expected)


def test_ties_go_to_the_smallest_disparity():
    flat = np.full((20, 30), 77, dtype=np.uint8)
    assert (sad_disparity(flat, flat, 10, 5) == 0).all()


@pytest.mark.parametrize("window", SAD_WINDOWS)
@pytest.mark.parametrize("disparity", [0, 4, 13, 40])
def test_disparity_of_a_textured_plane_is_recovered_exactly(window, disparity):
    left, right = plane_pair(80, 160, disparity, 0, seed=disparity)
    d = sad_disparity(left, right, max_disparity=48, window=window)
    # where the whole window's right-image samples exist, the true disparity costs 0 and wins
    x0 = disparity + window // 2
    assert (d[:, x0:] == disparity).all()


@pytest.mark.parametrize("window", SAD_WINDOWS)
def test_two_plane_scene_is_recovered_away_from_the_depth_edge(window):
    rect = (40, 110, 80, 160)
    left, right, truth = two_plane_pair(150, 220, 5, 21, rect)
    d = sad_disparity(left, right, max_disparity=32, window=window)
    # pixels whose window lies inside one plane and sees no occluded pixel
    known = truth >= 0
    region = np.where(truth == 21, 1, np.where(truth == 5, 2, 0))
    half = window // 2
    pure = (ndimage.minimum_filter(region, size=window + 2, mode="nearest")
            == ndimage.maximum_filter(region, size=window + 2, mode="nearest")) & known
    pure[:, :21 + half + 1] = False
    assert pure[truth == 21].sum() > 500 and pure[truth == 5].sum() > 1000
    assert np.array_equal(d[pure], truth[pure])


def test_bad_arguments_are_rejected():
    a = texture(20, 30, 1)
    with pytest.raises(ValueError):
        sad_disparity(a, a[:, :20])
    with pytest.raises(ValueError):
        sad_disparity(a, a, max_disparity=30)
    with pytest.raises(ValueError):
        sad_disparity(a, a, max_disparity=5, window=0)
    with pytest.raises(ValueError):
        sad_disparity(np.zeros((4, 5, 3)), np.zeros((4, 5, 3)), max_disparity=2)
