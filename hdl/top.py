"""GenesysTop: the board top level -- StereoDepthSystem + board clocking + Genesys pins and IO buffers.

Pins (``hdl.genesys.GenesysPlatform`` resources) and what drives them:

=====================  ========================================================================================
``clk100``, ``rst``     input buffers -> :class:`~hdl.clocking.GenesysClocking` (oscillator, reset button)
``switches``            input buffers -> ``sw`` (synchronised inside :class:`~hdl.switches.SwitchControl`)
``leds``                output buffers <- ``leds`` (see :mod:`hdl.system` for the meaning of each LED)
``vmodcam`` 0/1         D, LV, FV input buffers -> ``cam_a``/``cam_b`` pins of the system (sampled by the capture's
                        input registers in the camera's PCLK domain); PCLK input buffer -> BUFG -> camera
                        domain; MCLK forwarded by an ODDR (D1 = 1, D2 = 0) clocked by the 24 MHz ``mclk``; SCL
                        and SDA open drain; RST_N, PWDN outputs. Camera A (number 0) is the left camera.
``vmodcam_vdden``       output <- ``cam_vdden``
``ch7301c``             D[11:0]: one ODDR per pin (``SAME_EDGE``; D1 = the word shown while the pixel clock is
                        high, D2 = the word while it is low, as :func:`hdl.ch7301c_output.split_rgb` splits
                        the pixel, zero outside DE); H, V, DE: IOB flip-flops, so they leave on the same edge as
                        the data; XCLK_P/XCLK_N: two ODDRs (1/0 and 0/1) clocked by ``pix90``, so XCLK's rising
                        edge comes a quarter pixel period after each data change (the middle of the first
                        word) and its falling edge the middle of the second; RESET_N <- ``dvi_reset_n``
``ch7301c_i2c``         open drain (SCL, SDA), the CH7301C's init sequencer
=====================  ========================================================================================

The ODDR, IOB flip-flop and IO buffers come from ``amaranth.lib.io`` buffers the platform maps onto Virtex-5
primitives (``DDRBuffer`` -> ``ODDR``, ``FFBuffer`` -> IOB flip-flop); they exist only on the board (Amaranth's
simulator cannot run ``io.DDRBuffer``). The same bits are simulated through the behavioural model in
:class:`~hdl.ch7301c_output.CH7301COutput` (``StereoDepthSystem(ddr="behavioural")``): same split, same
one-clock output register, data high-phase word first. An ODDR in ``SAME_EDGE`` mode samples D1 and D2 on the
rising edge and outputs D1 for the high phase and D2 for the low phase of the following clock (Virtex-5 user guide
UG190, "ODDR"); the behavioural model registers both words on the rising edge and shows ``clk ? first : second``.

Open drain: a line is driven low when the system's ``*_oe`` is set with ``*_o`` = 0 and released (high impedance,
the board's pull-up makes it high) otherwise; the system never drives a line high (checked in simulation by
:class:`sim.system_bench.SystemBench`).

Clock domains: ``sync``, ``pix``, ``pix90``, ``mclk``, ``cam_a``, ``cam_b`` (all from :class:`GenesysClocking`).
Latency: as :class:`~hdl.system.StereoDepthSystem`; the CH7301C pins follow the video stream by one ``pix`` clock.
"""

from amaranth import Module, Mux
from amaranth.lib import io, wiring

from .ch7301c_output import split_rgb
from .clocking import PLAN, GenesysClocking
from .params import CEA_1080P60, SENSOR
from .system import CAMERAS, StereoDepthSystem
from .rejecting import rejecting

__all__ = ["GenesysTop", "board_plan"]


class GenesysTop(wiring.Component):
    """The Genesys board design. ``system_kwargs`` go to :class:`~hdl.system.StereoDepthSystem` (``ddr`` is
    always ``None`` here: the top level builds the CH7301C pins). Elaborate it with a
    :class:`hdl.genesys.GenesysPlatform` (``platform.prepare(GenesysTop())``)."""

    def __init__(self, geometry=SENSOR, timing=CEA_1080P60, *, plan=PLAN, **system_kwargs):
        with rejecting(self):
            if not (timing.hsync_positive and timing.vsync_positive):
                raise ValueError("the board output stage assumes positive sync polarities (CEA-861 1080p60)")
            if system_kwargs.pop("ddr", None) is not None:
                raise ValueError("GenesysTop builds the CH7301C pins itself (ddr must be None)")
        self.system = StereoDepthSystem(geometry, timing, ddr=None, **system_kwargs)
        self.clocking = GenesysClocking(plan, cam_domains=tuple(f"cam_{c}" for c in CAMERAS))
        super().__init__({})

    def elaborate(self, platform):
        if platform is None:
            raise TypeError("GenesysTop is a board top level: elaborate it with hdl.genesys.GenesysPlatform")
        m = Module()
        sys_ = self.system
        clocking = self.clocking
        m.domains += clocking.domains
        m.submodules.clocking = clocking
        m.submodules.system = sys_

        # Clock and reset inputs.
        m.submodules.clk_buf = clk_buf = io.Buffer("i", platform.request("clk100", dir="-"))
        m.submodules.rst_buf = rst_buf = io.Buffer("i", platform.request("rst", dir="-"))
        m.d.comb += [clocking.clk100.eq(clk_buf.i), clocking.button.eq(rst_buf.i)]

        # Switches and LEDs.
        m.submodules.sw_buf = sw_buf = io.Buffer("i", platform.request("switches", dir="-"))
        m.submodules.led_buf = led_buf = io.Buffer("o", platform.request("leds", dir="-"))
        m.d.comb += [sys_.sw.eq(sw_buf.i), led_buf.o.eq(sys_.leds)]

        def open_drain(name, port, o, oe, i):
            m.submodules[name] = b = io.Buffer("io", port)
            m.d.comb += [b.o.eq(0), b.oe.eq(oe & ~o), i.eq(b.i)]

        def output(name, port, value):
            m.submodules[name] = b = io.Buffer("o", port)
            m.d.comb += b.o.eq(value)

        # Cameras (VmodCAM): resource 0 = camera A (left), 1 = camera B (right).
        for number, c in enumerate(CAMERAS):
            cam = platform.request("vmodcam", number, dir="-")
            p = f"cam_{c}"
            for pin in ("data", "lv", "fv"):
                m.submodules[f"{p}_{pin}_buf"] = b = io.Buffer("i", getattr(cam, "d" if pin == "data" else pin))
                m.d.comb += getattr(sys_, f"{p}_{pin}").eq(b.i)
            m.submodules[f"{p}_pclk_buf"] = pclk = io.Buffer("i", cam.pclk)
            m.d.comb += clocking.cam_pclk[p].eq(pclk.i)
            m.submodules[f"{p}_mclk_oddr"] = mclk = io.DDRBuffer("o", cam.mclk, o_domain="mclk")
            m.d.comb += [mclk.o[0].eq(1), mclk.o[1].eq(0)]
            for line in ("scl", "sda"):
                open_drain(f"{p}_{line}_buf", getattr(cam, line), getattr(sys_, f"{p}_{line}_o"),
                           getattr(sys_, f"{p}_{line}_oe"), getattr(sys_, f"{p}_{line}_i"))
            output(f"{p}_rst_buf", cam.rst_n, sys_.cam_rst_n)
            output(f"{p}_pwdn_buf", cam.pwdn, sys_.cam_pwdn)
        output("cam_vdden_buf", platform.request("vmodcam_vdden", dir="-"), sys_.cam_vdden)

        # CH7301C: dual-edge data, IOB-registered syncs, XCLK pair from the 90-degree clock.
        ch = platform.request("ch7301c", dir="-")
        first, second = split_rgb(sys_.video_rgb)
        m.submodules.dvi_d_oddr = d = io.DDRBuffer("o", ch.d, o_domain="pix")
        m.d.comb += [d.o[0].eq(Mux(sys_.video_de, first, 0)), d.o[1].eq(Mux(sys_.video_de, second, 0))]
        for name, value in (("h", sys_.video_hsync), ("v", sys_.video_vsync), ("de", sys_.video_de)):
            m.submodules[f"dvi_{name}_ff"] = ff = io.FFBuffer("o", getattr(ch, name), o_domain="pix")
            m.d.comb += ff.o.eq(value)
        m.submodules.dvi_xclk_p_oddr = xp = io.DDRBuffer("o", ch.xclk_p, o_domain="pix90")
        m.submodules.dvi_xclk_n_oddr = xn = io.DDRBuffer("o", ch.xclk_n, o_domain="pix90")
        m.d.comb += [xp.o[0].eq(1), xp.o[1].eq(0), xn.o[0].eq(0), xn.o[1].eq(1)]
        output("dvi_reset_buf", ch.reset_n, sys_.dvi_reset_n)
        i2c = platform.request("ch7301c_i2c", dir="-")
        open_drain("dvi_scl_buf", i2c.scl, sys_.dvi_scl_o, sys_.dvi_scl_oe, sys_.dvi_scl_i)
        open_drain("dvi_sda_buf", i2c.sda, sys_.dvi_sda_o, sys_.dvi_sda_oe, sys_.dvi_sda_i)

        # Timing groups of the internal clocks (UCF PERIOD per BUFG output; hdl/genesys.py adds the TIGs
        # between unrelated groups).
        if hasattr(platform, "add_clock_group"):
            for signal, hz, family in clocking.clock_nets():
                platform.add_clock_group(signal, hz, family)
        return m


def board_plan(*, pins=None, allow_unconfirmed=False, files=None, name="top", **top_kwargs):
    """Prepare the ISE build of :class:`GenesysTop` (nothing is run): returns ``(platform, plan)``, ``plan`` an
    ``amaranth.build.BuildPlan`` whose ``files`` are the build directory's contents. See
    :class:`hdl.genesys.GenesysPlatform` for ``pins``, ``allow_unconfirmed`` and ``files``."""
    from .genesys import GenesysPlatform
    platform = GenesysPlatform(pins=pins, allow_unconfirmed=allow_unconfirmed, files=files)
    plan = platform.prepare(GenesysTop(**top_kwargs), name=name)
    return platform, plan
