"""MatchingCost: Hamming distance of census signatures, plus the clipped grey difference (AD-census), for one
group of disparities (docs/depth.md, "cost")."""

from amaranth import C, Cat, Module, Mux, Signal, signed
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from hdl.depth.census import grey_range_layout

__all__ = ["MatchingCost"]

CHUNK = 6       # bits counted by one 6-input LUT level


def _at_least(value, constant):
    """value >= constant (value unsigned, constant an integer) as and/or logic of value's bits."""
    if constant <= 0:
        return C(1, 1)
    if constant >= 1 << len(value):
        return C(0, 1)
    result = C(1, 1)
    for i in range(len(value)):             # low to high: result is value[:i + 1] >= constant[:i + 1]
        result = (value[i] & result) if (constant >> i) & 1 else (value[i] | result)
    return result


def _tree_sum(values):
    """The sum of ``values`` as a balanced tree of adders (log depth, not a chain)."""
    values = list(values)
    while len(values) > 1:
        values = [values[i] + values[i + 1] if i + 1 < len(values) else values[i]
                  for i in range(0, len(values), 2)]
    return values[0]


class MatchingCost(wiring.Component):
    """C = popcount(right XOR left) + (min(\\|right_grey - left_grey\\|, ad_clip) >> ad_shift) for ``lanes``
    candidates at once (the AD term only with ``config.ad_clip`` > 0); ``cost_max`` = census_bits +
    (ad_clip >> ad_shift) where the candidate's left column is outside the image. With ``config.ad_sampling``
    ``"bt_left"`` the AD term is Birchfield and Tomasi's min(dis, 2 ad_clip) >> (ad_shift + 1) in 2x units, dis =
    max(0, 2 I_R - high_L, low_L - 2 I_R) from the left candidate's range; with ``"bt"`` the smaller of that and
    max(0, 2 I_L - high_R, low_R - 2 I_L).

    Parameters
    ----------
    config : DepthConfig
        Census size, lanes, ``pixel_bits``, ``ad_clip``, ``ad_shift``, ``ad_sampling``.

    Ports
    -----
    right : In(census_bits)
        The reference pixel's census.
    left : In(ArrayLayout(census_bits, lanes))
        The candidates' census signatures.
    right_grey : In(pixel_bits)
        The reference pixel's grey value (with ``ad_clip`` > 0 only).
    left_grey : In(ArrayLayout(pixel_bits, lanes))
        The candidates' grey values (with ``ad_clip`` > 0 only).
    right_range : In(grey_range_layout(pixel_bits))
        The reference pixel's range (``low``, ``high``, 2x units; with ``ad_sampling`` "bt" only).
    left_range : In(ArrayLayout(grey_range_layout(pixel_bits), lanes))
        The candidates' ranges (with ``ad_sampling`` "bt_left" or "bt").
    inside : In(lanes)
        Bit k: candidate k's left column is inside the image.
    cost : Out(ArrayLayout(cost_bits, lanes))

    Clock domain: ``sync``. Latency: 3 clocks (XOR + count of 6-bit chunks, grey difference; chunk pairs summed,
    difference made absolute, clipped and shifted; total). With Birchfield and Tomasi's term the first clock
    takes the differences to the ranges' ends, each clipped and shifted, and the second the smaller of the two
    directions.
    """

    LATENCY = 3

    def __init__(self, config=DEPTH):
        self.config = config
        members = {
            "right": In(config.census_bits),
            "left": In(data.ArrayLayout(config.census_bits, config.lanes)),
            "inside": In(config.lanes),
            "cost": Out(data.ArrayLayout(config.cost_bits, config.lanes)),
        }
        if config.ad_clip:
            members["right_grey"] = In(config.pixel_bits)
            members["left_grey"] = In(data.ArrayLayout(config.pixel_bits, config.lanes))
        grey_range = grey_range_layout(config.pixel_bits)
        if config.ad_sampling == "bt":
            members["right_range"] = In(grey_range)
        if config.ad_sampling != "pixel":
            members["left_range"] = In(data.ArrayLayout(grey_range, config.lanes))
        super().__init__(members)

    def elaborate(self, platform):
        m = Module()
        cfg = self.config
        n = cfg.census_bits
        inside_1 = Signal(cfg.lanes)
        inside_2 = Signal(cfg.lanes)
        m.d.sync += [inside_1.eq(self.inside), inside_2.eq(inside_1)]
        for k in range(cfg.lanes):
            diff = self.left[k] ^ self.right
            chunks = []
            for c in range(0, n, CHUNK):
                part = diff[c:min(c + CHUNK, n)]
                count = Signal(range(len(part) + 1), name=f"count_{k}_{c // CHUNK}", reset_less=True)
                m.d.sync += count.eq(_tree_sum([part[i] for i in range(len(part))]))
                chunks.append(count)
            pairs = []
            for c in range(0, len(chunks), 2):
                pair = Signal(range(n + 1), name=f"pair_{k}_{c // 2}", reset_less=True)
                m.d.sync += pair.eq(_tree_sum(chunks[c:c + 2]))
                pairs.append(pair)
            if cfg.ad_sampling != "pixel":
                pairs.append(self._bt_term(m, k))
            elif cfg.ad_clip:
                pairs.append(self._ad_term(m, k))
            total = _tree_sum(pairs)
            m.d.sync += self.cost[k].eq(Mux(inside_2[k], total, cfg.cost_max))
        return m

    def _ad_term(self, m, k):
        """Lane k's AD term, registered in two stages beside the chunk counts and their pairs: the signed grey
        difference d, then min(\\|d\\|, ad_clip) >> ad_shift as and/or/xor logic of d's bits (no carry chain):
        with s = d's sign and e = d's low bits XOR s (\\|d\\| = e + s), \\|d\\| >= ad_clip iff e >= ad_clip - s,
        and below the clip \\|d\\| < 2**w (w = ad_clip's bits) is e + s on e's w low bits."""
        cfg = self.config
        n, clip = cfg.pixel_bits, cfg.ad_clip
        grey_diff = Signal(signed(n + 1), name=f"grey_diff_{k}", reset_less=True)
        m.d.sync += grey_diff.eq(self.right_grey - self.left_grey[k])
        sign = grey_diff[n]
        ones = grey_diff[:n] ^ sign.replicate(n)
        clipped = Mux(sign, _at_least(ones, clip - 1), _at_least(ones, clip))
        low, carry = [], sign
        for i in range(clip.bit_length()):
            low.append(ones[i] ^ carry)
            carry = carry & ones[i]
        ad = Signal(range(cfg.ad_max + 1), name=f"ad_{k}", reset_less=True)
        m.d.sync += ad.eq(Mux(clipped, clip >> cfg.ad_shift, Cat(*low) >> cfg.ad_shift))
        return ad

    def _bt_term(self, m, k):
        """Lane k's Birchfield-Tomasi term, registered in two stages beside the chunk counts and their pairs: each
        direction's dis = max(0, 2 I - high, low - 2 I) clipped at 2 ad_clip and shifted right by ad_shift + 1
        (the two differences' clipped values ORed: at most one of them is positive, as low <= high), then the
        smaller of the two directions."""
        cfg = self.config
        n = cfg.pixel_bits
        directions = [(self.right_grey, self.left_range[k])]           # the right pixel against the left range
        if cfg.ad_sampling == "bt":
            directions.append((self.left_grey[k], self.right_range))
        clipped = []
        for i, (grey, grey_range) in enumerate(directions):
            twice = Cat(C(0, 1), grey)
            above = Signal(signed(n + 2), name=f"bt_above_{k}_{i}")       # 2 I - high
            below = Signal(signed(n + 2), name=f"bt_below_{k}_{i}")       # low - 2 I
            m.d.comb += [above.eq(twice - grey_range.high), below.eq(grey_range.low - twice)]
            dis = Signal(range(cfg.ad_max + 1), name=f"bt_dis_{k}_{i}", reset_less=True)
            m.d.sync += dis.eq(self._clip(above) | self._clip(below))
            clipped.append(dis)
        ad = Signal(range(cfg.ad_max + 1), name=f"ad_{k}", reset_less=True)
        m.d.sync += ad.eq(clipped[0] if len(clipped) == 1 else
                          Mux(clipped[0] < clipped[1], clipped[0], clipped[1]))
        return ad

    def _clip(self, value):
        """min(max(value, 0), 2 ad_clip) >> (ad_shift + 1) of a signed difference, as logic of its bits."""
        cfg = self.config
        top, shift = 2 * cfg.ad_clip, cfg.ad_shift + 1
        sign, magnitude = value[-1], value[:-1]
        low = magnitude[:top.bit_length()] >> shift
        return Mux(sign, 0, Mux(_at_least(magnitude, top), top >> shift, low))
