"""Clock generation and per-domain resets: the Virtex-5 primitives for the board, a model for simulation.

Clock plan (:data:`PLAN`, checked by :meth:`ClockPlan.check`; docs/board.md has the same table):

==========  ===========================================================  ==============  =========
domain      source                                                       frequency       error
==========  ===========================================================  ==============  =========
``sync``    100 MHz oscillator (AG18) -> BUFG                            100 MHz         (board)
``mclk``    PLL_ADV ``pll_cam``: 100 MHz / D 1 x M 6 = VCO 600 MHz, / 25  24 MHz         0 ppm
``pix``     DCM_ADV ``dcm_pix`` CLKFX 100 x 11/10 = 110 MHz -> PLL_ADV    148.5 MHz       0 ppm
            ``pll_pix`` / D 5 x M 27 = VCO 594 MHz, CLKOUT0 / 4
``pix90``   ``pll_pix`` CLKOUT1 / 4, phase 90 degrees (CH7301C XCLK)       148.5 MHz       0 ppm
``cam_a/b`` each camera's PCLK pin -> BUFG                               sensor-driven
==========  ===========================================================  ==============  =========

Why not one DCM_ADV as in the thesis (4.4): one DCM's CLKFX gives 100 x M/D with M <= 32, D <= 32, and
148.5 / 100 = 297/200 has no such fraction; the 24 MHz camera clock and the pixel clock cannot share a PLL VCO
either (148.5 needs the factor 297 = 27 x 11). So the pixel clock is made in two exact steps, a DCM_ADV (x 11/10)
feeding a PLL_ADV (x 27/5 / 4) -- the DCM-to-PLL cascade is a supported configuration (``COMPENSATION =
"DCM2PLL"`` exists on PLL_ADV) -- and that PLL also gives the 90-degree copy the CH7301C's XCLK needs so its edges
sit in the middle of the data eye. The camera's 24 MHz comes from a second PLL_ADV rather than a DCM CLKFX
(the thesis's 100 / 25 x 6): 24 MHz is far below the CLKFX frequencies we could confirm as legal, while a PLL
output divider reaches it from a mid-range VCO. Attribute ranges used by :meth:`ClockPlan.check` are those the
Xilinx unisim simulation models enforce (stored copies of ``DCM_ADV.v`` and ``PLL_ADV.v``: CLKFX_MULTIPLY 2..32,
CLKFX_DIVIDE 1..32; CLKFBOUT_MULT 1..74 (64 for ISE), DIVCLK_DIVIDE 1..52, CLKOUTn_DIVIDE 1..128, VCO 400 MHz and
up, PFD and CLKIN 19 MHz and up); the DS202 speed-grade maxima could not be read here, so the plan keeps well
inside them (VCO 594/600 MHz, nothing above 150 MHz).

Resets: every domain's reset is asserted asynchronously while the reset button is pressed or any DCM/PLL is
unlocked, and released synchronously to that domain's clock (``amaranth.lib.cdc.ResetSynchronizer``, two
flip-flops). The simulation model (:class:`sim.models.clocking.SimClocking`) has the same reset tree; its "lock" is a counter of
``lock_cycles`` oscillator clocks, and its clocks are the simulator's (each domain at its real frequency).

Clock domains driven: ``sync``, ``pix`` and the camera domains (both versions); ``pix90`` and ``mclk``
(board only: they only drive output buffers). The blocks drive the domains' clocks and resets but do not define
them (a domain defined in a child and used by its siblings is deprecated in Amaranth 0.5): the parent adds
``clocking.domains`` to its module. Latency: a domain leaves reset 2 to 3 of its own clocks after
``locked`` rises (synchroniser depth 2).
"""

from dataclasses import dataclass
from fractions import Fraction

from amaranth import ClockDomain, ClockSignal, Const, Instance, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.reset_tree import add_reset_tree
from spec.board import CLOCKS
from spec.memory import MIG
from spec.video import CEA_1080P60

__all__ = ["ClockPlan", "PLAN", "GenesysClocking", "MIGClockPlan", "MIG_PLAN", "MIGClocking"]

# Attribute ranges from the Xilinx unisim simulation models (DCM_ADV.v, PLL_ADV.v; see the module docstring).
DCM_M_RANGE = (2, 32)
DCM_D_RANGE = (1, 32)
PLL_M_RANGE = (1, 64)      # the model allows 74; ISE's PLL_ADV documentation limit is 64: keep the stricter one
PLL_D_RANGE = (1, 52)
PLL_O_RANGE = (1, 128)
PLL_VCO_MIN_HZ = 400e6
PLL_VCO_SAFE_MAX_HZ = 1000e6   # conservative: below the -1 speed grade's maximum as far as we know (unverified)
PLL_PFD_MIN_HZ = 19e6
PLL_CLKIN_MIN_HZ = 19e6


@dataclass(frozen=True)
class ClockPlan:
    """M/D/O values of the board's clock primitives and the frequencies they give (exact fractions)."""
    osc_hz: int = CLOCKS.SYS_HZ
    # PLL_ADV "pll_cam": camera MCLK
    cam_pll_d: int = 1
    cam_pll_m: int = 6
    cam_pll_o: int = 25
    # DCM_ADV "dcm_pix" (CLKFX) -> PLL_ADV "pll_pix"
    dcm_m: int = 11
    dcm_d: int = 10
    pix_pll_d: int = 5
    pix_pll_m: int = 27
    pix_pll_o: int = 4
    xclk_phase_deg: float = 90.0

    @property
    def cam_vco_hz(self):
        return Fraction(self.osc_hz * self.cam_pll_m, self.cam_pll_d)

    @property
    def mclk_hz(self):
        return self.cam_vco_hz / self.cam_pll_o

    @property
    def dcm_fx_hz(self):
        return Fraction(self.osc_hz * self.dcm_m, self.dcm_d)

    @property
    def pix_pfd_hz(self):
        return self.dcm_fx_hz / self.pix_pll_d

    @property
    def pix_vco_hz(self):
        return self.pix_pfd_hz * self.pix_pll_m

    @property
    def pix_hz(self):
        return self.pix_vco_hz / self.pix_pll_o

    def error_ppm(self, actual, target):
        return float((Fraction(actual) - Fraction(target)) / Fraction(target) * 1_000_000)

    def check(self):
        """Raise ``ValueError`` if any attribute or frequency is outside the ranges in the module docstring."""
        def rng(name, value, lo, hi):
            if not lo <= value <= hi:
                raise ValueError(f"{name} = {value} is outside {lo}..{hi}")
        rng("DCM CLKFX_MULTIPLY", self.dcm_m, *DCM_M_RANGE)
        rng("DCM CLKFX_DIVIDE", self.dcm_d, *DCM_D_RANGE)
        for pll, d, m, o, vco, pfd, clkin in (
                ("pll_cam", self.cam_pll_d, self.cam_pll_m, self.cam_pll_o, self.cam_vco_hz,
                 Fraction(self.osc_hz, self.cam_pll_d), self.osc_hz),
                ("pll_pix", self.pix_pll_d, self.pix_pll_m, self.pix_pll_o, self.pix_vco_hz,
                 self.pix_pfd_hz, self.dcm_fx_hz)):
            rng(f"{pll} DIVCLK_DIVIDE", d, *PLL_D_RANGE)
            rng(f"{pll} CLKFBOUT_MULT", m, *PLL_M_RANGE)
            rng(f"{pll} CLKOUT_DIVIDE", o, *PLL_O_RANGE)
            if not PLL_VCO_MIN_HZ <= vco <= PLL_VCO_SAFE_MAX_HZ:
                raise ValueError(f"{pll} VCO {float(vco) / 1e6:.3f} MHz outside 400..1000 MHz")
            if pfd < PLL_PFD_MIN_HZ:
                raise ValueError(f"{pll} PFD {float(pfd) / 1e6:.3f} MHz below 19 MHz")
            if clkin < PLL_CLKIN_MIN_HZ:
                raise ValueError(f"{pll} CLKIN {float(clkin) / 1e6:.3f} MHz below 19 MHz")
        return self

    def table(self):
        """Rows ``(domain, how, frequency_hz, target_hz, error_ppm)`` for documentation and the CLI."""
        rows = [
            ("sync", "100 MHz oscillator -> BUFG", self.osc_hz, CLOCKS.SYS_HZ),
            ("mclk", f"PLL_ADV pll_cam: /{self.cam_pll_d} x{self.cam_pll_m} (VCO "
                     f"{float(self.cam_vco_hz) / 1e6:g} MHz) /{self.cam_pll_o}", self.mclk_hz, CLOCKS.CAM_MCLK_HZ),
            ("pix", f"DCM_ADV dcm_pix CLKFX x{self.dcm_m}/{self.dcm_d} = {float(self.dcm_fx_hz) / 1e6:g} MHz -> "
                    f"PLL_ADV pll_pix /{self.pix_pll_d} x{self.pix_pll_m} (VCO {float(self.pix_vco_hz) / 1e6:g} "
                    f"MHz) /{self.pix_pll_o}", self.pix_hz, CEA_1080P60.pixel_hz),
            ("pix90", f"pll_pix CLKOUT1 /{self.pix_pll_o}, phase {self.xclk_phase_deg:g} deg",
             self.pix_hz, CEA_1080P60.pixel_hz),
        ]
        return [(d, how, float(f), float(t), self.error_ppm(f, t)) for d, how, f, t in rows]


#: The clock plan of the board build.
PLAN = ClockPlan().check()


class GenesysClocking(wiring.Component):
    """Board clocking: BUFGs, DCM_ADV ``dcm_pix``, PLL_ADVs ``pll_pix`` and ``pll_cam``, per-domain resets.

    Parameters
    ----------
    plan : :class:`ClockPlan`
    cam_domains : tuple of str
        The camera domains, each clocked by its camera's PCLK.

    Attributes
    ----------
    clk100 : ``In(1)``
        The oscillator pin's input buffer output.
    button : ``In(1)``
        The reset button, active high.
    cam_pclk : ``In`` one bit per camera domain
        Each camera's PCLK input buffer output.
    locked : ``Out(1)``
        All DCM/PLLs locked (asynchronous).
    domains : list of ClockDomain
        ``sync``, ``pix``, ``pix90``, ``mclk`` and the camera domains, which this block drives and the parent adds
        to its module.

    Not simulatable (vendor primitives): :class:`sim.models.clocking.SimClocking` is its simulation model.

    Raises
    ------
    ValueError
        A plan outside the primitives' ranges (:meth:`ClockPlan.check`).
    """

    def __init__(self, plan=PLAN, *, cam_domains=("cam_a", "cam_b")):
        self.plan = plan.check()
        self.cam_domains = tuple(cam_domains)
        super().__init__({
            "clk100": In(1), "button": In(1), "locked": Out(1),
            "cam_pclk": In(wiring.Signature({name: Out(1) for name in self.cam_domains})),
        })
        self.domain_names = ("sync", "pix", "pix90", "mclk", *self.cam_domains)
        #: The clock domains this block drives; the parent adds them: ``m.domains += clocking.domains``.
        self.domains = [ClockDomain(name) for name in self.domain_names]
        #: The global clock nets (BUFG outputs), one per domain.
        #: (``keep``: the Yosys resource estimate, board/resources.py, finds each domain's clock by this name;
        #: the board's top.v drops the attribute, board/export.py.)
        self.clock_signals = {name: Signal(name=f"{name}_bufg", attrs={"keep": "TRUE"})
                              for name in self.domain_names}
        #: The PLL output nets (before their BUFGs), by domain; named, as the UCF's TIG groups sit on them
        #: (board/ise.py) and a net needs one name for that.
        self.pll_outputs = {"mclk": Signal(name="pll_cam_clkout0"), "pix": Signal(name="pll_pix_clkout0"),
                            "pix90": Signal(name="pll_pix_clkout1")}

    def tig_groups(self):
        """``(name, net, family)`` per clock for the UCF's TIG groups: ``net`` is the DCM/PLL output net (a signal,
        valid once elaborated) for the derived clocks, or the camera's name for the PCLK-driven domains (the top
        level puts those on the PCLK pad). Clocks of the same family are related (``pix`` and ``pix90`` come
        from one PLL); clocks of different families get a TIG between them. ``sync`` has no group: its only
        clock net also feeds the DCM/PLL inputs, and a TNM used in a FROM-TO there stops ngdbuild deriving the
        DCM/PLL clocks (docs/board.md)."""
        out = [("mclk", self.pll_outputs["mclk"], "mclk"), ("pix", self.pll_outputs["pix"], "pix"),
               ("pix90", self.pll_outputs["pix90"], "pix")]
        out += [(name, name, name) for name in self.cam_domains]
        return out

    def elaborate(self, platform):
        m = Module()
        p = self.plan
        g = self.clock_signals

        def bufg(name, i, o):
            m.submodules[name] = Instance("BUFG", i_I=i, o_O=o)

        osc = g["sync"]
        bufg("bufg_sync", self.clk100, osc)
        m.d.comb += ClockSignal("sync").eq(osc)

        # Camera MCLK: PLL_ADV, internal feedback (no phase relation to anything is needed).
        cam_fb, cam_out, cam_locked = Signal(name="pll_cam_fb"), self.pll_outputs["mclk"], Signal(name="cam_locked")
        m.submodules.pll_cam = Instance(
            "PLL_ADV",
            p_SIM_DEVICE="VIRTEX5", p_BANDWIDTH="OPTIMIZED", p_COMPENSATION="INTERNAL",
            p_CLKIN1_PERIOD=1e9 / p.osc_hz, p_DIVCLK_DIVIDE=p.cam_pll_d, p_CLKFBOUT_MULT=p.cam_pll_m,
            p_CLKOUT0_DIVIDE=p.cam_pll_o, p_CLKOUT0_PHASE=0.0, p_CLKOUT0_DUTY_CYCLE=0.5,
            p_RESET_ON_LOSS_OF_LOCK="FALSE",
            i_CLKIN1=osc, i_CLKIN2=Const(0, 1), i_CLKINSEL=Const(1, 1),
            i_CLKFBIN=cam_fb, o_CLKFBOUT=cam_fb, o_CLKOUT0=cam_out, o_LOCKED=cam_locked,
            i_RST=self.button, i_REL=Const(0, 1),
            i_DCLK=Const(0, 1), i_DEN=Const(0, 1), i_DWE=Const(0, 1), i_DADDR=Const(0, 5), i_DI=Const(0, 16),
        )
        mclk = g["mclk"]
        bufg("bufg_mclk", cam_out, mclk)
        m.d.comb += ClockSignal("mclk").eq(mclk)

        # Pixel clock: DCM_ADV CLKFX -> PLL_ADV (DCM2PLL), CLKOUT0 at 0 degrees, CLKOUT1 at 90 degrees.
        dcm_fx, dcm_locked = Signal(name="dcm_pix_clkfx"), Signal(name="dcm_locked")
        m.submodules.dcm_pix = Instance(
            "DCM_ADV",
            p_SIM_DEVICE="VIRTEX5", p_CLKIN_PERIOD=1e9 / p.osc_hz,
            p_CLKFX_MULTIPLY=p.dcm_m, p_CLKFX_DIVIDE=p.dcm_d, p_CLK_FEEDBACK="NONE",
            p_DFS_FREQUENCY_MODE="LOW", p_DLL_FREQUENCY_MODE="LOW", p_CLKOUT_PHASE_SHIFT="NONE",
            p_DCM_AUTOCALIBRATION="TRUE", p_STARTUP_WAIT="FALSE",
            i_CLKIN=osc, i_CLKFB=Const(0, 1), i_RST=self.button,
            i_PSCLK=Const(0, 1), i_PSEN=Const(0, 1), i_PSINCDEC=Const(0, 1),
            i_DCLK=Const(0, 1), i_DEN=Const(0, 1), i_DWE=Const(0, 1), i_DADDR=Const(0, 7), i_DI=Const(0, 16),
            o_CLKFX=dcm_fx, o_LOCKED=dcm_locked,
        )
        pix_fb, pix_out, pix90_out = Signal(name="pll_pix_fb"), self.pll_outputs["pix"], self.pll_outputs["pix90"]
        pix_locked = Signal(name="pix_locked")
        m.submodules.pll_pix = Instance(
            "PLL_ADV",
            p_SIM_DEVICE="VIRTEX5", p_BANDWIDTH="OPTIMIZED", p_COMPENSATION="DCM2PLL",
            p_CLKIN1_PERIOD=float(1e9 / p.dcm_fx_hz), p_DIVCLK_DIVIDE=p.pix_pll_d, p_CLKFBOUT_MULT=p.pix_pll_m,
            p_CLKOUT0_DIVIDE=p.pix_pll_o, p_CLKOUT0_PHASE=0.0, p_CLKOUT0_DUTY_CYCLE=0.5,
            p_CLKOUT1_DIVIDE=p.pix_pll_o, p_CLKOUT1_PHASE=float(p.xclk_phase_deg), p_CLKOUT1_DUTY_CYCLE=0.5,
            p_RESET_ON_LOSS_OF_LOCK="FALSE",
            i_CLKIN1=dcm_fx, i_CLKIN2=Const(0, 1), i_CLKINSEL=Const(1, 1),
            i_CLKFBIN=pix_fb, o_CLKFBOUT=pix_fb, o_CLKOUT0=pix_out, o_CLKOUT1=pix90_out, o_LOCKED=pix_locked,
            i_RST=self.button | ~dcm_locked, i_REL=Const(0, 1),
            i_DCLK=Const(0, 1), i_DEN=Const(0, 1), i_DWE=Const(0, 1), i_DADDR=Const(0, 5), i_DI=Const(0, 16),
        )
        pix, pix90 = g["pix"], g["pix90"]
        bufg("bufg_pix", pix_out, pix)
        bufg("bufg_pix90", pix90_out, pix90)
        m.d.comb += [ClockSignal("pix").eq(pix), ClockSignal("pix90").eq(pix90)]

        for name in self.cam_domains:
            clk = g[name]
            bufg(f"bufg_{name}", getattr(self.cam_pclk, name), clk)
            m.d.comb += ClockSignal(name).eq(clk)

        m.d.comb += self.locked.eq(cam_locked & dcm_locked & pix_locked)
        add_reset_tree(m, self.domain_names, self.button | ~self.locked)
        return m


# --- the DDR2 controller's clocks ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class MIGClockPlan:
    """The clocks a MIG 3.x DDR2 core generated with "DCM disabled" takes from the design (its ports ``clk0``,
    ``clk90``, ``clkdiv0``, ``clk200``, ``locked``): one PLL_BASE ``pll_mem`` from the 100 MHz oscillator.

    The settings are those of the one public MIG design for this board (freecores/genesys_ddr2
    ``rtl/clkGenPLL.v``: ``CLKIN_PERIOD`` 10 ns, ``DIVCLK_DIVIDE`` 1, ``CLKFBOUT_MULT`` 10 (VCO 1 GHz),
    ``CLKOUT0_DIVIDE`` 8, ``CLKOUT1_DIVIDE`` 8 at 90 degrees, ``CLKOUT2_DIVIDE`` 16, ``CLKOUT3_DIVIDE`` 5,
    ``BANDWIDTH`` ``"OPTIMIZED"``, ``COMPENSATION`` ``"SYSTEM_SYNCHRONOUS"``, ``CLKFBOUT`` straight back to
    ``CLKFBIN``; a BUFG on each output: ``rtl/DDR2_Mem.v``). 1 GHz is the only VCO in 400..1000 MHz that gives both
    125 MHz and 200 MHz (it must be a multiple of both); it is this project's upper VCO bound
    (:data:`PLL_VCO_SAFE_MAX_HZ`).
    """
    osc_hz: int = CLOCKS.SYS_HZ
    d: int = 1
    m: int = 10
    clk0_o: int = 8
    clk90_phase_deg: float = 90.0
    clkdiv0_o: int = 16
    clk200_o: int = 5

    @property
    def vco_hz(self):
        return Fraction(self.osc_hz * self.m, self.d)

    @property
    def clk0_hz(self):
        return self.vco_hz / self.clk0_o

    @property
    def clkdiv0_hz(self):
        return self.vco_hz / self.clkdiv0_o

    @property
    def clk200_hz(self):
        return self.vco_hz / self.clk200_o

    def outputs(self):
        """``(name, CLKOUTn_DIVIDE, CLKOUTn_PHASE)`` for CLKOUT0..3, in MIG's port names."""
        return (("clk0", self.clk0_o, 0.0), ("clk90", self.clk0_o, float(self.clk90_phase_deg)),
                ("clkdiv0", self.clkdiv0_o, 0.0), ("clk200", self.clk200_o, 0.0))

    def check(self):
        """Raise ``ValueError`` if an attribute is outside the PLL's ranges (as :meth:`ClockPlan.check`) or a clock
        is not the frequency the core expects (``spec.memory.MIG``: clk0, clkdiv0 = clk0 / 2, clk200)."""
        for name, value, (lo, hi) in (("pll_mem DIVCLK_DIVIDE", self.d, PLL_D_RANGE),
                                      ("pll_mem CLKFBOUT_MULT", self.m, PLL_M_RANGE),
                                      *((f"pll_mem {n} divide", o, PLL_O_RANGE) for n, o, _ in self.outputs())):
            if not lo <= value <= hi:
                raise ValueError(f"{name} = {value} is outside {lo}..{hi}")
        if not PLL_VCO_MIN_HZ <= self.vco_hz <= PLL_VCO_SAFE_MAX_HZ:
            raise ValueError(f"pll_mem VCO {float(self.vco_hz) / 1e6:.3f} MHz outside 400..1000 MHz")
        if Fraction(self.osc_hz, self.d) < PLL_PFD_MIN_HZ:
            raise ValueError("pll_mem PFD below 19 MHz")
        for name, actual, target in (("clk0", self.clk0_hz, MIG.CLK0_HZ), ("clkdiv0", self.clkdiv0_hz, MIG.CLKDIV0_HZ),
                                     ("clk200", self.clk200_hz, MIG.CLK200_HZ)):
            if actual != target:
                raise ValueError(f"pll_mem {name} = {float(actual) / 1e6:g} MHz, the core needs "
                                 f"{target / 1e6:g} MHz")
        return self

    def table(self):
        """Rows ``(domain, how, frequency_hz, target_hz, error_ppm)`` as :meth:`ClockPlan.table`."""
        vco = f"PLL_BASE pll_mem /{self.d} x{self.m} (VCO {float(self.vco_hz) / 1e6:g} MHz)"
        rows = [("mem", f"{vco} /{self.clk0_o}: MIG clk0 (clk0_tb)", self.clk0_hz, MIG.CLK0_HZ),
                ("clk90", f"pll_mem /{self.clk0_o}, phase {self.clk90_phase_deg:g} deg: MIG clk90", self.clk0_hz,
                 MIG.CLK0_HZ),
                ("clkdiv0", f"pll_mem /{self.clkdiv0_o}: MIG clkdiv0", self.clkdiv0_hz, MIG.CLKDIV0_HZ),
                ("clk200", f"pll_mem /{self.clk200_o}: MIG clk200 (IDELAYCTRL)", self.clk200_hz, MIG.CLK200_HZ)]
        return [(d, how, float(f), float(t), float((f - t) / t * 1_000_000)) for d, how, f, t in rows]


#: The DDR2 controller's clock plan.
MIG_PLAN = MIGClockPlan().check()


class MIGClocking(wiring.Component):
    """The clocks of a MIG DDR2 core with "DCM disabled": PLL_BASE ``pll_mem`` and a BUFG on each output
    (:class:`MIGClockPlan`).

    Parameters
    ----------
    plan : :class:`MIGClockPlan`

    Attributes
    ----------
    clk100 : ``In(1)``
        The oscillator's global clock (the ``sync`` BUFG).
    button : ``In(1)``
        The reset button, active high: resets the PLL.
    clk0, clk90, clkdiv0, clk200 : ``Out(1)``
        The BUFG outputs, for the core's ports of the same names.
    locked : ``Out(1)``
        The PLL's LOCKED, for the core's ``locked`` (asynchronous).
    pll_outputs : dict of str to Signal
        The PLL output nets (before their BUFGs) by port name, named ``pll_mem_clkout<n>``: the UCF's clock groups
        sit on them (board/ise.py, board/mig_ucf.py).

    Not simulatable in Amaranth (vendor primitives); ``sim/board/xilinx/PLL_BASE.v`` models the PLL.

    Raises
    ------
    ValueError
        A plan outside the PLL's ranges (:meth:`MIGClockPlan.check`).
    """

    def __init__(self, plan=MIG_PLAN):
        self.plan = plan.check()
        super().__init__({"clk100": In(1), "button": In(1), "clk0": Out(1), "clk90": Out(1), "clkdiv0": Out(1),
                          "clk200": Out(1), "locked": Out(1)})
        self.pll_outputs = {name: Signal(name=f"pll_mem_clkout{n}") for n, (name, _, _) in enumerate(plan.outputs())}

    def elaborate(self, platform):
        m = Module()
        p = self.plan
        outputs = {}
        for n, (name, divide, phase) in enumerate(p.outputs()):
            outputs.update({f"p_CLKOUT{n}_DIVIDE": divide, f"p_CLKOUT{n}_PHASE": phase,
                            f"p_CLKOUT{n}_DUTY_CYCLE": 0.5, f"o_CLKOUT{n}": self.pll_outputs[name]})
            m.submodules[f"bufg_{name}"] = Instance("BUFG", i_I=self.pll_outputs[name], o_O=getattr(self, name))
        feedback = Signal(name="pll_mem_fb")
        m.submodules.pll_mem = Instance(
            "PLL_BASE",
            p_BANDWIDTH="OPTIMIZED", p_COMPENSATION="SYSTEM_SYNCHRONOUS", p_CLKIN_PERIOD=1e9 / p.osc_hz,
            p_DIVCLK_DIVIDE=p.d, p_CLKFBOUT_MULT=p.m, p_CLKFBOUT_PHASE=0.0, p_REF_JITTER=0.1, **outputs,
            i_CLKIN=self.clk100, i_CLKFBIN=feedback, o_CLKFBOUT=feedback, o_LOCKED=self.locked, i_RST=self.button,
        )
        return m
