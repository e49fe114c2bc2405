"""Harris corner detector as the thesis describes it (section 3.1.1, equations 3.1-3.12).

    Ix = G^x (x) I,  Iy = G^y (x) I           G^x = (-1, 0, 1), G^y = G^x transposed    (3.1-3.4)
    Ixx = Ix Ix,  Iyy = Iy Iy,  Ixy = Ix Iy                                               (3.5-3.7)
    Sxx = W (x) Ixx, Syy = W (x) Iyy, Sxy = W (x) Ixy   W: Gaussian (thesis) or binary   (3.8-3.10)
    H = [[Sxx, Sxy], [Sxy, Syy]],   R = det(H) - k tr(H)^2                               (3.11-3.12)

then a threshold on R and non-maximum suppression. The thesis leaves the numbers open; the defaults here
(documented in docs/software.md) are those of Harris & Stephens (k = 0.04) and of Matlab's ``corner``
(Gaussian sigma 1.5, quality level 0.01 of the strongest response), since the thesis's model ran in Matlab.

Whether the gradient kernel is applied as a convolution or a correlation only flips the sign of Ix and Iy;
every product in H has two such factors, so R is the same either way. Here Ix(y, x) = I(y, x+1) - I(y, x-1).
Image borders are mirrored without repeating the edge pixel (scipy ``mirror`` = OpenCV BORDER_REFLECT_101).
Coordinates are (row, column) integer pixel positions.
"""

import numpy as np
from scipy import ndimage

__all__ = ["HARRIS_K", "WINDOW_SIGMA", "QUALITY_LEVEL", "NMS_RADIUS", "MAX_CORNERS",
           "gradients", "structure_tensor", "harris_response", "harris_corners"]

HARRIS_K = 0.04          # Harris & Stephens 1988; Matlab corner() default
WINDOW_SIGMA = 1.5       # Gaussian window W; Matlab corner() default filter sigma
QUALITY_LEVEL = 0.01     # keep R > QUALITY_LEVEL * max(R); Matlab corner() default
NMS_RADIUS = 2           # a corner is the maximum of R in its (2r+1) x (2r+1) neighbourhood
MAX_CORNERS = 500        # strongest corners kept per image (the tangent matrices are N x N)

_BORDER = "mirror"


def gradients(image):
    """(Ix, Iy): the image correlated with (-1, 0, 1) along columns and along rows (eq. 3.1-3.4)."""
    image = np.asarray(image, dtype=np.float64)
    kernel = np.array([-1.0, 0.0, 1.0])
    ix = ndimage.correlate1d(image, kernel, axis=1, mode=_BORDER)
    iy = ndimage.correlate1d(image, kernel, axis=0, mode=_BORDER)
    return ix, iy


def _window(values, window, sigma, box_size):
    if window == "gaussian":
        return ndimage.gaussian_filter(values, sigma, mode=_BORDER, truncate=4.0)
    if window == "box":
        # binary window W: the plain sum over box_size x box_size pixels
        return ndimage.uniform_filter(values, box_size, mode=_BORDER) * (box_size * box_size)
    raise ValueError(f"window must be 'gaussian' or 'box', not {window!r}")


def structure_tensor(image, sigma=WINDOW_SIGMA, window="gaussian", box_size=5):
    """(Sxx, Syy, Sxy) of eq. 3.8-3.10: the gradient products smoothed by the window W.

    ``window="gaussian"`` (the thesis's choice) uses a Gaussian of standard deviation ``sigma``, truncated at
    4 sigma; ``window="box"`` (the thesis's "binary" alternative) sums over ``box_size`` x ``box_size``.
    """
    ix, iy = gradients(image)
    return (_window(ix * ix, window, sigma, box_size),
            _window(iy * iy, window, sigma, box_size),
            _window(ix * iy, window, sigma, box_size))


def harris_response(image, k=HARRIS_K, sigma=WINDOW_SIGMA, window="gaussian", box_size=5):
    """The corner response R = det(H) - k tr(H)^2 (eq. 3.12) at every pixel."""
    sxx, syy, sxy = structure_tensor(image, sigma, window, box_size)
    return (sxx * syy - sxy * sxy) - k * (sxx + syy) ** 2


def harris_corners(image, k=HARRIS_K, sigma=WINDOW_SIGMA, quality_level=QUALITY_LEVEL,
                   nms_radius=NMS_RADIUS, max_corners=MAX_CORNERS, border=0, window="gaussian", box_size=5):
    """Corner positions, an (N, 2) int array of (row, column), strongest first.

    A pixel is a corner when R > 0, R > ``quality_level`` * max(R) (threshold) and R is the maximum of its
    (2 ``nms_radius`` + 1)^2 neighbourhood (non-maximum suppression). Corners closer than ``border`` pixels to
    the image edge are dropped. At most ``max_corners`` are kept; ties in R are ordered by row, then column.
    """
    if not 0 <= quality_level < 1:
        raise ValueError(f"quality_level must be in [0, 1), not {quality_level}")
    if nms_radius < 0 or max_corners < 1 or border < 0:
        raise ValueError("nms_radius and border must be >= 0 and max_corners >= 1")
    response = harris_response(image, k, sigma, window, box_size)
    peak = response.max()
    if peak <= 0:
        return np.zeros((0, 2), dtype=np.int64)
    local_max = ndimage.maximum_filter(response, size=2 * nms_radius + 1, mode="constant", cval=-np.inf)
    keep = (response == local_max) & (response > quality_level * peak) & (response > 0)
    if border:
        keep[:border, :] = keep[-border:, :] = False
        keep[:, :border] = keep[:, -border:] = False
    rows, cols = np.nonzero(keep)
    order = np.lexsort((cols, rows, -response[rows, cols]))[:max_corners]
    return np.stack([rows[order], cols[order]], axis=1).astype(np.int64)
