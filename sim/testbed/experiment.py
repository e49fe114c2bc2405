"""The thesis's test bed (4.6, table 4.2, figure 4.35) as a repeatable experiment on the golden model.

An experiment, not a model: it renders the scene (``sim/testbed/scene.py``), passes it through the golden models, sweeps
the registers as the thesis's observer did, and cross-checks a sample against the RTL (:func:`rtl_crosscheck`).

For an object at distance Z the experiment renders the two sensor images (``sim/testbed/scene.py``), runs them
through the hardware's data path as the golden model defines it (``golden.capture.capture_frame``: 1/16
downscale to 400 x 300, 5-bit grey; ``golden.disparity.difference_levels``: left read at (x + d, y + r),
right at (x, y), |L - R| quantised to display levels, "no data" where the shifted read leaves the image),
and sweeps the disparity register d = 0..127 the way the thesis's observer turned the switches.

Residual (the quantity minimised). The object's *footprint* is the set of buffer pixels (i, j) whose kept
sensor pixel (4i, 4j) in the right image shows the object (``sim.testbed.scene.object_footprint``). For a sweep
over d in [0, d_max] at a fixed rectification r, the evaluation *region* is the footprint minus the pixels
whose shifted read would leave the image for some swept value (x + d_max >= width or y + r >= height), so
every register value is judged on the same pixels and no "no data" pixel is ever inside it. Then

    residual(d, r) = sum over the region of level(x, y; d, r)

i.e. how much of the object is still visible in the difference image; it is 0 when the object has
"disappeared". The found disparity is the *smallest* d with the minimal residual (an observer turning the
switches up from 0 stops at the first value where the object vanishes); the *plateau* is [smallest,
largest] d with that minimum, reported so an ambiguous minimum is visible. The rectification is swept the
same way (r = 0..r_max at the found d, region rows y + r_max < height), alternating with the disparity
sweep until neither changes (coordinate descent; the thesis set the rectification first, then the
disparity).

Bound (docs/testbed.md derives it): with no misalignment every point of a fronto-parallel plane has the
same sensor disparity 4D (D = F B / (4 Z), buffer pixels). Point-sampled at columns 4i, an edge at sensor
column u in the right image and u + 4D in the left lands on buffer columns whose difference is floor(D) or
ceil(D); the per-row residual is a convex piecewise-linear function of d minimised between those two
columns' differences, so every minimiser, hence the found disparity, is in [floor(D), ceil(D)]:
|found - D| < 1 (found = D when D is an integer). The thesis's calculated column is D rounded either way
(|calculated - D| < 0.65), so |found - calculated| <= 1.
"""

import math
from dataclasses import dataclass, field, replace
from fractions import Fraction

import numpy as np

from golden.capture import capture_frame
from golden.disparity import difference_levels
from hdl.disparity import LATENCY, SETTLE_CLOCKS
from spec.board import CLOCKS
from spec.display import DIFF_THRESHOLDS
from spec.sensor import SENSOR
from sim.runners.amaranth import simulate
from sim.testbench.subtractor import set_pixel, subtractor_testbench
from sim.testbed.scene import RECTANGLE_SIZE_M, VMODCAM, make_object, object_footprint, render_pair

__all__ = [
    "THESIS_DISTANCES_M", "THESIS_CALCULATED_PX", "THESIS_OBSERVED_PX", "MAX_DISPARITY", "MAX_RECTIFICATION",
    "exact_disparity", "table_object_name", "SweepCurve", "Alignment", "TestbedPoint", "FitResult", "FIT_MODELS",
    "sweep_region", "disparity_curve", "rectification_curve", "find_alignment", "capture_pair", "run_point",
    "run_table", "auto_offset", "AutoOffset", "run_near_field", "NEAR_FIELD_DISTANCE_M", "fit_observed", "fitted_rig_and_distance",
    "RtlCheck", "rtl_difference_rows", "rtl_crosscheck", "EngineReading", "engine_reading", "engine_point",
    "engine_table"
]

# --- Thesis table 4.2 (docs/testbed.md) ------------------------------------------------------------------

THESIS_DISTANCES_M = (0.25, 0.50, 0.75, 1.00, 1.25, 1.50, 1.75, 2.00, 2.25, 2.50, 2.75, 3.00)
THESIS_CALCULATED_PX = (109, 54, 36, 27, 22, 18, 15, 13, 12, 11, 10, 9)
THESIS_OBSERVED_PX = (111, 51, 31, 22, 15, 12, 8, 7, 6, 4, 3, 2)

#: The disparity register is SW[6:0] (spec "Disparity map generator"): 0..127.
MAX_DISPARITY = 127
#: Rectification values swept by default (the register goes to 127; 15 buffer rows = 60 sensor rows is far
#: more vertical misalignment than a bolted stereo board has, and keeps the evaluated rows large).
MAX_RECTIFICATION = 15


def exact_disparity(distance_m, rig=VMODCAM, geometry=SENSOR):
    """Equation 2.1 in buffer pixels: F * B / Z / scale (no misalignment), as a float."""
    return rig.focal_px * rig.baseline_m / distance_m / geometry.scale


def centre_disparity(distance_m, rig=VMODCAM, geometry=SENSOR):
    """Buffer-pixel disparity of a point on the midline (X = 0, Y = 0) at ``distance_m`` for ``rig``,
    including its principal-point offset and toe-in: 2 F tan(atan(B / 2Z) - angle/2) + offset, / scale."""
    half = math.atan(rig.baseline_m / (2 * distance_m)) - math.radians(rig.convergence_deg) / 2
    return (2 * rig.focal_px * math.tan(half) + rig.principal_offset_px) / geometry.scale


def table_object_name(distance_m, rig=VMODCAM):
    """The object the table series uses: the 19 cm rectangle, or, where it is wider than the common field
    of view (0.25 m: thesis 4.6.6), the small rectangle the thesis switched to (figure 4.32)."""
    return "rectangle" if RECTANGLE_SIZE_M[0] < rig.common_field_width_m(distance_m) else "small_rectangle"


# --- Residual sweeps --------------------------------------------------------------------------------------

@dataclass(frozen=True)
class SweepCurve:
    """Residual per register value (index = value) over a fixed region of ``region_pixels`` pixels."""
    values: np.ndarray
    residual: np.ndarray
    region_pixels: int

    @property
    def minimum(self):
        return int(self.residual.min())

    @property
    def plateau(self):
        """(smallest, largest) register value with the minimal residual."""
        where = np.flatnonzero(self.residual == self.residual.min())
        return int(self.values[where[0]]), int(self.values[where[-1]])

    @property
    def found(self):
        return self.plateau[0]


def sweep_region(footprint, max_disparity, max_rectification):
    """The footprint pixels whose left read (x + d, y + r) is inside the image for every d <= max_disparity
    and r <= max_rectification."""
    h, w = footprint.shape
    region = footprint.copy()
    region[:, max(0, w - max_disparity):] = False
    region[max(0, h - max_rectification):, :] = False
    return region


def _residual(left, right, region, disparity, rectification, thresholds):
    levels, no_data = difference_levels(left, right, disparity, rectification, thresholds)
    if np.any(no_data[region]):
        raise AssertionError(f"no-data pixel inside the evaluation region at d={disparity} r={rectification}")
    return int(levels[region].sum(dtype=np.int64))


def _band(left, right, region, max_rectification, crop):
    """The rows the residual needs: the region's rows plus ``max_rectification`` below them, full width.

    Exact: a region pixel (x, y) reads left (x + d, y + r) with y + r < band end <= height and x + d < width,
    so on the band ``difference_levels`` gives the same levels and no-data flags for the region's pixels as
    on the whole frame (the band keeps the full width, so the column rule is unchanged)."""
    if not crop:
        return left, right, region
    rows = np.flatnonzero(region.any(axis=1))
    y0, y1 = int(rows[0]), min(region.shape[0], int(rows[-1]) + 1 + max_rectification)
    return left[y0:y1], right[y0:y1], region[y0:y1]


def _curve(left, right, region, pairs, values, thresholds, crop=True):
    if not region.any():
        raise ValueError("the object has no pixel whose shifted reads stay inside the image for the whole "
                         "sweep (object outside the view, or too far right)")
    max_r = max(r for _, r in pairs)
    band_left, band_right, band_region = _band(left, right, region, max_r, crop)
    residual = np.array([_residual(band_left, band_right, band_region, d, r, thresholds) for d, r in pairs],
                        dtype=np.int64)
    return SweepCurve(np.asarray(values), residual, int(region.sum()))


def disparity_curve(left, right, footprint, rectification=0, max_disparity=MAX_DISPARITY,
                    thresholds=DIFF_THRESHOLDS, crop=True):
    """Residual for d = 0..max_disparity at a fixed ``rectification`` (golden difference for each d; on the
    object's band of rows when ``crop``, which gives the same numbers faster)."""
    region = sweep_region(footprint, max_disparity, rectification)
    values = range(max_disparity + 1)
    return _curve(left, right, region, [(d, rectification) for d in values], values, thresholds, crop)


def rectification_curve(left, right, footprint, disparity, max_rectification=MAX_RECTIFICATION,
                        thresholds=DIFF_THRESHOLDS, crop=True):
    """Residual for r = 0..max_rectification at a fixed ``disparity``."""
    region = sweep_region(footprint, disparity, max_rectification)
    values = range(max_rectification + 1)
    return _curve(left, right, region, [(disparity, r) for r in values], values, thresholds, crop)


@dataclass(frozen=True)
class Alignment:
    """The register values that make the object disappear, and the last sweeps that found them."""
    disparity: int
    rectification: int
    disparity_sweep: SweepCurve
    rectification_sweep: SweepCurve | None
    rounds: int


def find_alignment(left, right, footprint, max_disparity=MAX_DISPARITY, max_rectification=MAX_RECTIFICATION,
                   thresholds=DIFF_THRESHOLDS, max_rounds=4):
    """Coordinate descent on (disparity, rectification) from (0, 0): sweep d at r, then r at d, until both
    are stable. ``max_rectification = 0`` sweeps the disparity only (rectification fixed at 0)."""
    r = 0
    d_curve = disparity_curve(left, right, footprint, r, max_disparity, thresholds)
    d = d_curve.found
    r_curve = None
    rounds = 1
    while max_rectification > 0 and rounds <= max_rounds:
        r_curve = rectification_curve(left, right, footprint, d, max_rectification, thresholds)
        if r_curve.found == r:
            break
        r = r_curve.found
        d_curve = disparity_curve(left, right, footprint, r, max_disparity, thresholds)
        d = d_curve.found
        rounds += 1
    return Alignment(d, r, d_curve, r_curve, rounds)


# --- One point of the experiment --------------------------------------------------------------------------

def capture_pair(scene, rig=VMODCAM, geometry=SENSOR, supersample=1):
    """Render ``scene`` for both cameras and capture both through the golden model: (left, right) grey5."""
    if (rig.width, rig.height) != (geometry.width, geometry.height):
        raise ValueError(f"rig sensor {rig.width}x{rig.height} differs from geometry "
                         f"{geometry.width}x{geometry.height}")
    left_rgb, right_rgb = render_pair(scene, rig, supersample)
    return capture_frame(left_rgb, geometry), capture_frame(right_rgb, geometry)


@dataclass(frozen=True)
class TestbedPoint:
    """One (distance, object) point of the experiment."""
    distance_m: float
    object_name: str
    exact_px: float               # equation 2.1 for the nominal geometry (buffer pixels)
    expected_px: float            # centre disparity for the rig used (with its misalignments)
    alignment: Alignment
    footprint_pixels: int
    engine: "EngineReading | None" = None      # the automatic depth engine on the same pair
    auto: "AutoOffset | None" = None           # the vertical-offset estimator on the same pair

    @property
    def found(self):
        return self.alignment.disparity

    @property
    def plateau(self):
        return self.alignment.disparity_sweep.plateau

    @property
    def within_bound(self):
        """Every minimising register value lies in [floor(expected), ceil(expected)] (module docstring)."""
        lo, hi = self.plateau
        return math.floor(self.expected_px) <= lo and hi <= math.ceil(self.expected_px)


@dataclass
class EngineReading:
    """The depth engine (golden model = RTL) on a test-bed pair: the median of its valid sub-pixel codes over
    the object's footprint in pixels (None: no valid code there), the centre readout it shows and that
    distance in metres (None for dashes), against the object's true distance."""
    disparity_px: float | None
    readout: str
    shown_m: float | None
    true_m: float

    @property
    def error(self):
        """Relative error of the shown distance (shown / true - 1), None when nothing is shown."""
        return None if self.shown_m is None else self.shown_m / self.true_m - 1

    def within(self, limit):
        """Whether the shown distance is within ``limit`` (a fraction: 0.01 for 1 %) of the true one, boundary
        included, in exact arithmetic on the whole centimetres shown and the distances as written (so 99 cm at
        1.00 m is within 1 %, 98 cm is not); False when nothing is shown."""
        if self.shown_m is None:
            return False
        shown = Fraction(round(self.shown_m * 100), 100)
        true, limit = Fraction(repr(float(self.true_m))), Fraction(repr(float(limit)))
        return abs(shown - true) <= limit * true


def engine_reading(left, right, footprint, rectification, true_m, geometry=SENSOR, config=None):
    """:class:`EngineReading` of the engine's map of the pair with the left image moved up by
    ``rectification`` (the switch the engine reads, ``golden.depth_display.engine_left``)."""
    from golden.depth import depth_map
    from golden.depth_display import centre_readout, engine_left
    from spec.depth import DEPTH
    config = config or DEPTH
    codes = depth_map(engine_left(left, rectification), right, config)
    valid = footprint & (codes != config.invalid)
    disparity = float(np.median(codes[valid])) / config.fraction if valid.any() else None
    _, text = centre_readout(codes, geometry, config)
    digits = text[:-2].strip()
    return EngineReading(disparity, text, int(digits) / 100 if digits.isdigit() else None, true_m)


def engine_point(distance_m, object_name=None, rig=VMODCAM, geometry=SENSOR, config=None, supersample=1,
                 **object_kw):
    """:class:`EngineReading` of the depth engine alone on one test-bed pair: ``object_name`` (default: the table's
    object, :func:`table_object_name`) at ``distance_m`` rendered for ``rig``, captured by ``geometry``'s capture
    (the thesis's or the averaging one), the engine of ``config`` (default: ``DEPTH`` for ``SENSOR``) on the
    buffers as captured (no rectification: for a rig without vertical misalignment, the one the sweep finds).
    The footprint samples each buffer pixel where its capture does: the kept pixel's centre, or the block's
    centre for the averaging capture. No register sweep: for builds whose buffers the thesis's subtractor does
    not read."""
    scene = make_object(object_name or table_object_name(distance_m, rig), distance_m, **object_kw)
    left, right = capture_pair(scene, rig, geometry, supersample)
    centre = geometry.scale / 2 if geometry.downscale == "average" else 0.5
    footprint = object_footprint(scene, rig, "right", geometry.scale, centre=centre)
    return engine_reading(left, right, footprint, 0, scene.distance_m, geometry, config)


def engine_table(distances=THESIS_DISTANCES_M, rig=VMODCAM, geometry=SENSOR, config=None, **kw):
    """[:class:`EngineReading`] of :func:`engine_point` at each distance (the table's object at each)."""
    return [engine_point(z, None, rig, geometry, config, **kw) for z in distances]


@dataclass(frozen=True)
class AutoOffset:
    """The vertical-offset estimator (automatic rectification, golden model = RTL) on a still pair from reset:
    ``offset`` in use after ``frames`` camera frames of it (buffer rows, signed), ``lock_frames`` (frames until it
    was in use: 0 when the reset's 0 is already right), ``held`` (no clear minimum in the last frame: the last
    offset kept, docs/rectification.md)."""
    offset: int
    lock_frames: int
    held: bool
    frames: int


def auto_offset(left, right, frames=None, config=None):
    """:class:`AutoOffset` of the grey buffers ``left``/``right`` shown ``frames`` times (default: the tracker's
    ``stable_frames`` + 2, enough to take any offset once)."""
    from golden.vertical_offset import estimate_offsets
    from spec.rectification import RECTIFICATION
    config = config or RECTIFICATION
    frames = frames or config.stable_frames + 2
    decisions = estimate_offsets([(left, right)] * frames, config)
    in_use = [0] + [d.offset for d in decisions]                    # from reset, then after each frame
    final = in_use[-1]
    lock = next(k for k in range(frames + 1) if all(o == final for o in in_use[k:]))
    return AutoOffset(final, lock, decisions[-1].held, frames)


def run_point(distance_m, object_name="rectangle", rig=VMODCAM, geometry=SENSOR, supersample=1,
              max_disparity=MAX_DISPARITY, max_rectification=MAX_RECTIFICATION, thresholds=DIFF_THRESHOLDS,
              object_distance_m=None, **object_kw):
    """Render ``object_name`` at ``distance_m`` (or at ``object_distance_m`` when the true distance
    differs from the nominal one, for the distance-offset fit), capture, sweep, find."""
    scene = make_object(object_name, distance_m if object_distance_m is None else object_distance_m,
                        **object_kw)
    left, right = capture_pair(scene, rig, geometry, supersample)
    footprint = object_footprint(scene, rig, "right", geometry.scale)
    alignment = find_alignment(left, right, footprint, max_disparity, max_rectification, thresholds)
    true_z = scene.distance_m
    engine = engine_reading(left, right, footprint, alignment.rectification, true_z, geometry)
    return TestbedPoint(distance_m, object_name, exact_disparity(distance_m, VMODCAM, geometry),
                        centre_disparity(true_z, rig, geometry), alignment, int(footprint.sum()), engine,
                        auto_offset(left, right))


def run_table(distances=THESIS_DISTANCES_M, rig=VMODCAM, geometry=SENSOR, progress=None, **kw):
    """The table series: at each distance the table object (``table_object_name``)."""
    points = []
    for z in distances:
        points.append(run_point(z, table_object_name(z, rig), rig, geometry, **kw))
        if progress:
            progress(points[-1])
    return points


#: The objects of thesis 4.6.6 (stereo field of view at 0.25 m).
NEAR_FIELD_OBJECTS = ("rectangle", "circle", "triangle", "small_rectangle")
NEAR_FIELD_DISTANCE_M = 0.25


def run_near_field(distance_m=NEAR_FIELD_DISTANCE_M, rig=VMODCAM, geometry=SENSOR, objects=NEAR_FIELD_OBJECTS,
                   **kw):
    """Every test object at ``distance_m`` (thesis 4.6.6): [TestbedPoint]."""
    return [run_point(distance_m, name, rig, geometry, **kw) for name in objects]


# --- Explaining the observed column -----------------------------------------------------------------------

#: Models of the observed disparity d_obs(Z) in buffer pixels, D(Z) = F B / (4 Z):
#:   offset:           D(Z) - c                          c = horizontal principal-point offset (or toe-in)
#:   offset+focal:     s D(Z) - c                        s = focal length (equivalently baseline) scale
#:   offset+distance:  F B / (4 (Z - z0)) - c            z0 = how far the distance reference lies behind
#:                                                          the lens's centre of projection
FIT_MODELS = ("offset", "offset+focal", "offset+distance")


@dataclass(frozen=True)
class FitResult:
    model: str
    params: dict = field(default_factory=dict)
    predicted: np.ndarray = None
    residual: np.ndarray = None      # observed - predicted

    @property
    def rms(self):
        return float(np.sqrt(np.mean(self.residual ** 2)))

    @property
    def max_abs(self):
        return float(np.max(np.abs(self.residual)))


def fit_observed(model, distances=THESIS_DISTANCES_M, observed=THESIS_OBSERVED_PX, rig=VMODCAM,
                 geometry=SENSOR):
    """Least-squares fit of ``model`` to the observed column. Parameters in the result: ``offset_px``
    (c, buffer px, > 0 lowers the disparity), ``principal_offset_px`` (the rig parameter cx_left - cx_right
    in sensor px that produces it, = -4c), ``convergence_deg`` (the toe-in angle that produces the same
    offset at the image centre), and ``focal_scale`` / ``focal_mm`` or ``distance_offset_m``."""
    z = np.asarray(distances, dtype=float)
    obs = np.asarray(observed, dtype=float)
    if z.shape != obs.shape or z.size < 3:
        raise ValueError("need at least three (distance, observed) pairs of equal length")
    fb = rig.focal_px * rig.baseline_m / geometry.scale
    d = fb / z
    params = {}
    if model == "offset":
        c = float(np.mean(d - obs))
        predicted = d - c
        focal_px = rig.focal_px
    elif model == "offset+focal":
        (s, c), *_ = np.linalg.lstsq(np.c_[d, -np.ones_like(d)], obs, rcond=None)
        s, c = float(s), float(c)
        predicted = s * d - c
        params.update(focal_scale=s, focal_mm=s * rig.focal_m * 1e3)
        focal_px = s * rig.focal_px
    elif model == "offset+distance":
        from scipy.optimize import least_squares

        def residual(p):
            return obs - (fb / (z - p[0]) - p[1])
        sol = least_squares(residual, x0=[0.0, float(np.mean(d - obs))])
        z0, c = (float(v) for v in sol.x)
        predicted = fb / (z - z0) - c
        params.update(distance_offset_m=z0)
        focal_px = rig.focal_px
    else:
        raise ValueError(f"model must be one of {', '.join(FIT_MODELS)}, not {model!r}")
    params.update(offset_px=c, principal_offset_px=-geometry.scale * c,
                  convergence_deg=math.degrees(2 * math.atan(geometry.scale * c / (2 * focal_px))))
    return FitResult(model, params, predicted, obs - predicted)


def fitted_rig_and_distance(fit, rig=VMODCAM):
    """(rig, true_distance(nominal)) that reproduce ``fit`` in the renderer: the principal-point offset is
    applied to the rig; a focal scale to its focal length; a distance offset moves the object."""
    p = fit.params
    new = replace(rig, principal_offset_px=p["principal_offset_px"],
                  focal_m=rig.focal_m * p.get("focal_scale", 1.0))
    z0 = p.get("distance_offset_m", 0.0)
    return new, (lambda z: z - z0)


# --- RTL cross-check --------------------------------------------------------------------------------------
# It runs hdl.disparity.DisparitySubtractor with two frame buffers preloaded with the captured buffers in Amaranth's
# simulator (sim/testbench/subtractor.py) and compares its output with the golden model the sweep uses, pixel for pixel.

@dataclass(frozen=True)
class RtlCheck:
    """One (disparity, rectification) point run through the RTL over ``rows`` (first, end) of the buffer."""
    disparity: int
    rectification: int
    rows: tuple
    pixels: int
    mismatches: int            # pixels whose (level, no_data) differ between the RTL and the golden model
    rtl_residual: int          # the residual computed from the RTL's levels over the region's pixels in rows
    golden_residual: int       # the same from the golden model

    @property
    def ok(self):
        return self.mismatches == 0 and self.rtl_residual == self.golden_residual


def rtl_difference_rows(left, right, settings, rows, geometry=SENSOR, thresholds=DIFF_THRESHOLDS):
    """Stream every pixel of buffer ``rows`` (raster order, one per pixel clock) through the RTL for each
    (disparity, rectification) in ``settings``; return a list of (levels, no_data) arrays (len(rows), width),
    one per setting. Registers change only while the pipeline is drained and are held for the subtractor's
    settle time before the first pixel, as the switch block guarantees between frames.

    The memories are initialised with the captured buffers up to the last address this run can read
    (row max(rows) + max(rectification), end of line); the words after it, never read, stay 0. This only
    saves simulator set-up time (Amaranth initialises memories word by word)."""
    w = geometry.buf_width
    rows = [int(y) for y in rows]
    last_row = min(geometry.buf_height, max(rows) + 1 + max(r for _, r in settings))
    words = last_row * w
    m, sub = subtractor_testbench(geometry, thresholds, np.asarray(left).ravel()[:words].tolist(),
                              np.asarray(right).ravel()[:words].tolist())
    outputs = [[] for _ in settings]

    async def bench(ctx):
        for k, (d, r) in enumerate(settings):
            ctx.set(sub.valid, 0)
            ctx.set(sub.settings.disparity, d)
            ctx.set(sub.settings.rectification, r)
            await ctx.tick().repeat(SETTLE_CLOCKS)
            for pixel in [(x, y) for y in rows for x in range(w)] + [None] * LATENCY:
                set_pixel(ctx, sub, pixel, w)
                await ctx.tick()
                if ctx.get(sub.out_valid):
                    outputs[k].append((ctx.get(sub.level), ctx.get(sub.no_data)))

    simulate(m, clocks={"sync": CLOCKS.PIXEL_HZ}, testbenches=[bench])
    result = []
    for out in outputs:
        if len(out) != len(rows) * w:
            raise AssertionError(f"the RTL gave {len(out)} valid outputs for {len(rows) * w} pixels")
        arr = np.array(out, dtype=np.int64).reshape(len(rows), w, 2)
        result.append((arr[..., 0].astype(np.uint8), arr[..., 1].astype(bool)))
    return result


def rtl_crosscheck(left, right, footprint, settings, rows=None, max_disparity=MAX_DISPARITY,
                   geometry=SENSOR, thresholds=DIFF_THRESHOLDS):
    """Run ``settings`` [(disparity, rectification)] through the RTL over ``rows`` (default: every row of the
    object's evaluation region) and compare with ``difference_levels`` and the residual; [RtlCheck]."""
    checks = []
    regions = [sweep_region(footprint, max_disparity, r) for _, r in settings]
    if rows is None:
        band = np.flatnonzero(np.logical_or.reduce(regions).any(axis=1))
        rows = range(int(band[0]), int(band[-1]) + 1)
    rows = list(rows)
    rtl = rtl_difference_rows(left, right, settings, rows, geometry, thresholds)
    for (d, r), region, (rtl_levels, rtl_no_data) in zip(settings, regions, rtl):
        levels, no_data = difference_levels(left, right, d, r, thresholds)
        levels, no_data, region = levels[rows], no_data[rows], region[rows]
        mismatches = int(np.count_nonzero((levels != rtl_levels) | (no_data != rtl_no_data)))
        checks.append(RtlCheck(d, r, (rows[0], rows[-1] + 1), levels.size, mismatches,
                               int(rtl_levels[region].sum(dtype=np.int64)), int(levels[region].sum(dtype=np.int64))))
    return checks
