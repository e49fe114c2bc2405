"""Synthetic test-bed scenes (thesis 4.6) seen by the VmodCAM's two pinhole cameras.

The thesis put flat cardboard shapes (a 19 cm rectangle, a 15.5 cm circle, a triangle) in front of a white
background at 0.25-3 m and looked for the disparity register value at which each shape "disappears" from
the difference image. This module renders that scene for the two sensors, exactly and deterministically,
so the experiment can be repeated in simulation (``sim/testbed/experiment.py``).

World frame (metres): origin midway between the two optical centres, X to the right, Y down, Z forward
(the viewing direction). Camera A (left) is at X = -baseline/2, camera B (right) at X = +baseline/2.

Projection (exact pinhole, no lens distortion). Sensor pixel column ``i``, row ``j`` covers the square
[i, i+1) x [j, j+1) in sensor-pixel units; with ``supersample = 1`` it takes the scene's colour at its
centre (i + 0.5, j + 0.5) (point sampling); with ``supersample = k`` it averages a k x k grid of points at
((s + 0.5) / k) inside the square and rounds half up to 8 bits (a box-filter anti-alias; deterministic).
A sample point (u, v) becomes the camera-frame ray ((u - cx) / F, (v - cy) / F, 1), F = focal / pixel pitch
(1731.8 px for 3.81 mm / 2.2 um). The principal points are split symmetrically around the sensor centre::

    cx_left  = W/2 + principal_offset_px/2      cx_right = W/2 - principal_offset_px/2
    cy_left  = H/2 + vertical_offset_px/2       cy_right = H/2 - vertical_offset_px/2

so a point's left-image column minus its right-image column is ``F * baseline / Z + principal_offset_px``
and its left-image row minus its right-image row is ``vertical_offset_px`` (the rectification register
undoes a positive vertical offset: the left read is at y + rectification). A toe-in (convergence) angle
yaws the left camera by +angle/2 (towards +X) and the right camera by -angle/2 about their vertical axes;
the ray is rotated and intersected with each object's plane Z = distance. The image is upright (row 0 at
the top, as the sensor reads it out).

Objects are planar, fronto-parallel, opaque; nearer objects hide farther ones; everything else is the white
background. Shapes are tested closed (a point on the outline is inside).
"""

import math
from dataclasses import dataclass, field

import numpy as np

from spec.sensor import SENSOR, VMODCAM_RIG

__all__ = [
    "StereoRig", "VMODCAM", "PlanarObject", "BACKGROUND_RGB", "RECTANGLE_SIZE_M", "CIRCLE_DIAMETER_M",
    "TRIANGLE_SIZE_M", "rectangle", "circle", "triangle", "small_rectangle", "make_object", "render_view",
    "render_pair", "object_footprint"
]

# --- The test objects (thesis 4.6; sizes the thesis does not give are this project's choice) ------------

#: The rectangle: 19 cm wide (thesis 4.6.6); its height is not given: 13 cm chosen (landscape card).
RECTANGLE_SIZE_M = (0.19, 0.13)
#: The circle: 15.5 cm across (thesis 4.6.6).
CIRCLE_DIAMETER_M = 0.155
#: The triangle: size not given in the thesis: isosceles, 17 cm base (bottom), 15 cm high, apex up (chosen).
TRIANGLE_SIZE_M = (0.17, 0.15)
#: The "small rectangle" of thesis figures 4.32-4.33 (size not given): 5 cm x 4 cm chosen. It fits the
#: common field of view at 0.25 m (16.8 cm wide there), and it is narrower than the 6.3 cm baseline, which
#: is what makes its two images "separated completely" at zero disparity (figure 4.33): an object of width
#: w at distance Z is F*w/Z pixels wide and its disparity is F*B/Z, so they separate iff w < B, at any Z.
SMALL_RECTANGLE_SIZE_M = (0.05, 0.04)

#: The white fabric background.
BACKGROUND_RGB = (255, 255, 255)
#: Default object colour: a dark blue card. Its 5-bit grey is 9 against the background's 31.
OBJECT_RGB = (30, 60, 150)

SHAPES = ("rectangle", "circle", "triangle")
#: solid: the colour everywhere; edged: a white card with a dark outline ``edge_m`` wide; textured: the
#: colour modulated per ``texel_m`` square by a fixed hash of the texel's index (a printed pattern).
FINISHES = ("solid", "edged", "textured")


@dataclass(frozen=True)
class StereoRig:
    """Two identical pinhole cameras side by side (the VmodCAM) and their misalignments.

    Defaults are the thesis's: baseline 6.3 cm (VmodCAM reference manual: 63 mm inter-camera spacing),
    f = 3.81 mm (thesis 4.6.7), 2.2 um pixels and 1600 x 1200 (MT9D112 datasheet), no misalignment.
    """
    baseline_m: float = VMODCAM_RIG.BASELINE_M
    focal_m: float = VMODCAM_RIG.FOCAL_M
    pixel_m: float = VMODCAM_RIG.PIXEL_M
    width: int = SENSOR.width
    height: int = SENSOR.height
    principal_offset_px: float = 0.0   # cx_left - cx_right, sensor pixels
    vertical_offset_px: float = 0.0    # cy_left - cy_right, sensor rows
    convergence_deg: float = 0.0       # total toe-in angle between the optical axes

    def __post_init__(self):
        for name in ("baseline_m", "focal_m", "pixel_m"):
            if not getattr(self, name) > 0:
                raise ValueError(f"{name} must be positive, not {getattr(self, name)!r}")
        if self.width < 1 or self.height < 1:
            raise ValueError(f"sensor size must be positive, not {self.width}x{self.height}")
        if not abs(self.convergence_deg) < 45:
            raise ValueError(f"convergence angle {self.convergence_deg} deg is not a small toe-in")

    @property
    def focal_px(self):
        """Focal length in sensor pixels (3.81 mm / 2.2 um = 1731.8)."""
        return self.focal_m / self.pixel_m

    def field_of_view_deg(self):
        """(horizontal, vertical, diagonal) full angles of view in degrees of the whole sensor."""
        half_w = self.width * self.pixel_m / 2
        half_h = self.height * self.pixel_m / 2
        return tuple(2 * math.degrees(math.atan(s / self.focal_m))
                     for s in (half_w, half_h, math.hypot(half_w, half_h)))

    def disparity_px(self, distance_m):
        """Sensor-pixel disparity (left column - right column) of a point at ``distance_m`` (no toe-in)."""
        return self.focal_px * self.baseline_m / distance_m + self.principal_offset_px

    def common_field_start_m(self):
        """Distance at which the two horizontal fields of view start to overlap (thesis: about 6.9 cm)."""
        half = math.tan(math.radians(self.field_of_view_deg()[0] / 2))
        return self.baseline_m / (2 * half)

    def common_field_width_m(self, distance_m):
        """Width of the region both cameras see at ``distance_m`` (thesis: about 17 cm at 25 cm)."""
        half = math.tan(math.radians(self.field_of_view_deg()[0] / 2))
        return max(0.0, 2 * distance_m * half - self.baseline_m)

    def camera(self, side):
        """(optical-centre X, cx, cy, yaw in radians) of ``side`` ("left" = camera A, "right" = camera B)."""
        sign = {"left": -1, "right": +1}.get(side)
        if sign is None:
            raise ValueError(f"camera side must be 'left' or 'right', not {side!r}")
        cx = self.width / 2 - sign * self.principal_offset_px / 2
        cy = self.height / 2 - sign * self.vertical_offset_px / 2
        yaw = -sign * math.radians(self.convergence_deg) / 2
        return sign * self.baseline_m / 2, cx, cy, yaw


#: The VmodCAM as the thesis describes it.
VMODCAM = StereoRig()


def _texel_grey(ix, iy):
    """A fixed pseudo-random factor in [0.25, 1] per texel index (integer hash; platform independent)."""
    h = (ix.astype(np.int64) * 73856093) ^ (iy.astype(np.int64) * 19349663)
    h = (h ^ (h >> 13)) * 1274126177
    h = h ^ (h >> 16)
    return 0.25 + 0.75 * ((h & 0xFF) / 255.0)


@dataclass(frozen=True)
class PlanarObject:
    """A flat shape facing the cameras at ``distance_m``, centred at (``centre_x_m``, ``centre_y_m``).

    ``size_m`` is (width, height) of its bounding box; a circle's is (diameter, diameter).
    """
    shape: str
    size_m: tuple
    distance_m: float
    centre_x_m: float = 0.0
    centre_y_m: float = 0.0
    finish: str = "solid"
    rgb: tuple = OBJECT_RGB
    edge_m: float = 0.01
    texel_m: float = 0.01
    name: str = field(default="", compare=False)

    def __post_init__(self):
        if self.shape not in SHAPES:
            raise ValueError(f"shape must be one of {', '.join(SHAPES)}, not {self.shape!r}")
        if self.finish not in FINISHES:
            raise ValueError(f"finish must be one of {', '.join(FINISHES)}, not {self.finish!r}")
        if not (self.distance_m > 0 and all(s > 0 for s in self.size_m)):
            raise ValueError(f"object distance and size must be positive ({self.distance_m}, {self.size_m})")
        if not self.name:
            object.__setattr__(self, "name", self.shape)

    def contains(self, x, y, inset=0.0):
        """Boolean mask of the points (``x``, ``y``) relative to the centre inside the shape shrunk by
        ``inset`` metres (the distance to every side is at least ``inset``)."""
        w, h = self.size_m
        if self.shape == "rectangle":
            return (np.abs(x) <= w / 2 - inset) & (np.abs(y) <= h / 2 - inset)
        if self.shape == "circle":
            r = w / 2 - inset
            return x * x + y * y <= r * r
        # Triangle: apex (0, -h/2), base from (-w/2, h/2) to (w/2, h/2); signed distances to the sides.
        side = math.hypot(w / 2, h)
        slant = (h * np.abs(x) - (w / 2) * (y + h / 2)) / side     # <= 0 inside both slanted sides
        return (y <= h / 2 - inset) & (slant <= -inset)

    def mask(self, X, Y):
        """Points of the object's plane (world X, Y) covered by the object."""
        return self.contains(X - self.centre_x_m, Y - self.centre_y_m)

    def colour(self, X, Y):
        """(..., 3) float RGB of the object at covered points (world X, Y)."""
        x, y = np.broadcast_arrays(X - self.centre_x_m, Y - self.centre_y_m)
        rgb = np.empty(x.shape + (3,))
        rgb[...] = self.rgb
        if self.finish == "edged":
            interior = self.contains(x, y, inset=self.edge_m)
            rgb[interior] = BACKGROUND_RGB
        elif self.finish == "textured":
            factor = _texel_grey(np.floor(x / self.texel_m), np.floor(y / self.texel_m))
            rgb *= factor[..., None]
        return rgb


def _object(shape, size, distance_m, **kw):
    return PlanarObject(shape=shape, size_m=tuple(size), distance_m=distance_m, **kw)


def rectangle(distance_m, **kw):
    """The thesis's 19 cm rectangle (13 cm high, chosen) at ``distance_m``."""
    return _object("rectangle", RECTANGLE_SIZE_M, distance_m, **kw)


def circle(distance_m, **kw):
    """The thesis's 15.5 cm circle at ``distance_m``."""
    return _object("circle", (CIRCLE_DIAMETER_M, CIRCLE_DIAMETER_M), distance_m, **kw)


def triangle(distance_m, **kw):
    """The triangle (17 cm base, 15 cm high, apex up: chosen) at ``distance_m``."""
    return _object("triangle", TRIANGLE_SIZE_M, distance_m, **kw)


def small_rectangle(distance_m, **kw):
    """The small rectangle of thesis figures 4.32-4.33 (5 x 4 cm, chosen) at ``distance_m``."""
    kw.setdefault("name", "small_rectangle")
    return _object("rectangle", SMALL_RECTANGLE_SIZE_M, distance_m, **kw)


_FACTORIES = {"rectangle": rectangle, "circle": circle, "triangle": triangle, "small_rectangle": small_rectangle}


def make_object(name, distance_m, **kw):
    """One of the test objects by name: rectangle, circle, triangle, small_rectangle."""
    if name not in _FACTORIES:
        raise ValueError(f"object must be one of {', '.join(_FACTORIES)}, not {name!r}")
    return _FACTORIES[name](distance_m, **kw)


def _rays(rig, side, cols, rows):
    """World-frame ray of each sample point: (centre X, dir_x (C,), dir_y (R, C), dir_z (C,)).

    ``cols``/``rows`` are sample coordinates in sensor-pixel units (pixel centres are at i + 0.5).
    Yaw is about the vertical axis, so dir_x and dir_z depend on the column only."""
    cam_x, cx, cy, yaw = rig.camera(side)
    xs = (np.asarray(cols, dtype=np.float64) - cx) / rig.focal_px
    ys = (np.asarray(rows, dtype=np.float64) - cy) / rig.focal_px
    cos_a, sin_a = math.cos(yaw), math.sin(yaw)
    dir_x = xs * cos_a + sin_a
    dir_z = cos_a - xs * sin_a
    return cam_x, dir_x, ys[:, None], dir_z


def _shade(objects, rig, side, cols, rows):
    """Shade the sample grid ``rows`` x ``cols``: (hits, label) where ``label`` is the (R, C) int16 index of
    the object seen at each sample (-1: background) and ``hits`` lists (row indices, column indices, mask,
    (N, 3) float RGB of the masked samples) per object, far to near (later entries cover earlier ones).

    Only the sub-grid of rows and columns that can meet an object's bounding box is evaluated."""
    cam_x, dir_x, dir_y, dir_z = _rays(rig, side, cols, rows)
    if np.any(dir_z <= 0):
        raise ValueError("a camera ray does not reach the object plane (toe-in too large)")
    dir_y = dir_y[:, 0]
    label = np.full((len(rows), len(cols)), -1, dtype=np.int16)
    hits = []
    order = sorted(range(len(objects)), key=lambda k: -objects[k].distance_m)   # far to near: near wins
    for k in order:
        obj = objects[k]
        w, h = obj.size_m
        t = obj.distance_m / dir_z                       # (C,) ray parameter at Z = distance
        X = cam_x + t * dir_x                            # (C,) world X seen by each column
        col_idx = np.flatnonzero(np.abs(X - obj.centre_x_m) <= w / 2)
        if col_idx.size == 0:
            continue
        t_sel = t[col_idx]
        y_lo = np.minimum(dir_y * t_sel.min(), dir_y * t_sel.max())     # world Y range seen by each row
        y_hi = np.maximum(dir_y * t_sel.min(), dir_y * t_sel.max())
        row_idx = np.flatnonzero((y_hi >= obj.centre_y_m - h / 2) & (y_lo <= obj.centre_y_m + h / 2))
        if row_idx.size == 0:
            continue
        Xs = np.broadcast_to(X[col_idx], (row_idx.size, col_idx.size))
        Ys = dir_y[row_idx, None] * t_sel[None, :]
        mask = obj.mask(Xs, Ys)
        if not mask.any():
            continue
        hits.append((row_idx, col_idx, mask, obj.colour(Xs[mask], Ys[mask])))
        label[np.ix_(row_idx, col_idx)] = np.where(mask, k, label[np.ix_(row_idx, col_idx)])
    return hits, label


def _paint(canvas, hits):
    """Paint ``hits`` (from :func:`_shade`) onto ``canvas`` (R, C, 3), far to near."""
    for row_idx, col_idx, mask, rgb in hits:
        block = canvas[np.ix_(row_idx, col_idx)]
        block[mask] = rgb
        canvas[np.ix_(row_idx, col_idx)] = block


def _as_objects(scene):
    if isinstance(scene, PlanarObject):
        return (scene,)
    objects = tuple(scene)
    if not all(isinstance(o, PlanarObject) for o in objects):
        raise TypeError("a scene is a PlanarObject or a sequence of them")
    return objects


def render_view(scene, rig=VMODCAM, side="left", supersample=1, rows=None):
    """The (height, width, 3) uint8 RGB image camera ``side`` sees of ``scene`` (objects before white).

    ``rows`` (optional) renders only those sensor rows (an int array), for tests that need a few lines.
    """
    objects = _as_objects(scene)
    k = int(supersample)
    if k < 1:
        raise ValueError(f"supersample must be >= 1, not {supersample!r}")
    pix_rows = np.arange(rig.height) if rows is None else np.asarray(rows)
    pix_cols = np.arange(rig.width)
    shape = (len(pix_rows), len(pix_cols), 3)
    if k == 1:      # point sampling: colours rounded half up straight into the 8-bit image
        image = np.empty(shape, dtype=np.uint8)
        image[...] = BACKGROUND_RGB
        hits, _ = _shade(objects, rig, side, pix_cols + 0.5, pix_rows + 0.5)
        _paint(image, [(r, c, m, np.floor(rgb + 0.5).clip(0, 255)) for r, c, m, rgb in hits])
        return image
    acc = np.zeros(shape)
    for sy in range(k):
        for sx in range(k):
            canvas = np.empty(shape)
            canvas[...] = BACKGROUND_RGB
            hits, _ = _shade(objects, rig, side, pix_cols + (sx + 0.5) / k, pix_rows + (sy + 0.5) / k)
            _paint(canvas, hits)
            acc += canvas
    return np.floor(acc / (k * k) + 0.5).clip(0, 255).astype(np.uint8)


def render_pair(scene, rig=VMODCAM, supersample=1):
    """(left, right): the two sensors' (height, width, 3) uint8 RGB images of ``scene``."""
    return (render_view(scene, rig, "left", supersample), render_view(scene, rig, "right", supersample))


def object_footprint(scene, rig=VMODCAM, side="right", scale=SENSOR.scale, index=0, centre=0.5):
    """Where object ``index`` of ``scene`` is seen at the capture's sample points: a boolean
    (height // scale, width // scale) mask, True where the sensor pixel (scale*i, scale*j) that the 1/16
    downscale keeps shows that object (point sampling at the pixel centre; hidden parts excluded). ``centre``:
    the sample point's offset in the block, 0.5 for the kept pixel's centre, ``scale / 2`` for the block's centre
    (the averaging capture)."""
    objects = _as_objects(scene)
    cols = np.arange(0, rig.width - scale + 1, scale)[: rig.width // scale] + centre
    rows = np.arange(0, rig.height - scale + 1, scale)[: rig.height // scale] + centre
    _, label = _shade(objects, rig, side, cols, rows)
    return label == index
