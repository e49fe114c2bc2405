"""CensusWindow: the census window register array and transform of one image (docs/depth.md, "census")."""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from spec.sensor import SENSOR

__all__ = ["CensusWindow", "grey_range_layout"]


def grey_range_layout(grey_bits):
    """Birchfield and Tomasi's range of a pixel in 2x units (docs/depth.md, "cost"): ``low`` = I + min(I, I(x - 1),
    I(x + 1)) and ``high`` = I + max(I, I(x - 1), I(x + 1)), twice the smallest and largest of the pixel and its
    half-way values towards its row neighbours."""
    return data.StructLayout({"low": grey_bits + 1, "high": grey_bits + 1})


class CensusWindow(wiring.Component):
    """A ``census_width`` x ``census_height`` window of grey pixels, shifted in a column at a time, and its
    census signature.

    Parameters
    ----------
    config : DepthConfig
        Window size; ``ad_clip`` and ``ad_sampling`` choose the AD term's outputs.
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
    centre_range : Out(grey_range_layout(grey_bits))
        The centre pixel's range (:func:`grey_range_layout`) from its neighbours in the window's middle row,
        registered with ``census`` (with ``config.ad_sampling`` other than ``"pixel"`` only). The smallest and
        largest of the three pixels are taken at the ``shift`` for the column that becomes the centre (the
        pixels at ``census_width // 2`` .. ``+ 2`` before the shift, the last one the entering column's for a
        3-wide window), and added to the centre in the next clock: two short stages in place of one long one.

    Clock domain: ``sync``. Latency: ``census`` reflects a shifted column 2 clocks after ``shift``.
    """

    def __init__(self, config=DEPTH, grey_bits=SENSOR.grey_bits):
        self.config = config
        self.grey_bits = grey_bits
        members = {
            "column": In(data.ArrayLayout(grey_bits, config.census_height)),
            "shift": In(1),
            "census": Out(config.census_bits),
        }
        if config.ad_clip:
            members["centre"] = Out(grey_bits)
        if config.ad_sampling != "pixel":
            members["centre_range"] = Out(grey_range_layout(grey_bits))
        super().__init__(members)

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
        if cfg.ad_sampling != "pixel":
            self._range(m, window, rx, ry)
        return m

    def _range(self, m, window, rx, ry):
        """``centre_range``: the next centre's row neighbours' smallest and largest (with the pixel itself) at the
        ``shift``, then the centre added."""
        middle = [window[i][ry] for i in range(self.config.census_width)] + [self.column[ry]]
        west, pixel, east = middle[rx], middle[rx + 1], middle[rx + 2]      # the next centre and its neighbours
        darkest = Signal(self.grey_bits, name="range_darkest", reset_less=True)
        brightest = Signal(self.grey_bits, name="range_brightest", reset_less=True)
        with m.If(self.shift):
            m.d.sync += [
                darkest.eq(Mux((west < pixel) & ~(east < west), west, Mux(east < pixel, east, pixel))),
                brightest.eq(Mux((west > pixel) & ~(east > west), west, Mux(east > pixel, east, pixel))),
            ]
        m.d.sync += [self.centre_range.low.eq(window[rx][ry] + darkest),
                     self.centre_range.high.eq(window[rx][ry] + brightest)]
