"""The cameras and the frame buffers: sensor size, the downscale into the buffers (thesis 4.2, 4.2.1; spec
"Camera driver") and the stereo rig's optics (the distance of a disparity)."""

from dataclasses import dataclass, replace

__all__ = ["SensorGeometry", "DOWNSCALES", "SENSOR", "SENSOR_800", "SMALL_SENSOR", "SMALL_SENSOR_800",
           "VMODCAM_RIG", "disparity_of_distance", "ROW_TAG_BITS", "SENSOR_FPS"]

#: How a ``scale`` x ``scale`` sensor block becomes one buffer pixel (docs/capture.md, "Downscale and grey"):
#: ``"keep"`` the pixel at (scale i, scale j), the thesis's capture (5-bit grey); ``"average"`` the mean of the
#: block (8-bit grey).
DOWNSCALES = ("keep", "average")


@dataclass(frozen=True)
class SensorGeometry:
    """Sensor output size and the downscale into the frame buffer.

    ``downscale = "keep"`` (the thesis): the capture keeps the pixel at (``scale``*i, ``scale``*j) of each
    ``scale`` x ``scale`` block (thesis figure 4.4) and converts it to ``grey_bits`` (5) of grey;
    ``downscale = "average"``: the buffer pixel is the rounded mean grey of the whole block, ``grey_bits`` (8)
    wide (docs/capture.md, "The averaging capture"). Either way it is written at
    ``A = y * buf_width + x`` (eq. 4.1).
    """
    width: int = 1600
    height: int = 1200
    scale: int = 4
    grey_bits: int = 5
    downscale: str = "keep"

    def __post_init__(self):
        if self.downscale not in DOWNSCALES:
            raise ValueError(f"downscale must be one of {', '.join(DOWNSCALES)}, not {self.downscale!r}")

    @property
    def buf_width(self):
        return self.width // self.scale

    @property
    def buf_height(self):
        return self.height // self.scale

    @property
    def buf_depth(self):
        return self.buf_width * self.buf_height

    @property
    def addr_bits(self):
        return max(1, (self.buf_depth - 1).bit_length())


#: Width of a buffer row's frame tag: the capture's frame count mod 2**ROW_TAG_BITS of the camera frame that
#: last started writing the row (docs/capture.md, "Consistency at the tear").
ROW_TAG_BITS = 4

#: The sensors' frame rate at 1600 x 1200 (VmodCAM: two MT9D112, 1600 x 1200 at 15 frames a second): the rate at
#: which a new camera-frame pair comes, so the depth maps' rate to keep up with.
SENSOR_FPS = 15

#: The VmodCAM's MT9D112 at full resolution -> 400 x 300 x 5-bit buffers (2 x 120,000 words).
SENSOR = SensorGeometry()
#: The 800 x 600 build: each buffer pixel the mean of its 2 x 2 sensor block, 8-bit grey (2 x 480,000 words).
SENSOR_800 = SensorGeometry(scale=2, grey_bits=8, downscale="average")
#: A small sensor for fast tests: 64 x 48 -> 16 x 12 buffers.
SMALL_SENSOR = SensorGeometry(width=64, height=48)
#: The 800 x 600 build's capture on the small sensor: SENSOR_800's 8-bit 2 x 2 means, 64 x 48 -> 32 x 24 buffers.
SMALL_SENSOR_800 = replace(SENSOR_800, width=SMALL_SENSOR.width, height=SMALL_SENSOR.height)


class VMODCAM_RIG:
    """The stereo rig's optics, the numbers the test bed uses (sim/scene.py): baseline 6.3 cm (VmodCAM reference
    manual: 63 mm camera spacing), focal length 3.81 mm (thesis 4.6.7), 2.2 um sensor pixels (MT9D112)."""
    BASELINE_M = 0.063
    FOCAL_M = 3.81e-3
    PIXEL_M = 2.2e-6


def disparity_of_distance(distance_m, geometry=SENSOR):
    """The buffer-pixel disparity of a point at ``distance_m``: d = B f / (Z p s), ``s`` = the buffer's scale
    (p s = 4 x 2.2 um for the 400 x 300 buffers). Its inverse gives the distance of a disparity."""
    return VMODCAM_RIG.BASELINE_M * VMODCAM_RIG.FOCAL_M / (distance_m * VMODCAM_RIG.PIXEL_M * geometry.scale)
