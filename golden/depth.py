"""Golden model of the automatic depth engine, written from docs/depth.md (never from the RTL).

The right image is the reference; the match of right pixel (x, y) at disparity d is left pixel (x + d, y), as
for the disparity subtractor (docs/disparity.md). For every right-image pixel the engine gives a code: the
disparity in 1 / 2**F pixel (F = ``fraction_bits``), or ``config.invalid`` = D 2**F:

1. :func:`census`: a signature of ``census_bits`` bits per pixel, bit k set iff window pixel k is darker than
   the centre; window positions outside the image take the nearest image pixel (coordinates clamped).
2. :func:`matching_cost`: C[d, y, x] = popcount(census_R(y, x) XOR census_L(y, x + d)) + (min(|I_R(y, x) -
   I_L(y, x + d)|, ad_clip) >> ad_shift) (the AD term, 0 for ``ad_clip`` = 0; with ``ad_sampling`` "bt_left" or
   "bt" Birchfield and Tomasi's dissimilarity in place of |I_R - I_L|, computed in 2x units: min(2 dis, 2 ad_clip)
   >> (ad_shift + 1), the exact half-grey dissimilarity clipped and shifted, floored); ``cost_max`` = census_bits
   + (ad_clip >> ad_shift) where x + d leaves the image.
3. :func:`path_cost`: semi-global aggregation along one path of ``config.paths`` (``spec.depth.PATH_STEPS``:
   left to right or right to left along a row, top to bottom along a column, or down a diagonal): L = C +
   min(L'[d], L'[d - 1] + P1, L'[d + 1] + P1, M' + P2) - M', where L' is the previous pixel's vector on the path
   and M' its minimum; before the first pixel (the previous one outside the image) L' = 0, M' = 0 (so L = C
   there). 0 <= L <= cost_max + P2.
4. :func:`winner`: S = the sum of the paths' L; d* = the smallest d with the smallest S; the code
   2**F d* + q in 1 / 2**F pixel, q the equiangular fit through S(d* - 1), S(d*), S(d* + 1)
   (:func:`subpixel`); invalid (code D 2**F) when that S is above ``max_cost``, d* = D - 1 (the match may
   lie beyond the search range), or 64 S* > ``uniqueness`` S2, S2 the best sum 2 or more disparities away
   (:func:`second_best`: the confidence).
5. With ``config.left_right``: :func:`left_winner`, d_L(x') = the smallest d with the smallest S(d, x' - d) (the
   left view's winner from the same sums); :func:`left_right_keep`: a right pixel with a valid code and integer
   winner d* is kept iff |d_L(min(x + d*, W - 1)) - d*| <= 1; :func:`background_fill`: every code not kept takes
   the smaller of the nearest kept codes left and right of it in its row (the one there is; invalid if none).
6. :func:`median3x3` (``config.median`` = 3): the 5th smallest of the 3 x 3 codes around each pixel, coordinates
   clamped; invalid sorts above every disparity, so a pixel is invalid only where most of its neighbourhood is.
   :func:`separable_median` (``median`` = n = 5 or 7, m = n // 2): the median of the n column medians at
   x - m .. x + m, each the median of the n codes at rows y - m .. y + m, coordinates clamped; with
   ``median_valid`` each median is taken over its valid codes (invalid when at most half of them are valid).

:func:`depth_map` runs the whole chain. With ``row_tags`` (the frame tag of every row of each image, docs/depth.md,
"Rows from different camera frames") it applies the two tag rules of :func:`row_flags`: rows whose census window
holds rows of two camera frames (or a torn row) are invalid, and the vertical path restarts below them. Only
constants come from ``spec``.
"""

import numpy as np

from spec.depth import DEPTH, PATH_STEPS

__all__ = ["census", "matching_cost", "path_step", "path_cost", "subpixel", "second_best", "winner", "left_winner",
           "left_right_keep", "background_fill", "median3x3", "separable_median", "median", "row_flags", "depth_map",
           "DepthResult"]


def _check_pair(left, right, config):
    left, right = np.asarray(left), np.asarray(right)
    if left.ndim != 2 or left.shape != right.shape:
        raise ValueError(f"left {left.shape} and right {right.shape} must be two grey images of the same size")
    if not (np.issubdtype(left.dtype, np.integer) and np.issubdtype(right.dtype, np.integer)):
        raise ValueError("grey images must hold integers")
    if min(left.min(initial=0), right.min(initial=0)) < 0:
        raise ValueError("grey values must not be negative")
    top = (1 << config.pixel_bits) - 1
    if max(left.max(initial=0), right.max(initial=0)) > top:
        raise ValueError(f"grey values must be 0..{top} (pixel_bits = {config.pixel_bits})")
    if config.disparities > left.shape[1]:
        raise ValueError(f"D = {config.disparities} is more than the image width {left.shape[1]}")
    return left.astype(np.int32), right.astype(np.int32)


def census(image, config=DEPTH):
    """(H, W) uint64 signatures. Bit k (k = 0, 1, ...) is window position k in raster order (top row first,
    left to right), the centre skipped: set iff that pixel < the centre pixel."""
    image = np.asarray(image, dtype=np.int32)
    h, w = image.shape
    ry, rx = config.census_height // 2, config.census_width // 2
    padded = np.pad(image, ((ry, ry), (rx, rx)), mode="edge")      # clamped coordinates
    out = np.zeros((h, w), dtype=np.uint64)
    bit = 0
    for dy in range(-ry, ry + 1):
        for dx in range(-rx, rx + 1):
            if dy == 0 and dx == 0:
                continue
            neighbour = padded[ry + dy:ry + dy + h, rx + dx:rx + dx + w]
            out |= (neighbour < image).astype(np.uint64) << np.uint64(bit)
            bit += 1
    return out


def matching_cost(left, right, config=DEPTH):
    """C[d, y, x] (D x H x W; uint8, uint16 for a ``cost_max`` above 255): Hamming distance of the census
    signatures of right(x, y) and left(x + d, y), plus min(|right(x, y) - left(x + d, y)|, ``ad_clip``) >>
    ``ad_shift`` (0 with ``ad_clip`` = 0); ``cost_max`` = census_bits + (ad_clip >> ad_shift) where x + d >= W."""
    left, right = _check_pair(left, right, config)
    cl, cr = census(left, config), census(right, config)
    h, w = right.shape
    dtype = np.uint8 if config.cost_max < 256 else np.uint16
    cost = np.full((config.disparities, h, w), config.cost_max, dtype=dtype)
    for d in range(config.disparities):
        hamming = np.bitwise_count(cr[:, :w - d] ^ cl[:, d:]).astype(np.int32)
        if config.ad_sampling == "pixel":
            grey = np.minimum(np.abs(right[:, :w - d] - left[:, d:]), config.ad_clip) >> config.ad_shift
        else:
            grey = np.minimum(_sampled_difference(left, right, d, config.ad_sampling == "bt"),
                              2 * config.ad_clip) >> (config.ad_shift + 1)
        cost[d, :, :w - d] = hamming + grey
    return cost


def _interpolated_range(image):
    """(lo, hi) in 2x units: the smallest and largest of 2 I(x), I(x) + I(x - 1), I(x) + I(x + 1) (neighbours
    clamped at the border): twice Birchfield and Tomasi's Imin and Imax, exact integers."""
    padded = np.pad(image, ((0, 0), (1, 1)), mode="edge")
    values = np.stack([2 * image, image + padded[:, :-2], image + padded[:, 2:]])
    return values.min(axis=0), values.max(axis=0)


def _sampled_difference(left, right, d, symmetric):
    """Twice Birchfield and Tomasi's dissimilarity of right(x) and left(x + d) (x = 0 .. W - d - 1): max(0,
    2 I_R - 2 Imax_L, 2 Imin_L - 2 I_R), with ``symmetric`` the smaller of that and the same with the images'
    roles swapped."""
    w = right.shape[1]
    lo, hi = _interpolated_range(left)
    r2, l2 = 2 * right[:, :w - d], 2 * left[:, d:]
    out = np.maximum(0, np.maximum(r2 - hi[:, d:], lo[:, d:] - r2))
    if symmetric:
        lo, hi = _interpolated_range(right)
        out = np.minimum(out, np.maximum(0, np.maximum(l2 - hi[:, :w - d], lo[:, :w - d] - l2)))
    return out


def path_step(cost, prev, p1, p2):
    """One path step for a batch: ``cost`` and ``prev`` are (D, N); returns the new (D, N) path costs."""
    m = prev.min(axis=0)
    best = np.minimum(prev, m + p2)
    best[1:] = np.minimum(best[1:], prev[:-1] + p1)
    best[:-1] = np.minimum(best[:-1], prev[1:] + p1)
    return cost + best - m


def _path_dtype(config):
    """The smallest signed integer type that holds every summed cost (no stage overflows: docs/depth.md)."""
    return np.int16 if config.sum_max < 2 ** 15 else np.int32


def path_cost(cost, path, config=DEPTH, restart=None):
    """Path costs (D x H x W) along ``path``, a name of ``spec.depth.PATH_STEPS`` (``"left_to_right"``,
    ``"top_to_bottom"``, ``"right_to_left"``, ``"top_left_to_bottom_right"``, ``"top_right_to_bottom_left"``).
    ``restart`` (paths that step down a row only: H booleans, or None for row 0 only) marks the rows where the
    path starts afresh (previous vector 0, as before row 0)."""
    if path not in PATH_STEPS:
        raise ValueError(f"path must be one of {', '.join(PATH_STEPS)}, not {path!r}")
    dx, dy = PATH_STEPS[path]
    dtype = _path_dtype(config)
    cost = np.asarray(cost).astype(dtype)
    if restart is not None and dy == 0:
        raise ValueError("restart applies to the paths that step down a row only")
    out = np.empty_like(cost)
    if dy == 0:
        prev = np.zeros(cost[:, :, 0].shape, dtype=dtype)
        columns = range(cost.shape[2]) if dx < 0 else range(cost.shape[2] - 1, -1, -1)
        for x in columns:
            prev = out[:, :, x] = path_step(cost[:, :, x], prev, config.p1, config.p2)
        return out
    above = np.zeros(cost[:, 0, :].shape, dtype=dtype)       # the previous row's vectors (0 before row 0)
    for y in range(cost.shape[1]):
        if restart is not None and restart[y]:
            above = np.zeros_like(above)
        prev = np.zeros_like(above)                           # p' = (x + dx, y - 1), 0 outside the image
        if dx == 0:
            prev[:] = above
        elif dx < 0:
            prev[:, 1:] = above[:, :-1]
        else:
            prev[:, :-1] = above[:, 1:]
        above = out[:, y, :] = path_step(cost[:, y, :], prev, config.p1, config.p2)
    return out


def subpixel(total, d, config=DEPTH):
    """The fraction q of the winner ``d`` (int64, same shape as ``d``) in 1 / 2**F pixel (F = fraction_bits):
    with a, b, c = S(d - 1), S(d), S(d + 1), e = max(a, c) - b and n = a - c, q = floor((2**F n + e) / (2 e))
    (the equiangular fit n / (2 e) rounded half up), -2**(F - 1) <= q <= 2**(F - 1); q = 0 for d = 0,
    d = D - 1 or F = 0."""
    total = np.asarray(total)
    d = np.asarray(d)
    top = total.shape[0] - 1
    a = np.take_along_axis(total, np.clip(d - 1, 0, top)[None], axis=0)[0].astype(np.int64)
    b = np.take_along_axis(total, d[None], axis=0)[0].astype(np.int64)
    c = np.take_along_axis(total, np.clip(d + 1, 0, top)[None], axis=0)[0].astype(np.int64)
    inner = (d > 0) & (d < top) & (config.fraction_bits > 0)
    e = np.where(inner, np.maximum(a, c) - b, 1)        # a > b (ties go to the smaller d), so e >= 1
    return np.where(inner, (config.fraction * (a - c) + e) // (2 * e), 0)


def second_best(total, d, config=DEPTH):
    """S2: the smallest summed cost at a disparity 2 or more away from ``d`` (2**sum_bits - 1 where there is
    none)."""
    total = np.asarray(total)
    d = np.asarray(d)
    out = np.full(d.shape, (1 << config.sum_bits) - 1, dtype=np.int64)
    for k in range(total.shape[0]):                 # one disparity at a time: no D x H x W temporaries
        np.minimum(out, np.where(np.abs(k - d) >= 2, total[k], out), out=out)
    return out


def winner(total, config=DEPTH):
    """(codes, best cost) from the summed path costs (D x H x W): d* = the smallest d with the smallest sum,
    code = 2**F d* + :func:`subpixel`, or the invalid code where that sum S* is above ``max_cost``, d* = D - 1,
    or the match is not unique enough: 64 S* > ``uniqueness`` x :func:`second_best`."""
    total = np.asarray(total)
    d = np.argmin(total, axis=0)                    # first minimum = smallest disparity on ties
    best = np.take_along_axis(total, d[None], axis=0)[0]
    ambiguous = 64 * best.astype(np.int64) > config.uniqueness * second_best(total, d, config)
    invalid = (best > config.max_cost) | (d == config.disparities - 1) | ambiguous
    code = d.astype(np.int64) * config.fraction + subpixel(total, d, config)
    return np.where(invalid, config.invalid, code).astype(np.uint16), best


def left_winner(total):
    """d_L (H x W, int64): the left view's winner from the summed costs (D x H x W): for left pixel x', the
    smallest d with the smallest S(d, x' - d) over d = 0 .. min(D - 1, x') (left pixel x' is right pixel x' - d's
    match at disparity d)."""
    total = np.asarray(total)
    w = total.shape[2]
    best = total[0].astype(np.int64)
    found = np.zeros(best.shape, dtype=np.int64)
    for d in range(1, min(total.shape[0], w)):
        offer = total[d, :, :w - d]                 # S(d, x' - d) for x' = d .. W - 1
        better = offer < best[:, d:]                # strictly: a tie keeps the smaller d
        best[:, d:] = np.where(better, offer, best[:, d:])
        found[:, d:] = np.where(better, d, found[:, d:])
    return found


def left_right_keep(total, codes, config=DEPTH):
    """The left-right check (H x W bool): right pixel (x, y) is kept iff its code is valid and its integer winner
    d* (the smallest d with the smallest S) is within 1 of the left view's winner at min(x + d*, W - 1)
    (:func:`left_winner`)."""
    total = np.asarray(total)
    w = total.shape[2]
    d = np.argmin(total, axis=0)
    target = np.minimum(np.arange(w)[None, :] + d, w - 1)
    back = np.take_along_axis(left_winner(total), target, axis=1)
    return (np.asarray(codes) != config.invalid) & (np.abs(back - d) <= 1)


def background_fill(codes, keep, config=DEPTH):
    """Every code not kept replaced by the smaller of the nearest kept codes left and right of it in its row (the
    farther surface's), by the one there is where only one side has one, by the invalid code where the row has
    none; kept codes unchanged."""
    codes, keep = np.asarray(codes), np.asarray(keep, dtype=bool)
    out = codes.copy()
    for y in range(codes.shape[0]):
        kept = np.flatnonzero(keep[y])
        if not kept.size:
            out[y] = config.invalid
            continue
        x = np.arange(codes.shape[1])
        after = np.searchsorted(kept, x)                        # index of the first kept column >= x
        left = np.where(after > 0, codes[y, kept[np.maximum(after - 1, 0)]], config.invalid)
        right = np.where(after < kept.size, codes[y, kept[np.minimum(after, kept.size - 1)]], config.invalid)
        out[y] = np.where(keep[y], codes[y], np.minimum(left, right))
    return out


def median3x3(codes):
    """The median of the 3 x 3 neighbourhood of every pixel, coordinates clamped at the image border."""
    codes = np.asarray(codes)
    h, w = codes.shape
    padded = np.pad(codes, 1, mode="edge")
    stack = np.stack([padded[dy:dy + h, dx:dx + w] for dy in range(3) for dx in range(3)])
    return np.sort(stack, axis=0)[4].astype(codes.dtype)


def _median_of(stack, valid_only, invalid):
    """The median of the k codes along axis 0 of ``stack``: the (k // 2)-th smallest (0-based; ``invalid``, the
    largest code, sorts last), or with ``valid_only`` the ((v - 1) // 2)-th smallest of the v valid codes (code
    != ``invalid``) if v > k // 2, else ``invalid``."""
    k = len(stack)
    if not valid_only:
        return np.sort(stack, axis=0)[k // 2]
    valid = stack != invalid
    v = valid.sum(axis=0)
    ordered = np.sort(np.where(valid, stack.astype(np.int64), np.iinfo(np.int64).max), axis=0)
    pick = np.take_along_axis(ordered, ((np.maximum(v, 1) - 1) // 2)[None], axis=0)[0]
    return np.where(v > k // 2, pick, invalid)


def separable_median(codes, n, valid_only=False, invalid=DEPTH.invalid):
    """The separable n x n median (n = 5 or 7, m = n // 2) of every pixel: the median of the n column medians at
    columns x - m .. x + m, column x' 's the median of its n codes at rows y - m .. y + m; rows and columns
    clamped at the image border (the border pixel repeats; a clamped column's median is the border column's).
    Each median is :func:`_median_of` (``valid_only``: over the valid codes, ``invalid`` the invalid code)."""
    codes = np.asarray(codes)
    h, w = codes.shape
    m = n // 2
    rows = np.pad(codes, ((m, m), (0, 0)), mode="edge")
    columns = _median_of(np.stack([rows[dy:dy + h] for dy in range(n)]), valid_only, invalid)
    padded = np.pad(columns, ((0, 0), (m, m)), mode="edge")
    return _median_of(np.stack([padded[:, dx:dx + w] for dx in range(n)]), valid_only, invalid).astype(codes.dtype)


def median(codes, config=DEPTH):
    """The median ``config.median`` selects: :func:`median3x3` (3) or :func:`separable_median` (5, 7; with
    ``config.median_valid``)."""
    if config.median == 3:
        return median3x3(codes)
    return separable_median(codes, config.median, config.median_valid, config.invalid)


def _check_tags(tags, height, side):
    try:
        tags = list(tags)
    except TypeError:
        raise ValueError(f"{side} row tags must be a sequence of {height} ints or None") from None
    if len(tags) != height:
        raise ValueError(f"{side} row tags: {len(tags)} entries for {height} rows")
    for tag in tags:
        if tag is not None and not isinstance(tag, (int, np.integer)):
            raise ValueError(f"{side} row tags must be ints or None, not {tag!r}")
    return tags


def row_flags(row_tags, height, config=DEPTH):
    """(invalid, restart): two (H,) bool arrays from ``row_tags`` = (left_tags, right_tags), each H entries of an
    int frame tag or None (a torn row); None means every row of one frame. With h = census_height // 2 and W(y) the
    rows clamp(y - h) .. clamp(y + h): row y is invalid iff, for either image, a row of W(y) is torn or the tags of
    W(y) differ, or a row of W(y) has a left tag other than its right tag (the cameras' frames are paired: docs/
    capture.md, "Frame pairs"); the vertical path restarts at row y iff y = 0, row y - 1 is invalid, or, for
    either image, row y or y - 1 is torn or their tags differ."""
    invalid, restart = np.zeros(height, dtype=bool), np.zeros(height, dtype=bool)
    restart[0] = True
    if row_tags is None:
        return invalid, restart
    try:
        left_tags, right_tags = row_tags
    except (TypeError, ValueError):
        raise ValueError("row_tags must be None or a pair (left_tags, right_tags)") from None
    h = config.census_height // 2
    left_tags, right_tags = _check_tags(left_tags, height, "left"), _check_tags(right_tags, height, "right")
    for y in range(height):
        rows = slice(max(y - h, 0), min(y + h, height - 1) + 1)
        if left_tags[rows] != right_tags[rows]:         # a window row of two camera frame pairs
            invalid[y] = True
        for tags in (left_tags, right_tags):
            window = tags[rows]
            if None in window or len(set(window)) > 1:
                invalid[y] = True
            if y >= 1 and (tags[y] is None or tags[y - 1] is None or tags[y] != tags[y - 1]):
                restart[y] = True
    restart[1:] |= invalid[:-1]
    return invalid, restart


class DepthResult:
    """Every intermediate of :func:`depth_map` (for tests and pictures): ``paths`` maps each path's name to its
    costs; ``invalid_rows`` and ``restart_rows`` are :func:`row_flags`; ``checked`` is the median's input (``raw``
    after the left-right check and the fill with ``config.left_right``, else ``raw``)."""

    def __init__(self, cost, paths, raw, best, codes, config, invalid_rows=None, restart_rows=None, checked=None):
        self.cost, self.paths, self.checked = cost, paths, raw if checked is None else checked
        self.raw, self.best, self.codes, self.config = raw, best, codes, config
        self.invalid_rows, self.restart_rows = invalid_rows, restart_rows

    @property
    def valid(self):
        return self.codes != self.config.invalid


def depth_map(left, right, config=DEPTH, *, details=False, row_tags=None):
    """The engine's output for two grey buffers: (H, W) uint16 codes, disparity x 2**F, or the invalid code.
    ``row_tags``: None (every row of one camera frame) or (left_tags, right_tags), each H entries of an int frame
    tag or None (torn), the left ones indexed by engine row; rows flagged by :func:`row_flags` are invalid before
    the median (and before the left-right check with ``config.left_right``), and the vertical path restarts where
    it says. ``details=True`` returns a :class:`DepthResult`
    with the intermediates instead."""
    cost = matching_cost(left, right, config)
    invalid_rows, restart_rows = row_flags(row_tags, cost.shape[1], config)
    paths, total = {}, None
    for name in config.paths:
        steps_down = PATH_STEPS[name][1] != 0
        paths[name] = path_cost(cost, name, config, restart=restart_rows if steps_down else None)
        total = paths[name].copy() if total is None else np.add(total, paths[name], out=total)
        if not details:
            del paths[name]                             # the sum is all the winner needs
    raw, best = winner(total, config)
    raw[invalid_rows] = config.invalid
    checked = raw
    if config.left_right:
        checked = background_fill(raw, left_right_keep(total, raw, config), config)
    codes = median(checked, config)
    if details:
        return DepthResult(cost, paths, raw, best, codes, config, invalid_rows, restart_rows, checked)
    return codes
