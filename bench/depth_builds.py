"""The thesis build against the 800 x 600 build (docs/depth.md, "Parameters"), on one scale: the table of bench
depth's first section.

Builds: the thesis's (``SENSOR``: keep one pixel of every 4 x 4 block, 5-bit, 400 x 300; ``DEPTH``: 64 disparities,
2 paths), the 800 x 600 one (``SENSOR_800``: the 8-bit mean of every 2 x 2 block; ``DEPTH_800``: 128
disparities, AD-census with Birchfield and Tomasi's symmetric term, the left-to-right and the top-right diagonal
paths, the left-right check, the separable 7 x 7 median) and, on the same buffers, the same engine without those quality options (``DEPTH_800_BASE``: two
paths, census alone, the 3 x 3 median) and what a third path would buy (``DEPTH_800_THREE``: the base with the
right-to-left path, beyond the board's budget, docs/depth.md). All from the golden models (golden/capture.py, golden/depth.py).
Beside each buffer size, OpenCV's StereoSGBM in its full 8-path mode (``STEREO_SGBM_MODE_HH``) on the same buffers
(8-bit: the thesis's 5-bit values shifted up by 3), with the same number of disparities.

Figures at the buffers, over every pixel with a ground truth, an invalid pixel counted bad, errors in 400-pixel
units (an 800 x 600 map's disparities halved) so that the builds compare on one scale: bad > 0.5 / 1 / 2 and the
density. The goals (motorcycle bad > 0.5 <= 17 %, bad > 1 <= 13.5 %, bad > 2 <= 11 %, density >= 97 %) are
checked for the 800 x 600 build.
"""

import dataclasses

import cv2
import numpy as np

from golden.capture import capture_frame
from golden.depth import depth_map
from spec.depth import DEPTH, DEPTH_800, DEPTH_800_BASE, DEPTH_800_THREE
from spec.sensor import SENSOR, SENSOR_800
from sim.analysis.truth import error_figures, motorcycle_truth, scene_truth

__all__ = ["Build", "BUILDS", "GOALS", "pairs", "engine", "sgbm_hh", "builds_table", "goal_lines"]


@dataclasses.dataclass(frozen=True)
class Build:
    name: str
    geometry: object
    config: object

    @property
    def to_400(self):
        """Factor from this build's buffer pixels to 400-pixel units."""
        return self.geometry.scale / SENSOR.scale


BUILDS = (Build("thesis: 400 x 300, 5-bit, one pixel kept; D 64, 2 paths", SENSOR, DEPTH),
          Build("800 x 600, 8-bit 2 x 2 mean; D 128, AD-census (Birchfield-Tomasi), 2 paths (one diagonal), "
                "left-right check, 7 x 7 median", SENSOR_800, DEPTH_800),
          Build("800 x 600 without the quality options: census, 2 paths, 3 x 3 median", SENSOR_800, DEPTH_800_BASE),
          Build("800 x 600 base with a third path (beyond the budget)", SENSOR_800, DEPTH_800_THREE))
#: The 800 x 600 build's goals, motorcycle: (bad > 0.5, bad > 1, bad > 2) at most, density at least (fractions).
GOALS = ((0.17, 0.135, 0.11), 0.97)


def pairs(build):
    """[(name, left, right, truth in 400-pixel units)] of ``build``: the motorcycle (right view) and the synthetic
    scenes of bench depth, each captured by the golden model of the build's capture."""
    from bench.bench_depth import synthetic_scenes
    from golden.stereo_pair import load_default_pair
    from sim.testbed.scene import render_pair
    g = build.geometry
    left_rgb, right_rgb = load_default_pair(g.width, g.height)
    out = [("motorcycle", capture_frame(left_rgb, g), capture_frame(right_rgb, g),
            motorcycle_truth("right", g) * build.to_400)]
    scenes, rig = synthetic_scenes()
    for name, scene in scenes.items():
        l_rgb, r_rgb = render_pair(scene, rig)
        out.append((name.split(" (")[0], capture_frame(l_rgb, g), capture_frame(r_rgb, g),
                    scene_truth(scene, rig, g) * build.to_400))
    return out


def engine(build, left, right, config=None):
    """The golden engine's map in 400-pixel units and its validity."""
    config = config or build.config
    codes = depth_map(left, right, config)
    return codes.astype(np.float64) / config.fraction * build.to_400, codes != config.invalid


def sgbm_hh(build, left, right):
    """OpenCV StereoSGBM, full 8-path mode, on the build's buffers as 8 bits, right image as reference (run on the
    mirrored pair), D disparities; in 400-pixel units."""
    block = 5
    matcher = cv2.StereoSGBM_create(minDisparity=0, numDisparities=build.config.disparities, blockSize=block,
                                    P1=8 * block * block, P2=32 * block * block, disp12MaxDiff=1, preFilterCap=63,
                                    uniquenessRatio=10, speckleWindowSize=100, speckleRange=2,
                                    mode=cv2.STEREO_SGBM_MODE_HH)
    shift = 8 - build.geometry.grey_bits
    raw = matcher.compute(np.ascontiguousarray((right[:, ::-1].astype(np.int64) << shift).astype(np.uint8)),
                          np.ascontiguousarray((left[:, ::-1].astype(np.int64) << shift).astype(np.uint8)))[:, ::-1]
    return raw / 16.0 * build.to_400, raw >= 0


def _cells(figures):
    b05, b1, b2, _, density = figures
    return f"{100 * b05:.1f} / {100 * b1:.1f} / {100 * b2:.1f} | {100 * density:.1f}"


def builds_table(pairs_of_build):
    """Markdown lines of the table and {(build name, pair name, method): figures}; ``pairs_of_build``: {build:
    :func:`pairs` of it}."""
    lines = ["### The thesis build and the 800 x 600 build (golden models; errors in 400-pixel units, invalid "
             "counted bad)", "", "| pair | build | method | bad > 0.5 / 1 / 2 % | density % |", "|---|---|---|---|---|"]
    results = {}
    names = [p[0] for p in next(iter(pairs_of_build.values()))]
    for index, pair_name in enumerate(names):
        peers = set()               # SGBM once per buffer size and D
        for build, build_pairs in pairs_of_build.items():
            _, left, right, truth = build_pairs[index]
            methods = [("depth engine (golden)", engine)]
            if (build.geometry, build.config.disparities) not in peers:
                peers.add((build.geometry, build.config.disparities))
                methods.append(("OpenCV StereoSGBM HH, 8 paths", sgbm_hh))
            for method, run in methods:
                figures = error_figures(*run(build, left, right), truth)
                results[(build.name, pair_name, method)] = figures
                lines.append(f"| {pair_name} | {build.name} | {method} | {_cells(figures)} |")
    return lines + [""], results


def goal_lines(results):
    """Whether the 800 x 600 build meets the goals on the motorcycle, and whether a synthetic scene got worse
    than the thesis build (bad > 2)."""
    (g05, g1, g2), g_density = GOALS
    lines, verdicts = [], {}
    for build in BUILDS[1:2]:
        b05, b1, b2, _, density = results[(build.name, "motorcycle", "depth engine (golden)")]
        verdicts[build] = b05 <= g05 and b1 <= g1 and b2 <= g2 and density >= g_density
        lines.append(f"Goals (motorcycle, {build.name}): bad > 0.5 {100 * b05:.1f} <= {100 * g05:.1f} %, bad > 1 "
                     f"{100 * b1:.1f} <= {100 * g1:.1f} %, bad > 2 {100 * b2:.1f} <= {100 * g2:.1f} %, density "
                     f"{100 * density:.1f} >= {100 * g_density:.1f} %: {'met' if verdicts[build] else 'NOT met'}.")
        worse = [pair for (name, pair, method), f in results.items()
                 if name == build.name and pair != "motorcycle" and method == "depth engine (golden)"
                 and f[2] > results[(BUILDS[0].name, pair, method)][2]]
        lines.append("Synthetic scenes with bad > 2 worse than the thesis build: " + (", ".join(worse) or "none")
                     + ".")
    return lines + [""], verdicts[BUILDS[1]]
