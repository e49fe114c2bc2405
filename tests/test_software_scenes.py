"""Synthetic stereo scenes with a known truth for the software-pipeline tests (imported by the other
tests/test_software_*.py), and a check of that truth with a third-party method (scikit-image's phase
correlation), so the tests below rest on scenes that are what they claim to be.

Convention: a scene point at (row y, column x) of the left image is at (y + vertical_shift, x - disparity) of
the right image (left image = reference; positive vertical shift = the right image is lower).
"""

import numpy as np
import pytest
from scipy import ndimage
from skimage.registration import phase_cross_correlation


def texture(height, width, seed, blur=1.2):
    """Random blob texture, 8-bit, with plenty of corners and no repetition."""
    rng = np.random.default_rng(seed)
    noise = ndimage.gaussian_filter(rng.normal(size=(height, width)), blur)
    noise = (noise - noise.min()) / (noise.max() - noise.min())
    return np.rint(noise * 255).astype(np.uint8)


def plane_pair(height, width, disparity, vertical_shift, seed=1):
    """A textured fronto-parallel plane: the right image is the left one moved ``disparity`` columns left
    and ``vertical_shift`` rows down (exact integer shifts of one texture)."""
    m = 40
    canvas = texture(height + 2 * m, width + 2 * m + disparity, seed)
    left = canvas[m:m + height, m:m + width]
    right = canvas[m - vertical_shift:m - vertical_shift + height, m + disparity:m + disparity + width]
    return left, right


def two_plane_pair(height, width, d_back, d_front, rect, vertical_shift=0, seed=2):
    """A textured background plane at disparity ``d_back`` and, in front of it, a textured rectangle
    ``rect = (y0, y1, x0, x1)`` (left-image coordinates) at disparity ``d_front`` > ``d_back``.

    Returns ``(left, right, truth)``; ``truth`` is the left image's disparity, -1 where the left pixel is
    occluded in the right image (background hidden by the moved rectangle)."""
    y0, y1, x0, x1 = rect
    m = 40
    back = texture(height + 2 * m, width + 2 * m + d_front, seed)
    front = texture(height + 2 * m, width + 2 * m + d_front, seed + 100)
    rows = np.arange(-m, height + m)[:, None]      # scene rows, in left-image coordinates
    cols = np.arange(width + d_front + m)[None, :]
    in_rect = (rows >= y0) & (rows < y1) & (cols >= x0) & (cols < x1)

    def view(disp_shift_back, disp_shift_front, row_shift):
        # image pixel (y, x) shows scene column x + shift of its plane, scene row y - row_shift
        ys = np.arange(height)[:, None] - row_shift + m
        xs = np.arange(width)[None, :]
        fx = xs + disp_shift_front
        front_here = in_rect[ys, np.clip(fx, 0, in_rect.shape[1] - 1)] & (fx < in_rect.shape[1])
        return np.where(front_here, front[ys, fx % front.shape[1]],
                        back[ys, xs + disp_shift_back]).astype(np.uint8)

    left = view(0, 0, 0)
    right = view(d_back, d_front, vertical_shift)
    truth = np.full((height, width), d_back, dtype=np.int16)
    truth[y0:y1, x0:x1] = d_front
    # background pixels of the left image whose right-image position is covered by the moved rectangle
    gap = d_front - d_back
    truth[y0:y1, max(0, x0 - gap):x0] = -1
    return left, right, truth


@pytest.mark.parametrize("disparity, vertical_shift", [(0, 0), (7, 3), (20, -4), (1, 6)])
def test_plane_pair_truth_agrees_with_phase_correlation(disparity, vertical_shift):
    left, right = plane_pair(96, 128, disparity, vertical_shift)
    shift, _, _ = phase_cross_correlation(left.astype(float), right.astype(float))
    # phase correlation returns the shift that registers ``right`` onto ``left``: (-vertical, +disparity)
    assert tuple(shift) == (-vertical_shift, disparity)


def test_two_plane_pair_truth_agrees_with_phase_correlation_per_plane():
    left, right, truth = two_plane_pair(120, 160, 6, 18, (30, 90, 60, 120), vertical_shift=2)
    # the rectangle's own texture, cut from each image, registers at the front disparity...
    y0, y1, x0, x1 = 30, 90, 60, 120
    shift_front, _, _ = phase_cross_correlation(left[y0 + 5:y1 - 5, x0 + 5:x1 - 5].astype(float),
                                                right[y0 + 7:y1 - 3, x0 - 13:x1 - 23].astype(float))
    assert tuple(shift_front) == (0, 0)
    # ...and a background strip above the rectangle at the back disparity
    shift_back, _, _ = phase_cross_correlation(left[2:26, 20:150].astype(float),
                                               right[4:28, 14:144].astype(float))
    assert tuple(shift_back) == (0, 0)
    assert (truth[y0:y1, x0:x1] == 18).all() and (truth[:y0] == 6).all()
    assert (truth[y0:y1, x0 - 12:x0] == -1).all()
