"""Probe of the cheap levers of the 800 x 600 build (docs/depth.md, "Cheap levers at 800 x 600"): changes of the
two-path, D = 128 engine without the build's quality options (``DEPTH_800_BASE``) that cost little or no block RAM,
each measured alone against it
on every pair of bench depth (the motorcycle and the synthetic scenes), then together; errors in 400-pixel units,
invalid counted bad.

The probe's pipeline is the golden model's (golden/depth.py: census, Hamming cost, the path recursion, winner with
the equiangular fit and the validity rule, 3 x 3 median) with one stage replaced at a time; with no lever it gives
``depth_map(left, right, DEPTH_800_BASE)`` bit for bit (checked on every run). Levers:

* adaptive P2: the penalty of a step from p' to p along a path taken from the grey step g = |I(p) - I(p')| of the
  reference (right) image, P2' = P2 for g < t1, P2 / 2 for t1 <= g < t2, P2 / 4 for g >= t2 (never below P1 + 1),
  and the SGM paper's P2' = max(P1 + 1, P2 s / (s + g));
* census variants, 48 bits: a sparse 13 x 7 window (every second column), the centre replaced by the 3 x 3 mean
  (bit = 9 I(q) < the 3 x 3 sum) or by the window's mean, a noise band (bit = I(q) < I(c) - t);
* AD-census: C = Hamming + min(|I_R(x) - I_L(x + d)|, clip) >> shift;
* ``max_cost`` off or raised; P1 / P2 with AD-census;
* the median: 5 x 5 (the 13th smallest code), 5 x 3, and their separable forms (the median of column medians);
* the second path from the top right or the top left (p' = (x +- 1, y - 1)) instead of from above;
* combinations of the levers that pay;
* on top of the package being built (``PACKAGE``: AD-census 16 >> 1, the separable 5 x 5 median, the diagonal
  path, max_cost 136; its own row is their base): the vertical line buffer holding l = min(L - M, P2) (7 bits,
  exact: checked equal to the package on every run) or l rounded to 5 or 4 bits, a third forward path, the
  backward path for reference, an invalid-aware median, larger separable medians, the AD term on the 3 x 3
  means, P1 / P2, census 9 x 7, a weighted diagonal, and SGM's left-right check from the same sums with the
  background's code filled into the codes it rejects.

Run: ``python -m bench depth_probe`` (every lever, some ten minutes of CPU); ``--levers WORD ...`` for the levers
whose name holds a WORD (and the base); ``--testbed --levers WORD ...`` for the test bed's readouts with those
levers instead (bench testbed's distances, the 800 x 600 build: about a minute and a half of CPU a lever;
``base`` names the base's row); ``--occluded --levers WORD ...``: the motorcycle's bad > 2 split into the
pixels hidden from the left camera and the rest.
"""

import argparse
import dataclasses

import numpy as np

from golden.depth import census, depth_map, median3x3, winner
from spec.depth import DEPTH_800_BASE, PATH_STEPS

BASE = DEPTH_800_BASE


# --- stages --------------------------------------------------------------------------------------------------------

def census_sparse(image, width=13, height=7, step=2):
    """Census on a ``width`` x ``height`` window sampled every ``step``-th column (48 bits for 13 x 7, step 2),
    coordinates clamped, bit order raster, centre skipped: set iff that pixel < the centre."""
    image = np.asarray(image, dtype=np.int32)
    h, w = image.shape
    ry, rx = height // 2, width // 2
    padded = np.pad(image, ((ry, ry), (rx, rx)), mode="edge")
    out = np.zeros((h, w), dtype=np.uint64)
    bit = 0
    for dy in range(-ry, ry + 1):
        for dx in range(-rx, rx + 1, step):
            if dy == 0 and dx == 0:
                continue
            out |= (padded[ry + dy:ry + dy + h, rx + dx:rx + dx + w] < image).astype(np.uint64) << np.uint64(bit)
            bit += 1
    return out


def _box_sum(image, ry, rx):
    image = np.asarray(image, dtype=np.int64)
    h, w = image.shape
    padded = np.pad(image, ((ry, ry), (rx, rx)), mode="edge")
    return sum(padded[ry + dy:ry + dy + h, rx + dx:rx + dx + w] for dy in range(-ry, ry + 1)
               for dx in range(-rx, rx + 1))


def census_centre(image, centre_radius=1, config=BASE, band=0):
    """The 7 x 7 census with the centre replaced by the mean of the (2r + 1)^2 block around it (r = 0: the pixel;
    bit = n I(q) < the block's sum, exact integers), or with a noise band (bit = I(q) < I(c) - band)."""
    image = np.asarray(image, dtype=np.int64)
    h, w = image.shape
    ry, rx = config.census_height // 2, config.census_width // 2
    n = (2 * centre_radius + 1) ** 2
    ref = _box_sum(image, centre_radius, centre_radius) if centre_radius else image
    padded = np.pad(image, ((ry, ry), (rx, rx)), mode="edge")
    out = np.zeros((h, w), dtype=np.uint64)
    bit = 0
    for dy in range(-ry, ry + 1):
        for dx in range(-rx, rx + 1):
            if dy == 0 and dx == 0:
                continue
            q = padded[ry + dy:ry + dy + h, rx + dx:rx + dx + w]
            out |= (n * q < ref - band * n).astype(np.uint64) << np.uint64(bit)
            bit += 1
    return out


def hamming_cost(cl, cr, bits, disparities):
    h, w = cr.shape
    cost = np.full((disparities, h, w), bits, dtype=np.int32)
    for d in range(disparities):
        cost[d, :, :w - d] = np.bitwise_count(cr[:, :w - d] ^ cl[:, d:])
    return cost


def ad_term(left, right, disparities, clip, shift):
    """min(|I_R(x) - I_L(x + d)|, clip) >> shift; clip >> shift where x + d >= W."""
    left, right = np.asarray(left, dtype=np.int32), np.asarray(right, dtype=np.int32)
    h, w = right.shape
    out = np.full((disparities, h, w), clip >> shift, dtype=np.int32)
    for d in range(disparities):
        out[d, :, :w - d] = np.minimum(np.abs(right[:, :w - d] - left[:, d:]), clip) >> shift
    return out


def grey_steps(right, path):
    """g(p) = |I(p) - I(p')| of the reference image along ``path`` (0 where p' is outside the image)."""
    image = np.asarray(right, dtype=np.int32)
    dx, dy = PATH_STEPS[path]
    prev = np.full_like(image, -1)
    h, w = image.shape
    ys, xs = slice(max(dy, 0), h + min(dy, 0)), slice(max(dx, 0), w + min(dx, 0))
    ps, pxs = slice(max(-dy, 0), h + min(-dy, 0)), slice(max(-dx, 0), w + min(-dx, 0))
    prev[ys, xs] = image[ps, pxs]
    return np.where(prev < 0, 0, np.abs(image - prev))


def stored_row(above, p2, shift):
    """What a line buffer holding l = min(L - M, P2) keeps of the row above (``shift`` None: L itself, the
    engine's store; 0: l, 7 bits for P2 = 96, which gives the recursion exactly what L does; s > 0: l rounded to
    a multiple of 2^s, half up, ``(min(l, P2) + 2^(s - 1)) >> s`` stored: 5 bits for s = 2, 4 bits for s = 3)."""
    if shift is None:
        return above
    low = np.minimum(above - above.min(axis=0), p2)
    if shift:
        low = ((low + (1 << (shift - 1))) >> shift) << shift
    return low


def aggregate(cost, path, p1, p2, store=None):
    """The golden recursion along ``path`` with a per-pixel P2 (``p2``: an int or an (H, W) array: the penalty of
    the step into each pixel); ``store``: the line buffer's form of the row above for the paths that step down a
    row (:func:`stored_row`; needs an int ``p2``)."""
    dx, dy = PATH_STEPS[path]
    cost = np.asarray(cost, dtype=np.int32)
    p2 = np.broadcast_to(np.asarray(p2, dtype=np.int32), cost.shape[1:])
    out = np.empty_like(cost)

    def step(c, prev, pen):
        m = prev.min(axis=0)
        best = np.minimum(prev, m + pen)
        best[1:] = np.minimum(best[1:], prev[:-1] + p1)
        best[:-1] = np.minimum(best[:-1], prev[1:] + p1)
        return c + best - m

    if dy == 0:
        prev = np.zeros(cost[:, :, 0].shape, dtype=np.int32)
        columns = range(cost.shape[2]) if dx < 0 else range(cost.shape[2] - 1, -1, -1)
        for x in columns:
            prev = out[:, :, x] = step(cost[:, :, x], prev, p2[:, x])
        return out
    above = np.zeros(cost[:, 0, :].shape, dtype=np.int32)
    for y in range(cost.shape[1]):
        prev = np.zeros_like(above)
        above = stored_row(above, int(p2[0, 0]), store) if y else above
        if dx == 0:
            prev[:] = above
        elif dx < 0:
            prev[:, 1:] = above[:, :-1]
        else:
            prev[:, :-1] = above[:, 1:]
        above = out[:, y, :] = step(cost[:, y, :], prev, p2[y])
    return out


def p2_steps(g, p1, p2, t1, t2):
    """The three-step rule: P2 below t1, P2 / 2 below t2, P2 / 4 from t2 on, never below P1 + 1."""
    return np.maximum(np.where(g < t1, p2, np.where(g < t2, p2 // 2, p2 // 4)), p1 + 1)


def p2_paper(g, p1, p2, s):
    return np.maximum(p2 * s // (s + g), p1 + 1)


def box_mean(image):
    """The 3 x 3 mean of every pixel (floor of the sum / 9), coordinates clamped."""
    return _box_sum(image, 1, 1) // 9


def median_of_columns_valid(codes, height, width, invalid):
    """:func:`median_of_columns` with the invalid code ignored unless most of a column (then of the row of column
    medians) is invalid: the median of n valid codes is the ((n - 1) // 2)-th smallest, where the plain median
    takes the (k // 2)-th of all k, the invalid code sorted last, which for n = k // 2 + 1 .. k - 1 valid codes
    is above their median (their largest for n = k // 2 + 1)."""
    codes = np.asarray(codes)
    h, w = codes.shape

    def middle(stack):
        k = stack.shape[0]
        n = np.sum(stack != invalid, axis=0)
        index = np.where(n > k // 2, (n - 1) // 2, k // 2)
        return np.take_along_axis(np.sort(stack, axis=0), index[None], axis=0)[0]

    columns = middle(_stack(codes, height // 2, 0))
    return middle(_stack(columns, 0, width // 2)).astype(codes.dtype)


def median5x5(codes):
    return np.sort(_stack(codes, 2, 2), axis=0)[12].astype(np.asarray(codes).dtype)


def _stack(codes, ry, rx):
    codes = np.asarray(codes)
    h, w = codes.shape
    padded = np.pad(codes, ((ry, ry), (rx, rx)), mode="edge")
    return np.stack([padded[dy:dy + h, dx:dx + w] for dy in range(2 * ry + 1) for dx in range(2 * rx + 1)])


def median5x3(codes):
    """The median (8th smallest) of the 5 wide x 3 tall neighbourhood: the 3 x 3 median's two rows of codes."""
    return np.sort(_stack(codes, 1, 2), axis=0)[7].astype(np.asarray(codes).dtype)


def median_of_columns(codes, height, width):
    """Separable: the median of the ``width`` column medians of ``height`` codes (each column sorted as the 3 x 3
    median sorts its columns), coordinates clamped."""
    codes = np.asarray(codes)
    h, w = codes.shape
    ry, rx = height // 2, width // 2
    columns = np.sort(_stack(codes, ry, 0), axis=0)[ry]
    return np.sort(_stack(columns, 0, rx), axis=0)[rx].astype(codes.dtype)


# --- the levers ----------------------------------------------------------------------------------------------------

@dataclasses.dataclass(frozen=True)
class Lever:
    """One change of the pipeline: ``signature`` (image -> (uint64 signatures, bits)), ``ad`` (clip, shift) or
    None, ``p2_rule`` (grey steps -> P2 per pixel) or None, ``median``, ``config`` changes, ``store`` (the line
    buffer's form of the row above: :func:`stored_row`), ``ad_mean`` (the AD term on the 3 x 3 means),
    ``weights`` (one integer a path of ``paths``: S = the weighted sum) or None (all 1), ``left_right`` (the
    left-right check from the same sums, the rejected codes filled with the background's)."""
    name: str
    signature: object = None
    ad: tuple = None
    p2_rule: object = None
    median: object = median3x3
    changes: tuple = ()
    store: int = None
    ad_mean: bool = False
    weights: tuple = None
    left_right: bool = False


def levers():
    p1, p2 = BASE.p1, BASE.p2
    out = [Lever("base: DEPTH_800_BASE (2 paths, 7 x 7 census, P2 96, 3 x 3 median)")]
    for t1, t2 in ((4, 16), (8, 24), (8, 32), (16, 48)):
        out.append(Lever(f"adaptive P2: 96 / 48 / 24 at grey step < {t1} / < {t2} / >= {t2}",
                         p2_rule=lambda g, t1=t1, t2=t2: p2_steps(g, p1, p2, t1, t2)))
    for s in (8, 16):
        out.append(Lever(f"adaptive P2 (SGM paper's form): max(P1 + 1, 96 {s} / ({s} + g))",
                         p2_rule=lambda g, s=s: p2_paper(g, p1, p2, s)))
    out.append(Lever("census 13 x 7, every second column (48 bits)",
                     signature=lambda im: (census_sparse(im), 48)))
    out.append(Lever("census centre = 3 x 3 mean", signature=lambda im: (census_centre(im, 1), 48)))
    out.append(Lever("census centre = 7 x 7 mean", signature=lambda im: (census_centre(im, 3), 48)))
    for band in (1, 2, 4):
        out.append(Lever(f"census noise band: I(q) < I(c) - {band}",
                         signature=lambda im, band=band: (census_centre(im, 0, band=band), 48)))
    for clip, shift in ((32, 2), (64, 3), (16, 1), (8, 0), (24, 1)):
        out.append(Lever(f"AD-census: + min(|dI|, {clip}) >> {shift}", ad=(clip, shift)))
    out.append(Lever("max_cost off (the validity rule's d* = D - 1 only)", changes=(("max_cost", 1 << 9),)))
    out.append(Lever("5 x 5 median", median=median5x5))
    out.append(Lever("5 x 3 median (the 3 x 3 median's rows)", median=median5x3))
    out.append(Lever("separable 5 x 3 median: median of 5 column medians of 3",
                     median=lambda c: median_of_columns(c, 3, 5)))
    out.append(Lever("separable 5 x 5 median: median of 5 column medians of 5",
                     median=lambda c: median_of_columns(c, 5, 5)))
    sparse = lambda im: (census_sparse(im), 48)         # noqa: E731
    out += [Lever("combined: AD-census 16 >> 1 + census 13 x 7", signature=sparse, ad=(16, 1)),
            Lever("combined: AD-census 16 >> 1 + 5 x 5 median", ad=(16, 1), median=median5x5),
            Lever("combined: census 13 x 7 + 5 x 5 median", signature=sparse, median=median5x5),
            Lever("combined: AD-census 16 >> 1 + census 13 x 7 + 5 x 5 median", signature=sparse, ad=(16, 1),
                  median=median5x5)]
    out += [Lever("combined: AD-census 16 >> 1 + 5 x 3 median", ad=(16, 1), median=median5x3),
            Lever("combined: AD-census 16 >> 1 + separable 5 x 3 median", ad=(16, 1),
                  median=lambda c: median_of_columns(c, 3, 5)),
            Lever("combined: AD-census 16 >> 1 + separable 5 x 5 median", ad=(16, 1),
                  median=lambda c: median_of_columns(c, 5, 5))]
    sep5 = lambda c: median_of_columns(c, 5, 5)        # noqa: E731
    for p1_, p2_ in ((16, 128), (20, 96), (12, 96)):
        out.append(Lever(f"combined: AD-census 16 >> 1 + separable 5 x 5 median, P1 {p1_} / P2 {p2_}", ad=(16, 1),
                         median=sep5, changes=(("p1", p1_), ("p2", p2_))))
    for diagonal in ("top_left_to_bottom_right", "top_right_to_bottom_left"):
        out.append(Lever(f"paths: left to right + {diagonal.replace('_', ' ')} (instead of top to bottom)",
                         changes=(("paths", ("left_to_right", diagonal)),)))
    trbl = (("paths", ("left_to_right", "top_right_to_bottom_left")),)
    out += [Lever("combined: AD-census 16 >> 1 + separable 5 x 5 median + diagonal path", ad=(16, 1), median=sep5,
                  changes=trbl),
            Lever("combined: AD-census 16 >> 1 + diagonal path", ad=(16, 1), changes=trbl),
            Lever("combined: separable 5 x 5 median + diagonal path", median=sep5, changes=trbl),
            Lever("combined: AD-census 16 >> 1 + separable 5 x 5 median + diagonal path, max_cost 136", ad=(16, 1),
                  median=sep5, changes=trbl + (("max_cost", 136),)),
            Lever("combined: AD-census 32 >> 2 + separable 5 x 5 median + diagonal path, max_cost 136", ad=(32, 2),
                  median=sep5, changes=trbl + (("max_cost", 136),)),
            Lever("combined: AD-census 16 >> 1 + separable 5 x 5 median + diagonal path, max_cost off", ad=(16, 1),
                  median=sep5, changes=trbl + (("max_cost", 1 << 9),)),
            Lever("combined: AD-census 16 >> 1 + 5 x 5 median + diagonal path", ad=(16, 1), median=median5x5,
                  changes=trbl),
            Lever("combined: AD-census 24 >> 1 + separable 5 x 5 median + diagonal path", ad=(24, 1), median=sep5,
                  changes=trbl),
            Lever("combined: census 13 x 7 + diagonal path", signature=sparse, changes=trbl),
            Lever("combined: census 13 x 7 + separable 5 x 5 median + diagonal path", signature=sparse, median=sep5,
                  changes=trbl),
            Lever("combined: AD-census 16 >> 1 + census 13 x 7 + separable 5 x 5 median + diagonal path",
                  signature=sparse, ad=(16, 1), median=sep5, changes=trbl)]
    return out + package_levers()


#: The package being built (docs/depth.md, "What to build"): AD-census 16 >> 1, the separable 5 x 5 median, the
#: second path from the top right, max_cost 136 (60 a path + the AD term's 8).
PACKAGE = "package: AD-census 16 >> 1 + separable 5 x 5 median + diagonal path, max_cost 136"


def package_levers():
    """Levers on top of the package (its own row first: their base)."""
    sep5 = lambda c: median_of_columns(c, 5, 5)        # noqa: E731
    base = dict(ad=(16, 1), median=sep5)
    two = ("left_to_right", "top_right_to_bottom_left")
    per_path = (BASE.max_cost // len(BASE.paths)) + (16 >> 1)      # 68: 60 a path + the AD term's 8

    def paths(*names):
        return (("paths", names), ("max_cost", per_path * len(names)))

    invalid = BASE.invalid
    return [
        Lever(PACKAGE, **base, changes=paths(*two)),
        Lever("package + line buffer l = min(L - M, P2), 7 bits (exact: must equal the package)", **base,
              changes=paths(*two), store=0),
        Lever("package + line buffer l rounded to 5 bits (s = 2)", **base, changes=paths(*two), store=2),
        Lever("package + line buffer l rounded to 4 bits (s = 3)", **base, changes=paths(*two), store=3),
        Lever("package + third forward path top to bottom, max_cost 204", **base,
              changes=paths("left_to_right", "top_to_bottom", "top_right_to_bottom_left")),
        Lever("package + third forward path top left to bottom right, max_cost 204", **base,
              changes=paths("left_to_right", "top_left_to_bottom_right", "top_right_to_bottom_left")),
        Lever("package + third forward path top to bottom, line buffers 5 bits (s = 2), max_cost 204", **base,
              changes=paths("left_to_right", "top_to_bottom", "top_right_to_bottom_left"), store=2),
        Lever("package + third forward path top to bottom, line buffers 4 bits (s = 3), max_cost 204", **base,
              changes=paths("left_to_right", "top_to_bottom", "top_right_to_bottom_left"), store=3),
        Lever("package + third path right to left (backward: beyond the budget, for reference), max_cost 204",
              **base, changes=paths("left_to_right", "top_right_to_bottom_left", "right_to_left")),
        Lever("package mirrored: rows scanned right to left (paths right to left + top left to bottom right)",
              **base, changes=paths("right_to_left", "top_left_to_bottom_right")),
        Lever("package mirrored + invalid-aware separable 7 x 7 median", ad=(16, 1),
              median=lambda c: median_of_columns_valid(c, 7, 7, invalid),
              changes=paths("right_to_left", "top_left_to_bottom_right")),
        Lever("package + left-right check from the same sums, background fill",
              **base, changes=paths(*two), left_right=True),
        Lever("package + left-right check, background fill + invalid-aware separable 7 x 7 median", ad=(16, 1),
              median=lambda c: median_of_columns_valid(c, 7, 7, invalid), changes=paths(*two), left_right=True),
        Lever("package + left-right check, background fill + separable 7 x 7 median", ad=(16, 1),
              median=lambda c: median_of_columns(c, 7, 7), changes=paths(*two), left_right=True),
        Lever("without AD-census: diagonal path + left-right check, background fill + separable 5 x 5 median",
              median=sep5, changes=(("paths", two),), left_right=True),
        Lever("without AD-census: diagonal path + left-right check, background fill + separable 7 x 7 median",
              median=lambda c: median_of_columns(c, 7, 7), changes=(("paths", two),), left_right=True),
        Lever("package + invalid-aware separable median", ad=(16, 1), changes=paths(*two),
              median=lambda c: median_of_columns_valid(c, 5, 5, invalid)),
        Lever("package + AD term on the 3 x 3 means", **base, changes=paths(*two), ad_mean=True),
        Lever("package + P1 12", **base, changes=paths(*two) + (("p1", 12),)),
        Lever("package + P1 20", **base, changes=paths(*two) + (("p1", 20),)),
        Lever("package + P2 128", **base, changes=paths(*two) + (("p2", 128),)),
        Lever("package + P1 / P2 scaled with the cost range (56 / 48): 19 / 112", **base,
              changes=paths(*two) + (("p1", 19), ("p2", 112))),
        Lever("package + separable 7 x 7 median", ad=(16, 1), median=lambda c: median_of_columns(c, 7, 7),
              changes=paths(*two)),
        Lever("package + invalid-aware separable 7 x 7 median", ad=(16, 1), changes=paths(*two),
              median=lambda c: median_of_columns_valid(c, 7, 7, invalid)),
        Lever("package + separable 9 x 9 median (where the median's gain ends)", ad=(16, 1),
              median=lambda c: median_of_columns(c, 9, 9), changes=paths(*two)),
        Lever("package + the diagonal weighted 2 (S = L_lr + 2 L_diagonal), max_cost 204", **base,
              changes=(("paths", two), ("max_cost", 3 * per_path)), weights=(1, 2)),
        Lever("package + census 9 x 7 (62 bits), max_cost off", **base,
              changes=(("paths", two), ("census_width", 9), ("max_cost", 1 << 10))),
    ]


def run(lever, left, right, config=BASE):
    """Codes (H, W) of ``config`` with ``lever`` applied."""
    config = dataclasses.replace(config, **dict(lever.changes))
    signature = lever.signature or (lambda im: (census(im, config), config.census_bits))
    (cl, bits), (cr, _) = signature(left), signature(right)
    cost = hamming_cost(cl, cr, bits, config.disparities)
    if lever.ad:
        grey = (box_mean(left), box_mean(right)) if lever.ad_mean else (left, right)
        cost += ad_term(*grey, config.disparities, *lever.ad)
    total = None
    for k, path in enumerate(config.paths):
        pen = config.p2 if lever.p2_rule is None else lever.p2_rule(grey_steps(right, path))
        lpath = aggregate(cost, path, config.p1, pen, store=lever.store)
        if lever.weights:
            lpath *= lever.weights[k]
        total = lpath if total is None else total + lpath
    raw, _ = winner(total, dataclasses.replace(config, p2=config.p2 + int(cost.max()) - config.census_bits))
    if lever.left_right:
        raw = background_fill(raw, left_right_consistent(total, raw, config), config.invalid)
    return lever.median(raw)


def left_right_consistent(total, raw, config):
    """SGM's left-right check from the same summed costs (Hirschmueller's D_m(q) = argmin_d S(q - d, d)): the left
    view's winner for left pixel x' is the d with the smallest S(d, x' - d); a valid right pixel x with winner d* is
    consistent iff the left view's winner at x + d* is within 1 of d*."""
    d_count, h, w = total.shape
    sheared = np.full(total.shape, np.iinfo(np.int32).max, dtype=np.int32)
    for d in range(d_count):
        sheared[d, :, d:] = total[d, :, :w - d]
    left_winner = np.argmin(sheared, axis=0)
    del sheared
    winner_d = np.argmin(total, axis=0)
    target = np.minimum(np.arange(w)[None, :] + winner_d, w - 1)
    back = np.take_along_axis(left_winner, target, axis=1)
    return (raw != config.invalid) & (np.abs(back - winner_d) <= 1)


def background_fill(codes, keep, invalid):
    """Each code not kept replaced by the smaller (the farther) of the nearest kept codes left and right of it in
    its row (the one there is where only one is; invalid where neither)."""
    h, w = codes.shape
    columns = np.broadcast_to(np.arange(w), (h, w))
    before = np.maximum.accumulate(np.where(keep, columns, -1), axis=1)
    after = np.minimum.accumulate(np.where(keep, columns, w)[:, ::-1], axis=1)[:, ::-1]
    rows = np.arange(h)[:, None]
    left_code = np.where(before >= 0, codes[rows, np.maximum(before, 0)], invalid)
    right_code = np.where(after < w, codes[rows, np.minimum(after, w - 1)], invalid)
    return np.where(keep, codes, np.minimum(left_code, right_code)).astype(codes.dtype)


def testbed_lines(lever):
    """The test bed (bench testbed's readings, the 800 x 600 build, every finish, the 12 distances of table 4.2)
    with ``lever``: per finish the worst |error| from 0.5 to 1.5 m and at 3 m against the goals (1 %, 2 %)."""
    from unittest import mock
    from bench.bench_testbed import build_table, goal_checks
    from sim.testbed.scene import FINISHES
    cells = []
    with mock.patch("golden.depth.depth_map", lambda left, right, config: run(lever, left, right, config)):
        for finish in FINISHES:
            checks = goal_checks("800", build_table("800", finish))
            cells.append(f"{finish} " + ", ".join(f"{worst:.1%}{'' if met else ' (miss)'}"
                                                   for _, worst, _, met in checks))
    return f"| {lever.name} | " + " | ".join(cells) + " |"


def occluded(truth):
    """Pixels of the right (reference) view hidden from the left camera, from the truth (disparities in buffer
    pixels, NaN unknown): pixel x of a row maps to left pixel x + d, and is hidden when a pixel x' < x of the row
    maps beyond it, x' + d(x') > x + d(x) + 1 (a nearer surface covers it)."""
    known = np.isfinite(truth)
    h, w = truth.shape
    reach = np.where(known, np.arange(w)[None, :] + np.where(known, truth, 0), -np.inf)
    before = np.maximum.accumulate(np.concatenate([np.full((h, 1), -np.inf), reach[:, :-1]], axis=1), axis=1)
    return known & (before > reach + 1)


def occlusion_line(name, codes, truth, to_400):
    """bad > 2 of a map split into the occluded pixels and the rest, in % of the pixels with a truth."""
    known = np.isfinite(truth)
    hidden = occluded(truth / to_400)
    estimate = codes.astype(np.float64) / BASE.fraction * to_400
    bad = known & ((codes == BASE.invalid) | (np.abs(estimate - np.where(known, truth, 0)) > 2))
    near = bad & (codes != BASE.invalid) & (estimate > truth)

    def pc(mask):
        return f"{100 * mask.sum() / known.sum():.2f}"
    return (f"| {name} | {pc(bad)} | {pc(hidden)} | {pc(bad & hidden)} ({pc(near & hidden)}) | "
            f"{pc(bad & ~hidden)} ({pc(near & ~hidden)}) |")


def main(argv=None):
    from bench.depth_builds import BUILDS, pairs
    from sim.analysis.truth import error_figures
    parser = argparse.ArgumentParser(prog="python -m bench depth_probe", description=__doc__.split("\n\n")[0])
    parser.add_argument("--levers", nargs="*", metavar="WORD", help="only the levers whose name holds WORD")
    parser.add_argument("--testbed", action="store_true",
                        help="the test bed's readouts (bench testbed, 800 x 600) instead of bench depth's pairs; "
                             "with --levers, of those levers only (the base's row: --levers base)")
    parser.add_argument("--occluded", action="store_true",
                        help="the motorcycle's bad > 2 split into the pixels hidden from the left camera and the "
                             "rest, with --levers, of those levers (and the package)")
    args = parser.parse_args(argv or [])
    build = BUILDS[1]
    every = levers()
    matched = [lv for lv in every if not args.levers or any(word in lv.name for word in args.levers)]
    if args.testbed:
        print("| lever | worst \\|error\\| 0.5-1.5 m, at 3 m (goals 1 %, 2 %), by finish |||")
        print("|---|---|---|---|")
        for lever in matched:
            print(testbed_lines(lever), flush=True)
        return
    if args.occluded:
        name, left, right, truth = pairs(build)[0]
        print(f"{name}, bad > 2 in % of the pixels with a truth (too near: the estimate above the truth)")
        print("| lever | bad > 2 | occluded pixels | bad > 2 there (too near) | bad > 2 elsewhere (too near) |")
        print("|---|---|---|---|---|")
        for lever in [lv for lv in every if lv.name == PACKAGE] + [lv for lv in matched if lv.name != PACKAGE]:
            print(occlusion_line(lever.name, run(lever, left, right), truth, build.to_400), flush=True)
        return
    chosen = [every[0]] + [lv for lv in matched if lv is not every[0]]
    build_pairs = pairs(build)
    results = {lv.name: [] for lv in chosen}
    for pair_name, left, right, truth in build_pairs:
        for lever in chosen:
            codes = run(lever, left, right)
            if lever is chosen[0] and not np.array_equal(codes, depth_map(left, right, BASE)):
                raise SystemExit(f"the probe's pipeline differs from golden.depth.depth_map on {pair_name}")
            if lever.store == 0 and not np.array_equal(codes, run(dataclasses.replace(lever, store=None), left,
                                                                      right)):
                raise SystemExit(f"the 7-bit line buffer (l = min(L - M, P2)) changes the map of {pair_name}")
            disparity = codes.astype(np.float64) / BASE.fraction * build.to_400
            results[lever.name].append(error_figures(disparity, codes != BASE.invalid, truth))
    names = [p[0] for p in build_pairs]
    print("| lever | " + " | ".join(names) + " |")
    print("|---|" + "---|" * len(names))
    for name, figures in results.items():
        cells = [f"{100 * f[0]:.1f} / {100 * f[1]:.1f} / {100 * f[2]:.1f}, {100 * f[4]:.1f}" for f in figures]
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
