"""MatchingCost: Hamming distance of census signatures for one group of disparities (docs/depth.md, "cost")."""

from amaranth import Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH

__all__ = ["MatchingCost"]

CHUNK = 6       # bits counted by one 6-input LUT level


def _tree_sum(values):
    """The sum of ``values`` as a balanced tree of adders (log depth, not a chain)."""
    values = list(values)
    while len(values) > 1:
        values = [values[i] + values[i + 1] if i + 1 < len(values) else values[i]
                  for i in range(0, len(values), 2)]
    return values[0]


class MatchingCost(wiring.Component):
    """C = popcount(right XOR left) for ``lanes`` candidates at once; ``census_bits`` where the candidate's
    left column is outside the image.

    Parameters
    ----------
    config : DepthConfig
        Census size and lanes.

    Ports
    -----
    right : In(census_bits)
        The reference pixel's census.
    left : In(ArrayLayout(census_bits, lanes))
        The candidates' census signatures.
    inside : In(lanes)
        Bit k: candidate k's left column is inside the image.
    cost : Out(ArrayLayout(cost_bits, lanes))

    Clock domain: ``sync``. Latency: 3 clocks (XOR + count of 6-bit chunks; chunk pairs summed; total).
    """

    LATENCY = 3

    def __init__(self, config=DEPTH):
        self.config = config
        super().__init__({
            "right": In(config.census_bits),
            "left": In(data.ArrayLayout(config.census_bits, config.lanes)),
            "inside": In(config.lanes),
            "cost": Out(data.ArrayLayout(config.cost_bits, config.lanes)),
        })

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
            total = _tree_sum(pairs)
            m.d.sync += self.cost[k].eq(Mux(inside_2[k], total, n))
        return m
