"""The thesis's software pipeline (chapter 3, appendix A) in NumPy; see docs/software.md.

harris   - Harris corner detector (3.1.1)
ssd      - SSD matching of corner neighbourhoods (eq. 3.13)
rectify  - the tangent (slope) method: vertical shift between the images (3.1.2, appendix A)
sad      - shift-and-subtract cost, SAD window aggregation (eq. 3.16), winner-take-all disparity (3.2)
distance - Z = B f / (d * pixel pitch) (eq. 2.1) with the thesis's camera parameters (3.3, 4.6.7)
pipeline - the whole flow of figure 3.8
"""

from .distance import BOARD_CAMERAS, WEBCAM_CAMERAS, CameraParameters, distance_from_disparity
from .pipeline import DepthResult, depth_pipeline, estimate_vertical_shift, to_grey
from .rectify import vertical_shift
from .sad import sad_disparity

__all__ = ["BOARD_CAMERAS", "WEBCAM_CAMERAS", "CameraParameters", "distance_from_disparity", "DepthResult",
           "depth_pipeline", "estimate_vertical_shift", "to_grey", "vertical_shift", "sad_disparity"]
