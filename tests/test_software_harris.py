"""Harris detector (thesis 3.1.1) against OpenCV and against synthetic scenes with known corners."""

import cv2
import numpy as np
import pytest

from golden.software.harris import gradients, harris_corners, harris_response
from test_software_scenes import texture


def test_gradients_are_the_minus1_0_1_kernel_of_opencv_sobel_ksize_1():
    img = texture(40, 50, 11).astype(np.float64)
    ix, iy = gradients(img)
    assert np.array_equal(ix, cv2.Sobel(img, cv2.CV_64F, 1, 0, ksize=1))    # BORDER_REFLECT_101 both
    assert np.array_equal(iy, cv2.Sobel(img, cv2.CV_64F, 0, 1, ksize=1))
    assert ix[5, 7] == img[5, 8] - img[5, 6] and iy[5, 7] == img[6, 7] - img[4, 7]


@pytest.mark.parametrize("block", [3, 5, 7])
def test_binary_window_response_equals_opencv_corner_harris(block):
    """The thesis's "binary" window W is OpenCV's cornerHarris box; with ksize=1 OpenCV's gradient is
    (-1, 0, 1) scaled by 1/block, so its R is ours / block^4 (float32 inside OpenCV)."""
    img = texture(60, 80, 3).astype(np.float32)
    ours = harris_response(img.astype(np.float64), k=0.04, window="box", box_size=block)
    theirs = cv2.cornerHarris(img, block, 1, 0.04).astype(np.float64) * block ** 4
    assert np.abs(ours - theirs).max() <= 1e-5 * np.abs(ours).max()


def test_gaussian_window_response_equals_opencv_built_response():
    """R = det - k tr^2 of Gaussian-smoothed gradient products, built from OpenCV's Sobel and GaussianBlur."""
    img = texture(60, 80, 4).astype(np.float64)
    sigma, k = 1.5, 0.04
    radius = int(4 * sigma + 0.5)                    # the same 4-sigma truncation
    ix = cv2.Sobel(img, cv2.CV_64F, 1, 0, ksize=1)
    iy = cv2.Sobel(img, cv2.CV_64F, 0, 1, ksize=1)

    def blur(a):
        return cv2.GaussianBlur(a, (2 * radius + 1, 2 * radius + 1), sigma, borderType=cv2.BORDER_REFLECT_101)

    sxx, syy, sxy = blur(ix * ix), blur(iy * iy), blur(ix * iy)
    expected = sxx * syy - sxy ** 2 - k * (sxx + syy) ** 2
    ours = harris_response(img, k=k, sigma=sigma)
    assert np.abs(ours - expected).max() <= 1e-12 * np.abs(ours).max()


def test_corners_of_a_square_are_found_at_its_four_corners():
    img = np.zeros((60, 70))
    img[20:40, 25:50] = 200.0                         # corner pixels (20,25) (20,49) (39,25) (39,49)
    found = harris_corners(img)
    assert len(found) == 4
    expected = np.array([[20, 25], [20, 49], [39, 25], [39, 49]])
    for corner in expected:
        assert np.abs(found - corner).max(axis=1).min() <= 1     # within one pixel (Gaussian sigma 1.5)
    # the response classes of figure 3.2(b): corner > 0, edge < 0, flat ~ 0
    r = harris_response(img)
    assert r[found[:, 0], found[:, 1]].min() > 0
    assert r[30, 25] < 0 and r[20, 37] < 0 and r[30, 37] == 0 and r[5, 5] == 0


@pytest.mark.parametrize("dy, dx", [(0, 5), (3, 0), (-2, 7), (4, -3)])
def test_corners_move_exactly_with_an_integer_shift_of_the_image(dy, dx):
    big = texture(160, 200, 21)
    a = big[30:130, 30:170]
    b = big[30 - dy:130 - dy, 30 - dx:170 - dx]        # b[y + dy, x + dx] = a[y, x]
    ca = harris_corners(a, max_corners=10_000, border=12)
    cb = harris_corners(b, max_corners=10_000, border=12)
    # away from the borders (where the mirrored outside differs) the corner sets are the same, shifted
    h, w = a.shape
    inner = lambda c, oy, ox: c[(c[:, 0] + oy >= 20) & (c[:, 0] + oy < h - 20)
                                & (c[:, 1] + ox >= 20) & (c[:, 1] + ox < w - 20)]
    sa = {tuple(p) for p in inner(ca, dy, dx) + [dy, dx]}
    sb = {tuple(p) for p in inner(cb, 0, 0)}
    assert len(sa) > 30
    assert sa == sb


def test_threshold_non_maximum_suppression_and_limit():
    img = texture(120, 160, 5)
    r = harris_response(img)
    corners = harris_corners(img, quality_level=0.01, nms_radius=3, max_corners=10_000)
    values = r[corners[:, 0], corners[:, 1]]
    assert (values > 0.01 * r.max()).all()
    assert np.all(np.diff(values) <= 0)                         # strongest first
    for i, p in enumerate(corners):                             # each is the maximum of its 7x7 neighbourhood
        y, x = p
        assert r[y, x] == r[max(0, y - 3):y + 4, max(0, x - 3):x + 4].max()
        others = np.delete(corners, i, axis=0)
        assert np.abs(others - p).max(axis=1).min() > 0         # no duplicates
    # the suppression leaves no two strict maxima closer than the radius unless they tie exactly
    close = [(i, j) for i in range(len(corners)) for j in range(i + 1, len(corners))
             if np.abs(corners[i] - corners[j]).max() <= 3]
    assert all(values[i] == values[j] for i, j in close)
    assert len(harris_corners(img, max_corners=7)) == 7
    assert np.array_equal(harris_corners(img, max_corners=7), harris_corners(img, max_corners=10_000)[:7])
    assert len(harris_corners(np.full((30, 30), 9.0))) == 0    # flat image: no corner
