"""Distance from disparity, thesis equation 2.1: d = x - x' = B f / Z, so Z = B f / (d * pixel pitch).

B (baseline), f (focal length) and Z are lengths; the disparity on the sensor B f / Z becomes pixels by
dividing by the pixel pitch (thesis 4.6.7). Everything here is in metres.

Camera sets from the thesis:

* ``BOARD_CAMERAS`` (4.6.7, the project's VmodCAM on the Genesys board): B = 6.3 cm, f = 3.81 mm, pitch
  2.2 um x 4 = 8.8 um, because the 1600 x 1200 frames are kept as 400 x 300 (one pixel of each 4 x 4 block).
* ``WEBCAM_CAMERAS`` (3.3, the two USB webcams of the Matlab model, 640 x 480): B = 15 cm, f = 3.85 mm. The
  thesis prints the pixel size as "0.041 cm" (``PRINTED_WEBCAM_PITCH_M``). Taken literally that is 410 um:
  then Z = 15 cm * 3.85 mm / (d * 0.41 mm) = 1.41 m / d, so every pixel with a disparity of 1 or more would be
  nearer than 1.41 m, which contradicts the 2.5-5 m the thesis reports for the same images. We use 4.1 um
  (0.00041 cm), the printed digits read as micrometres: it puts 2.5-5 m at 56-28 pixels of disparity and is a
  usual pixel size for a 640 x 480 webcam sensor. Pass another pitch if you know it (docs/software.md).
"""

from dataclasses import dataclass

import numpy as np

__all__ = ["CameraParameters", "BOARD_CAMERAS", "WEBCAM_CAMERAS", "PRINTED_WEBCAM_PITCH_M",
           "disparity_from_distance", "distance_from_disparity", "table_4_2_rounding"]


@dataclass(frozen=True)
class CameraParameters:
    """A parallel stereo camera pair: baseline, focal length and pixel pitch, all in metres."""
    baseline_m: float
    focal_length_m: float
    pixel_pitch_m: float

    def __post_init__(self):
        for name in ("baseline_m", "focal_length_m", "pixel_pitch_m"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive finite length, not {value!r}")

    @property
    def focal_length_px(self):
        return self.focal_length_m / self.pixel_pitch_m


BOARD_CAMERAS = CameraParameters(baseline_m=0.063, focal_length_m=3.81e-3, pixel_pitch_m=2.2e-6 * 4)
PRINTED_WEBCAM_PITCH_M = 0.041e-2
WEBCAM_CAMERAS = CameraParameters(baseline_m=0.15, focal_length_m=3.85e-3, pixel_pitch_m=4.1e-6)


def disparity_from_distance(distance_m, camera=BOARD_CAMERAS):
    """Equation 2.1 in pixels: d = B f / (Z * pitch). Float, not rounded."""
    z = np.asarray(distance_m, dtype=np.float64)
    return camera.baseline_m * camera.focal_length_m / (z * camera.pixel_pitch_m)


def distance_from_disparity(disparity_px, camera=BOARD_CAMERAS):
    """Z = B f / (d * pitch) in metres; +inf where d == 0 (beyond the range), NaN where d < 0 (no data)."""
    d = np.asarray(disparity_px, dtype=np.float64)
    z = np.full(d.shape, np.nan)
    z[d == 0] = np.inf
    pos = d > 0
    z[pos] = camera.baseline_m * camera.focal_length_m / (d[pos] * camera.pixel_pitch_m)
    return z if z.ndim else float(z)


def table_4_2_rounding(disparity_px):
    """The rounding that turns eq. 2.1 into the "calculated" column of thesis table 4.2: up only from a
    fraction of 0.75, i.e. floor(d + 0.25). Neither round-to-nearest nor floor nor ceil reproduces all twelve
    entries (each misses three; tests/test_software_distance.py); any cut between 0.64 and 0.82 does."""
    return np.floor(np.asarray(disparity_px, dtype=np.float64) + 0.25).astype(np.int64)
