"""CensusWindow: the census window register array and transform of one image (docs/depth.md, "census")."""

from amaranth import Cat, Module, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from spec.sensor import SENSOR

__all__ = ["CensusWindow"]


class CensusWindow(wiring.Component):
    """A ``census_width`` x ``census_height`` window of grey pixels, shifted in a column at a time, and its
    census signature.

    Parameters
    ----------
    config : DepthConfig
        Window size.
    grey_bits : int
        Pixel width.

    Ports
    -----
    column : In(ArrayLayout(grey_bits, census_height))
        The next column, top row first; it enters on the right of the window when ``shift`` is high.
    shift : In(1)
    census : Out(census_bits)
        Bit k = window position k in raster order (top row first, left to right, centre skipped) is
        darker than the centre. Registered: it shows the window one clock after the window changes.
    centre : Out(grey_bits)
        The centre pixel, registered with ``census`` (with ``config.ad_clip`` > 0 only: the AD term's grey).

    Clock domain: ``sync``. Latency: ``census`` reflects a shifted column 2 clocks after ``shift``.
    """

    def __init__(self, config=DEPTH, grey_bits=SENSOR.grey_bits):
        self.config = config
        self.grey_bits = grey_bits
        super().__init__({
            "column": In(data.ArrayLayout(grey_bits, config.census_height)),
            "shift": In(1),
            "census": Out(config.census_bits),
            **({"centre": Out(grey_bits)} if config.ad_clip else {}),
        })

    def elaborate(self, platform):
        m = Module()
        cfg = self.config
        window = [Signal(data.ArrayLayout(self.grey_bits, cfg.census_height), name=f"window_col{i}",
                         reset_less=True)
                  for i in range(cfg.census_width)]                 # window[0] = leftmost column
        with m.If(self.shift):
            for i in range(cfg.census_width - 1):
                m.d.sync += window[i].eq(window[i + 1])
            m.d.sync += window[-1].eq(self.column)
        rx, ry = cfg.census_width // 2, cfg.census_height // 2
        centre = window[rx][ry]
        bits = [window[i][j] < centre for j in range(cfg.census_height) for i in range(cfg.census_width)
                if (i, j) != (rx, ry)]
        m.d.sync += self.census.eq(Cat(*bits))
        if cfg.ad_clip:
            m.d.sync += self.centre.eq(centre)
        return m
