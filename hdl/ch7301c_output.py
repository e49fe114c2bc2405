"""CH7301C output stage: 24-bit RGB as two 12-bit halves on the two edges of XCLK, syncs aligned, XCLK pair."""

from amaranth.hdl import Module, Signal, Mux, Cat, ClockSignal, Instance, Const
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec.video import CEA_1080P60
from hdl.video_bus import VideoSignature

__all__ = ["CH7301CSignature", "CH7301COutput", "split_rgb", "check_ddr"]


#: The CH7301C's input pins as the FPGA drives them: the 12-bit dual-edge ``data`` bus (D[11:0]), ``hsync``,
#: ``vsync``, ``de`` and the clock pair ``xclk_p``/``xclk_n`` (XCLK, XCLK*).
CH7301CSignature = wiring.Signature({
    "data": Out(12), "hsync": Out(1), "vsync": Out(1), "de": Out(1), "xclk_p": Out(1), "xclk_n": Out(1),
})


#: ``"behavioural"``: simulation / Verilog-export model; ``"virtex5"``: Virtex-5 ODDR + OBUFDS primitives.
DDR_MODES = ("behavioural", "virtex5")


def split_rgb(rgb):
    """IDF 0 halves of a 24-bit RGB value (R[23:16] G[15:8] B[7:0]): ``(first, second)``.

    first (P0a, latched on the XCLK rising edge)  = G[3:0] B[7:0]  -> D[11:8] = G[3:0], D[7:0] = B[7:0]
    second (P0b, latched on the XCLK falling edge) = R[7:0] G[7:4] -> D[11:4] = R[7:0], D[3:0] = G[7:4]
    Works on Python ints and on Amaranth values.
    """
    if isinstance(rgb, int):
        r, g, b = (rgb >> 16) & 0xFF, (rgb >> 8) & 0xFF, rgb & 0xFF
        return ((g & 0xF) << 8) | b, (r << 4) | (g >> 4)
    r, g, b = rgb[16:24], rgb[8:16], rgb[0:8]
    return Cat(b, g[0:4]), Cat(g[4:8], r)


def check_ddr(ddr, xclk_domain=None):
    """``ValueError`` unless ``ddr`` is one of ``DDR_MODES`` and ``xclk_domain`` is given only with ``"virtex5"``."""
    if ddr not in DDR_MODES:
        raise ValueError(f"ddr must be one of {DDR_MODES}, not {ddr!r}")
    if xclk_domain is not None and ddr != "virtex5":
        raise ValueError("xclk_domain only applies to ddr='virtex5'")


class CH7301COutput(wiring.Component):
    """Drives the Chrontel CH7301C's 12-bit dual-edge data port from a :data:`VideoSignature` stream.

    Data format (CH7301C datasheet, Rev. 1.32, section 3.3 "Input Clock and Data Formats"; register 1Fh
    ``IDF[2:0]``): IDF = 0, *12-bit multiplexed RGB 8-8-8*, XCLK at the pixel rate with data latched on both
    edges (the multiplexed formats carry one pixel as two words P0a, P0b; "rising" means a rising edge of XCLK,
    a falling edge of XCLK*). Per pixel:

    ======================  ====================================================
    XCLK rising edge (P0a)  ``D[11:8] = G[3:0]``, ``D[7:0] = B[7:0]``
    XCLK falling edge (P0b) ``D[11:4] = R[7:0]``, ``D[3:0] = G[7:4]``
    ======================  ====================================================

    The first word follows the rising edge, the second the falling edge, so the pixel's first word is on the
    bus while XCLK is high and its second word while XCLK is low. Outside ``de`` the data pins carry 0.
    ``hsync``, ``vsync`` and ``de`` are registered with the data, so they are aligned with the pixel's first
    word and held for the whole pixel clock.

    Two implementations of the same bits, chosen by ``ddr``:

    * ``"behavioural"`` (simulation and Verilog export): both halves are registered on the rising edge of the
      ``sync`` clock and ``data = clk ? first : second``; ``xclk_p = clk``, ``xclk_n = ~clk``. This is the
      behaviour of a Virtex-5 ``ODDR`` in ``SAME_EDGE`` mode (D1 and D2 captured on the rising edge; Q = D1
      while C is high, D2 while C is low).
    * ``"virtex5"`` (the board): one ``ODDR`` (``DDR_CLK_EDGE="SAME_EDGE"``) per data pin with D1 = first
      word, D2 = second word; ``ODDR`` s with D1 = D2 for ``hsync``/``vsync``/``de`` (an IOB register); XCLK
      from an ``ODDR`` (D1 = 1, D2 = 0) through ``OBUFDS``. The ODDRs are the pipeline register, so the latency
      is the same as the behavioural model's. The XCLK ODDR runs in ``xclk_domain`` (default: the data clock);
      give it a 90-degree shifted clock, or use the CH7301C's XCLK delay (register 1Dh), so its edges fall in
      the middle of the data eye.

    Clock domain: ``sync`` (placed in ``pix`` by the parent). Latency: 1 clock. The pixel on ``video`` in
    clock n is on the pins from the rising edge that ends clock n: first word while the clock is high, second
    word while it is low, ``hsync``/``vsync``/``de`` for the whole clock. After reset the pins show a blank
    pixel with the syncs at their inactive level (``timing`` gives the polarities).

    Parameters
    ----------
    timing : :class:`spec.video.VideoTiming`
        For the sync polarities.
    ddr : str
        ``"behavioural"`` or ``"virtex5"``.
    xclk_domain : str or None
        ``"virtex5"`` only: the domain of the XCLK ODDR.

    Attributes
    ----------
    video : ``In(VideoSignature)``
    pins : ``Out(CH7301CSignature)``

    Raises
    ------
    ValueError
        An unknown ``ddr``, or ``xclk_domain`` without ``ddr="virtex5"``.
    """

    video: In(VideoSignature)
    pins: Out(CH7301CSignature)

    def __init__(self, timing=CEA_1080P60, *, ddr="behavioural", xclk_domain=None):
        check_ddr(ddr, xclk_domain)
        self.mode = timing
        self.ddr = ddr
        self.xclk_domain = xclk_domain or "sync"
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        t = self.mode
        pins = self.pins
        first, second = split_rgb(self.video.rgb)
        de = self.video.de
        # Blank the data outside de (both words 0).
        first_d = Mux(de, first, 0)
        second_d = Mux(de, second, 0)
        h_idle = 0 if t.hsync_positive else 1
        v_idle = 0 if t.vsync_positive else 1

        if self.ddr == "behavioural":
            first_q = Signal(12)
            second_q = Signal(12)
            hsync_q = Signal(init=h_idle)
            vsync_q = Signal(init=v_idle)
            de_q = Signal()
            m.d.sync += [
                first_q.eq(first_d),
                second_q.eq(second_d),
                hsync_q.eq(self.video.hsync),
                vsync_q.eq(self.video.vsync),
                de_q.eq(de),
            ]
            clk = ClockSignal("sync")
            m.d.comb += [
                pins.data.eq(Mux(clk, first_q, second_q)),
                pins.hsync.eq(hsync_q),
                pins.vsync.eq(vsync_q),
                pins.de.eq(de_q),
                pins.xclk_p.eq(clk),
                pins.xclk_n.eq(~clk),
            ]
            return m

        # Virtex-5 primitives (UG190 "ODDR"; Libraries Guide "OBUFDS").
        def oddr(name, d1, d2, q, init=0, domain="sync"):
            m.submodules[name] = Instance(
                "ODDR",
                p_DDR_CLK_EDGE="SAME_EDGE", p_INIT=Const(init, 1), p_SRTYPE="SYNC",
                i_C=ClockSignal(domain), i_CE=Const(1, 1), i_D1=d1, i_D2=d2,
                i_R=Const(0, 1), i_S=Const(0, 1), o_Q=q,
            )

        for i in range(12):
            oddr(f"oddr_d{i}", first_d[i], second_d[i], pins.data[i])
        oddr("oddr_hsync", self.video.hsync, self.video.hsync, pins.hsync, init=h_idle)
        oddr("oddr_vsync", self.video.vsync, self.video.vsync, pins.vsync, init=v_idle)
        oddr("oddr_de", de, de, pins.de)
        xclk = Signal()
        oddr("oddr_xclk", Const(1, 1), Const(0, 1), xclk, domain=self.xclk_domain)
        m.submodules.obufds_xclk = Instance("OBUFDS", i_I=xclk, o_O=pins.xclk_p, o_OB=pins.xclk_n)
        return m
