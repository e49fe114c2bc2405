"""GenesysTop: the board top level -- StereoDepthSystem + board clocking + Genesys pins and IO buffers.

Pins (``board.genesys.GenesysPlatform`` resources) and what drives them:

=====================  ========================================================================================
``clk100``, ``rst``     input buffers -> :class:`~board.clocking.GenesysClocking` (oscillator, reset button)
``switches``            input buffers -> ``sw`` (synchronised inside :class:`~hdl.switches.SwitchControl`)
``leds``                output buffers <- ``leds`` (see :mod:`hdl.system` for the meaning of each LED)
``vmodcam`` 0/1         D, LV, FV: IOB input flip-flops clocked by the camera's PCLK (``io.FFBuffer``; the UCF's
                        OFFSET IN constrains them) -> ``cam_a``/``cam_b`` pins of the system (one PCLK later than
                        the pins, the same for all three); PCLK input buffer -> BUFG -> camera
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
the board's pull-up makes it high) otherwise; the system never drives a line high (checked in simulation by the
testbench's bus resolver, ``sim/models/i2c/bus.py``).

Clock domains: ``sync``, ``pix``, ``pix90``, ``mclk``, ``cam_a``, ``cam_b`` (all from :class:`GenesysClocking`);
with the DDR2 (``memory="ddr2"``) also ``mem`` (:class:`board.mig.GenesysDDR2`: the MIG core's ``clk0_tb``).
Latency: as :class:`~hdl.system.StereoDepthSystem`; the CH7301C pins follow the video stream by one ``pix`` clock.
"""

from amaranth import Module, Mux
from amaranth.lib import io, wiring

from hdl.ch7301c_output import split_rgb
from board.clocking import PLAN, GenesysClocking
from board.export import flat_name
from board.mig import DEFAULT_CORE_NAME, GenesysDDR2
from hdl.config import DesignConfig
from spec.sensor import SENSOR
from spec.video import CEA_1080P60
from hdl.stereo_display import MEMORIES
from hdl.system import CAMERAS, StereoDepthSystem, SystemParameters

__all__ = ["GenesysTop", "board_plan", "MEMORIES", "MIGCoreMissing"]


class GenesysTop(wiring.Component):
    """The Genesys board design: see the module docstring for the pins. Elaborate it with a
    :class:`board.genesys.GenesysPlatform` (``platform.prepare(GenesysTop())``); it has no ports of its own.

    Parameters
    ----------
    geometry, timing
        For :class:`~hdl.system.StereoDepthSystem`.
    plan : :class:`board.clocking.ClockPlan`
    memory : ``"bram"`` or ``"ddr2"``
        Where the system keeps the camera frames (:class:`~hdl.system.StereoDepthSystem`'s ``memory``, the design's
        :attr:`hdl.config.DesignConfig.memory`). ``"ddr2"``: the system's frame store on the DDR2 behind the user's
        MIG core (:class:`board.mig.GenesysDDR2`, submodule ``ddr2``, domain ``mem``), the system's ``mig`` port
        connected to the core's user interface. The build then needs the core's files (``stereodepth verilog
        --mig DIR``).
    mig_core : str
        The MIG core's top module name (CoreGen's component name).
    **system_kwargs
        For :class:`~hdl.system.StereoDepthSystem` (``ddr`` is always ``None`` here: the top level builds the
        CH7301C pins).

    Attributes
    ----------
    params : :class:`hdl.system.SystemParameters`
        The system's parameters. The system and the clocking are the submodules ``system`` and ``clocking``.

    Raises
    ------
    ValueError
        Negative sync polarities (the output stage assumes CEA-861 1080p60's), a ``ddr``, a ``memory`` not in
        :data:`MEMORIES`, the system's checks.
    TypeError
        Elaborated without a platform.
    """

    def __init__(self, geometry=SENSOR, timing=CEA_1080P60, *, plan=PLAN, memory="bram", mig_core=DEFAULT_CORE_NAME,
                 **system_kwargs):
        if not (timing.hsync_positive and timing.vsync_positive):
            raise ValueError("the board output stage assumes positive sync polarities (CEA-861 1080p60)")
        if system_kwargs.pop("ddr", None) is not None:
            raise ValueError("GenesysTop builds the CH7301C pins itself (ddr must be None)")
        if memory not in MEMORIES:
            raise ValueError(f"memory must be one of {', '.join(map(repr, MEMORIES))}, not {memory!r}")
        self.params = SystemParameters(geometry, timing, ddr=None, memory=memory, **system_kwargs)
        self.plan = plan
        self.memory = memory
        self.mig_core = mig_core
        super().__init__({})


    def elaborate(self, platform):
        if platform is None:
            raise TypeError("GenesysTop is a board top level: elaborate it with board.genesys.GenesysPlatform")
        m = Module()
        clocking = GenesysClocking(self.plan, cam_domains=tuple(f"cam_{c}" for c in CAMERAS))
        system = StereoDepthSystem(**vars(self.params))
        m.domains += clocking.domains
        m.submodules.clocking = clocking
        m.submodules.system = system
        self._clock_inputs(m, platform, clocking)
        self._panel(m, platform, system)
        for number, c in enumerate(CAMERAS):          # resource 0 = camera A (left), 1 = camera B (right)
            self._camera(m, platform, number, c, system, clocking)
        self._output(m, ("control", "cam_vdden"), platform.request("vmodcam_vdden", dir="-"),
                     system.control.cam_vdden)
        self._ch7301c(m, platform, system)
        if self.memory == "ddr2":
            self._ddr2(m, platform, clocking, system)
        # TIG groups of the clocks (board/ise.py: PERIODs sit on the clock pads only, ngdbuild derives the
        # DCM/PLL outputs; the TIG groups are second groups on the PLL output nets and the PCLK pads).
        if hasattr(platform, "add_tig_group"):
            for name, net, family in clocking.tig_groups():
                if isinstance(net, str):
                    number = CAMERAS.index(net.removeprefix("cam_"))
                    net = f"vmodcam_{number}__pclk__io"
                platform.add_tig_group(name, net, family)
        return m

    @staticmethod
    def _buffer(m, path, buffer):
        """Add an IO buffer as a submodule named after the system member it serves (``board.export.flat_name``)."""
        m.submodules[flat_name(path) + "_buf"] = buffer
        return buffer

    def _open_drain(self, m, path, port, pin):
        """An open-drain pad for ``pin`` (an ``OpenDrainSignature`` interface): pulled low while ``oe`` is set
        with ``o`` = 0, released otherwise."""
        b = self._buffer(m, path, io.Buffer("io", port))
        m.d.comb += [b.o.eq(0), b.oe.eq(pin.oe & ~pin.o), pin.i.eq(b.i)]

    def _output(self, m, path, port, value):
        b = self._buffer(m, path, io.Buffer("o", port))
        m.d.comb += b.o.eq(value)

    def _ddr2(self, m, platform, clocking, system):
        """The DDR2 (MIG core, its PLL, the ``mem`` domain), its user side on the system's ``mig`` port."""
        ddr2 = GenesysDDR2(self.mig_core)
        m.domains += ddr2.domains
        m.submodules.ddr2 = ddr2
        m.d.comb += [ddr2.clk100.eq(clocking.clock_signals["sync"]), ddr2.button.eq(clocking.button)]
        wiring.connect(m, system.mig, ddr2.user)

    def _clock_inputs(self, m, platform, clocking):
        clk = self._buffer(m, ("clk100",), io.Buffer("i", platform.request("clk100", dir="-")))
        rst = self._buffer(m, ("rst",), io.Buffer("i", platform.request("rst", dir="-")))
        m.d.comb += [clocking.clk100.eq(clk.i), clocking.button.eq(rst.i)]

    def _panel(self, m, platform, system):
        panel = system.panel
        sw = self._buffer(m, ("panel", "sw"), io.Buffer("i", platform.request("switches", dir="-")))
        m.d.comb += panel.sw.eq(sw.i)
        self._output(m, ("panel", "leds"), platform.request("leds", dir="-"), panel.leds)

    def _camera(self, m, platform, number, c, sys_, clocking):
        """VmodCAM resource ``number`` onto camera ``c``'s pins (of the system ``sys_``), I2C bus, PCLK (into
        ``clocking``) and MCLK."""
        name = f"cam_{c}"
        cam = platform.request("vmodcam", number, dir="-")
        pins = getattr(sys_, name)
        for pin, port in (("data", cam.d), ("lv", cam.lv), ("fv", cam.fv)):   # IOB input flip-flops (OFFSET IN)
            b = self._buffer(m, (name, pin), io.FFBuffer("i", port, i_domain=name))
            m.d.comb += getattr(pins, pin).eq(b.i)
        pclk = self._buffer(m, (name, "pclk"), io.Buffer("i", cam.pclk))
        m.d.comb += getattr(clocking.cam_pclk, name).eq(pclk.i)
        m.submodules[f"{name}_mclk_oddr"] = mclk = io.DDRBuffer("o", cam.mclk, o_domain="mclk")
        m.d.comb += [mclk.o[0].eq(1), mclk.o[1].eq(0)]
        bus = getattr(sys_.i2c, name)
        self._open_drain(m, ("i2c", name, "scl"), cam.scl, bus.scl)
        self._open_drain(m, ("i2c", name, "sda"), cam.sda, bus.sda)
        self._output(m, (name, "rst_n"), cam.rst_n, sys_.control.cam_rst_n)
        self._output(m, (name, "pwdn"), cam.pwdn, sys_.control.cam_pwdn)

    def _ch7301c(self, m, platform, sys_):
        """CH7301C (from the system ``sys_``): dual-edge data, IOB-registered syncs, XCLK pair from the 90-degree
        clock, its I2C bus."""
        video = sys_.video
        ch = platform.request("ch7301c", dir="-")
        first, second = split_rgb(video.rgb)
        m.submodules.dvi_d_oddr = d = io.DDRBuffer("o", ch.d, o_domain="pix")
        m.d.comb += [d.o[0].eq(Mux(video.de, first, 0)), d.o[1].eq(Mux(video.de, second, 0))]
        for name, value in (("h", video.hsync), ("v", video.vsync), ("de", video.de)):
            m.submodules[f"dvi_{name}_ff"] = ff = io.FFBuffer("o", getattr(ch, name), o_domain="pix")
            m.d.comb += ff.o.eq(value)
        m.submodules.dvi_xclk_p_oddr = xp = io.DDRBuffer("o", ch.xclk_p, o_domain="pix90")
        m.submodules.dvi_xclk_n_oddr = xn = io.DDRBuffer("o", ch.xclk_n, o_domain="pix90")
        m.d.comb += [xp.o[0].eq(1), xp.o[1].eq(0), xn.o[0].eq(0), xn.o[1].eq(1)]
        self._output(m, ("control", "dvi_reset_n"), ch.reset_n, sys_.control.dvi_reset_n)
        i2c = platform.request("ch7301c_i2c", dir="-")
        self._open_drain(m, ("i2c", "dvi", "scl"), i2c.scl, sys_.i2c.dvi.scl)
        self._open_drain(m, ("i2c", "dvi", "sda"), i2c.sda, sys_.i2c.dvi.sda)


class MIGCoreMissing(ValueError):
    """A board design with the DDR2 built without the user's MIG core (one line)."""


def board_plan(*, design=None, pins=None, allow_unconfirmed=False, files=None, name="top", mig=None,
               mig_black_box=False, **top_kwargs):
    """Prepare the ISE build of :class:`GenesysTop` for ``design`` (an :class:`hdl.config.DesignConfig`; ``None``:
    the board's, ``DesignConfig.full()``), nothing run: returns ``(platform, plan)``, ``plan`` an
    ``amaranth.build.BuildPlan`` whose ``files`` are the build directory's contents. ``top_kwargs`` override the
    design's :meth:`~hdl.config.DesignConfig.top_kwargs` (a short simulation's LED blink rates). See
    :class:`board.genesys.GenesysPlatform` for ``pins``, ``allow_unconfirmed``, ``files`` and ``mig`` (the user's
    MIG core, :func:`board.mig_core.read_mig_core`: the top then has the DDR2, ``memory="ddr2"``, with the core's
    name). ``mig_black_box``: a DDR2 build without the core's files, the core left an instance of its top module
    (``mig_core``, default :data:`board.mig.DEFAULT_CORE_NAME`) that nothing defines: for the Yosys estimates
    (given :func:`board.resources.board_black_boxes`) and the board-top simulation (given the MIG model behind MIG's
    port names, sim/board/top.py); never for ISE.

    Raises
    ------
    MIGCoreMissing
        The design has the DDR2 (``memory="ddr2"``: the design's ``top_kwargs`` or given here), ``mig`` is
        ``None`` and ``mig_black_box`` is not set.
    """
    from board.genesys import GenesysPlatform
    top_kwargs = {**(design or DesignConfig.full()).top_kwargs(), **top_kwargs}
    if mig is not None:
        top_kwargs.update(memory="ddr2", mig_core=mig.core_name)
    if mig is None and top_kwargs.get("memory") == "ddr2" and not mig_black_box:
        raise MIGCoreMissing("this design uses the DDR2 behind Xilinx MIG, whose core is not in the repository: "
                             "generate it in ISE CoreGen (docs/board.md, \"Generating the MIG core for the Genesys\") "
                             "and give its folder with --mig DIR")
    platform = GenesysPlatform(pins=pins, allow_unconfirmed=allow_unconfirmed, files=files, mig=mig)
    plan = platform.prepare(GenesysTop(**top_kwargs), name=name)
    return platform, plan
