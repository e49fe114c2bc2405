"""The thesis's software pipeline (chapter 3, appendix A) in NumPy; see docs/software.md.

harris   - Harris corner detector (3.1.1)
ssd      - SSD matching of corner neighbourhoods (eq. 3.13)
rectify  - the tangent (slope) method: vertical shift between the images (3.1.2, appendix A)
sad      - shift-and-subtract cost, SAD window aggregation (eq. 3.16), winner-take-all disparity (3.2)
distance - Z = B f / (d * pixel pitch) (eq. 2.1) with the thesis's camera parameters (3.3, 4.6.7)
pipeline - the whole flow of figure 3.8

The names below are imported on first use, so importing one light module (e.g. ``distance``) does not load
SciPy; this keeps the command line's input checks fast.
"""

import importlib

_EXPORTS = {
    "BOARD_CAMERAS": "distance", "WEBCAM_CAMERAS": "distance", "CameraParameters": "distance",
    "distance_from_disparity": "distance", "DepthResult": "pipeline", "depth_pipeline": "pipeline",
    "estimate_vertical_shift": "pipeline", "to_grey": "pipeline", "vertical_shift": "rectify",
    "sad_disparity": "sad",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name):
    if name in _EXPORTS:
        return getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + __all__)
