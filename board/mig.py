"""The Genesys DDR2 behind a Xilinx MIG 3.x core that the user generates in ISE CoreGen (docs/board.md,
"Generating the MIG core for the Genesys"): the core as a black box, its clocks, and the ``mem`` domain.

MIG's generated files carry Xilinx's licence, so none is in this repository: the board's ``top.v`` instantiates
the core's top module by name (the component name chosen in CoreGen, :data:`DEFAULT_CORE_NAME` unless given), and
``stereodepth verilog --mig DIR`` adds the user's ``DIR/user_design/rtl/*.v`` to the ISE build and merges
``DIR/user_design/par/*.ucf`` into ``top.ucf`` (:mod:`board.mig_core`, :mod:`board.mig_ucf`).

The core's top module, as MIG 3.6.1 writes it for this board (freecores/genesys_ddr2,
``rtl/ipcore_dir/MEMCtrl/user_design/rtl/MEMCtrl.v``; the port table of /work/shared/ddr2-facts.md, docs/board.md):
:data:`MIG_PORTS` (every port, its direction and width) and :data:`MIG_PARAMETERS` (the parameters this design
depends on, passed explicitly). The widths of the memory pins come from the board's ``ddr2`` resource
(:data:`board.genesys.DDR2_SUBSIGNALS`), the user interface's from ``spec.memory.MIG``.

Clocks ("DCM disabled"): the design gives the core ``clk0`` (125 MHz), ``clk90``, ``clkdiv0`` (62.5 MHz),
``clk200`` (IDELAYCTRL reference) and ``locked`` from :class:`board.clocking.MIGClocking`. The core's ``clk0_tb``
is its ``clk0`` passed through (``assign clk0_tb = clk0``) and ``rst0_tb`` its ``clk0``-synchronous reset (released
25 ``clk0`` clocks after ``sys_rst_n`` is high, ``locked`` is high and the IDELAYCTRL is ready:
``ddr2_infrastructure.v``); they drive the ``mem`` domain, in which every ``app_*`` signal is synchronous.
Reset: ``sys_rst_n`` is active low (``RST_ACT_LOW = 1``) and held low while the reset button is pressed.
"""

from amaranth import ClockDomain, ClockSignal, Instance, Module, ResetSignal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from board.clocking import MIG_PLAN, MIGClocking
from board.genesys import DDR2_SUBSIGNALS
from hdl.mig_user import MIGUserSignature
from spec.memory import MIG

__all__ = ["DEFAULT_CORE_NAME", "MIG_PARAMETERS", "MIG_PORTS", "MIG_CLOCK_PORTS", "MIG_USER_PORTS", "MIGCore",
           "GenesysDDR2", "black_box_verilog"]

#: The core's component name when none is given (CoreGen's "Component Name"; the top module's name).
DEFAULT_CORE_NAME = "mig_ddr2"


def _width(name):
    return len(DDR2_SUBSIGNALS[name][1].split())


#: The parameters the instance passes (the generated module's values for this board; MEMCtrl.v): the widths of
#: the memory pins, the user word, the burst, the clock period in ps, the active-low reset. The memory's timing
#: parameters (TRCD, TRFC, ...) are left at the generated module's values.
MIG_PARAMETERS = {
    "BANK_WIDTH": MIG.BANK_BITS, "CKE_WIDTH": _width("cke"), "CLK_WIDTH": _width("ck"), "COL_WIDTH": MIG.COL_BITS,
    "CS_NUM": 1, "CS_WIDTH": _width("cs_n"), "DM_WIDTH": _width("dm"), "DQ_WIDTH": _width("dq"),
    "DQ_PER_DQS": _width("dq") // _width("dqs"), "DQS_WIDTH": _width("dqs"), "ODT_WIDTH": _width("odt"),
    "ROW_WIDTH": MIG.ROW_BITS, "BURST_LEN": MIG.BURST_LENGTH, "APPDATA_WIDTH": MIG.DATA_WIDTH,
    "CLK_PERIOD": 10**12 // MIG.CLK0_HZ, "RST_ACT_LOW": 1,
}

#: The clock and reset ports of the core ("DCM disabled"), all inputs but ``clk0_tb`` / ``rst0_tb``.
MIG_CLOCK_PORTS = ("clk0", "clk90", "clkdiv0", "clk200", "locked", "sys_rst_n")

#: The user interface's ports: MIG's name -> (direction, width, path in :class:`~hdl.mig_user.MIGUserSignature`).
_USER_PORTS = {
    "app_af_cmd": ("input", MIG.CMD_WIDTH, ("command", "cmd")),
    "app_af_addr": ("input", MIG.ADDR_WIDTH, ("command", "addr")),
    "app_af_wren": ("input", 1, ("command", "wren")),
    "app_af_afull": ("output", 1, ("command", "afull")),
    "app_wdf_data": ("input", MIG.DATA_WIDTH, ("write", "data")),
    "app_wdf_mask_data": ("input", MIG.MASK_WIDTH, ("write", "mask")),
    "app_wdf_wren": ("input", 1, ("write", "wren")),
    "app_wdf_afull": ("output", 1, ("write", "afull")),
    "rd_data_fifo_out": ("output", MIG.DATA_WIDTH, ("read", "data")),
    "rd_data_valid": ("output", 1, ("read", "valid")),
    "phy_init_done": ("output", 1, ("phy_init_done",)),
}

_PIN_DIRECTION = {"io": "inout", "o": "output"}

#: Every port of the core's top module: name -> (direction, width), in the generated module's terms.
MIG_PORTS = {
    **{f"ddr2_{name}": (_PIN_DIRECTION[direction], len(pins.split()))
       for name, (direction, pins, _) in DDR2_SUBSIGNALS.items()},
    **{name: ("input", 1) for name in MIG_CLOCK_PORTS},
    "clk0_tb": ("output", 1), "rst0_tb": ("output", 1),
    **{name: (direction, width) for name, (direction, width, _) in _USER_PORTS.items()},
}


#: The user interface's ports (all synchronous to ``clk0``/``clk0_tb``): MIG's name -> the member's path in
#: :class:`~hdl.mig_user.MIGUserSignature`.
MIG_USER_PORTS = {name: path for name, (_, _, path) in _USER_PORTS.items()}


def black_box_verilog(core_name=DEFAULT_CORE_NAME):
    """A Verilog declaration of the core's top module as a black box (``(* blackbox *)``: its ports,
    :data:`MIG_PORTS`, and the parameters :class:`MIGCore` sets, with this board's values), for Yosys runs of a DDR2
    build without the core's files (the resource and timing estimates: ``read_verilog -lib``, see
    ``board.resources.run_yosys``). Verilog, not RTLIL: Yosys derives a parametrised black box (as ABC9 does for
    every instance) only for a module it read from Verilog. The core's cells are not counted by Yosys."""
    parameters = ", ".join(f"parameter {name} = {value}" for name, value in {"SIM_ONLY": 0, **MIG_PARAMETERS}.items())
    ports = ",\n".join(f"  {direction} [{width - 1}:0] {name}" for name, (direction, width) in MIG_PORTS.items())
    return f"(* blackbox *)\nmodule {_checked_core_name(core_name)} #({parameters}) (\n{ports}\n);\nendmodule\n"


def _checked_core_name(name):
    if not (name.isidentifier() and name.isascii()):
        raise ValueError(f"MIG core name {name!r} is not a Verilog identifier")
    return name


class MIGCore(wiring.Component):
    """The user's MIG core as a black box: an instance of its top module ``core_name`` with the board's DDR2 pins.

    Elaborate it on a :class:`board.genesys.GenesysPlatform`: it requests the ``ddr2`` resource and connects each
    pin port straight to the core's port of the same name (the core has the IO buffers). ``elaborate`` returns
    the instance itself, so the core's hierarchy starts at this component's submodule name (``mig`` in
    :class:`GenesysDDR2`); the core's UCF names its internal cells with ``*/`` wildcard paths, which match there.

    Parameters
    ----------
    core_name : str
        The core's top module (CoreGen's component name).
    sim_only : bool
        The core's ``SIM_ONLY`` (1 skips the memory's 200 us power-up wait; for simulation only).

    Attributes
    ----------
    user : ``In(MIGUserSignature())``
        The user interface, the controller's side (``mem`` domain: ``clk0_tb``).
    clk0, clk90, clkdiv0, clk200, locked : ``In(1)``
        From :class:`board.clocking.MIGClocking`.
    sys_rst_n : ``In(1)``
        The core's reset, active low.
    clk0_tb, rst0_tb : ``Out(1)``
        The ``mem`` domain's clock and reset.

    Raises
    ------
    ValueError
        A core name that is not a Verilog identifier.
    TypeError
        Elaborated without a platform.
    """

    def __init__(self, core_name=DEFAULT_CORE_NAME, *, sim_only=False):
        self.core_name = _checked_core_name(core_name)
        self.sim_only = sim_only
        super().__init__({
            "user": In(MIGUserSignature()),
            **{name: In(1) for name in MIG_CLOCK_PORTS},
            "clk0_tb": Out(1), "rst0_tb": Out(1),
        })

    def elaborate(self, platform):
        if platform is None:
            raise TypeError("MIGCore instantiates the user's MIG core: elaborate it with board.genesys.GenesysPlatform")
        pins = platform.request("ddr2", 0, dir="-")
        ports = {}
        for name, (direction, _, _) in DDR2_SUBSIGNALS.items():
            prefix = "io" if direction == "io" else "o"
            ports[f"{prefix}_ddr2_{name}"] = getattr(pins, name).io
        for name in MIG_CLOCK_PORTS:
            ports[f"i_{name}"] = getattr(self, name)
        ports.update(o_clk0_tb=self.clk0_tb, o_rst0_tb=self.rst0_tb)
        for name, (direction, _, path) in _USER_PORTS.items():
            member = self.user
            for part in path:
                member = getattr(member, part)
            ports[f"{'i' if direction == 'input' else 'o'}_{name}"] = member
        parameters = {f"p_{name}": value for name, value in MIG_PARAMETERS.items()}
        return Instance(self.core_name, p_SIM_ONLY=int(self.sim_only), **parameters, **ports)


class GenesysDDR2(wiring.Component):
    """The DDR2 on the Genesys: MIG's clocks (:class:`board.clocking.MIGClocking`, submodule ``mig_clocking``), the
    core (:class:`MIGCore`, submodule ``mig``), and the ``mem`` domain they drive. Add it to the top level as
    submodule ``ddr2`` (the core's instance path ``ddr2/mig``, :data:`board.mig_ucf.INSTANCE_PATH`).

    On a platform with the project's ISE flow (:class:`board.ise.ISEFlow`) it registers the PLL's output nets for
    the core's UCF clock constraints and a TIG group ``mem`` on ``clk0`` (the ``mem`` domain is asynchronous to
    every other clock of the board: its crossings go through the design's dual-clock FIFOs).

    Parameters
    ----------
    core_name : str
        For :class:`MIGCore`.
    plan : :class:`board.clocking.MIGClockPlan`

    Raises
    ------
    ValueError
        A plan outside the PLL's ranges; a core name that is not a Verilog identifier.

    Attributes
    ----------
    clk100 : ``In(1)``
        The oscillator's global clock (the ``sync`` BUFG).
    button : ``In(1)``
        The reset button, active high: resets the PLL and holds the core's ``sys_rst_n`` low.
    user : ``In(MIGUserSignature())``
        The core's user interface, the controller's side; connect the design's ``Out(MIGUserSignature())`` to it.
    domains : list of ClockDomain
        ``mem`` (clock ``clk0_tb``, reset ``rst0_tb``), which this block drives and the parent adds to its module.

    Clock domains: ``mem`` (125 MHz). Latency: ``mem`` leaves reset 25 ``mem`` clocks after the PLL locks and the
    core's IDELAYCTRL is ready; ``user.phy_init_done`` rises after the memory's initialisation and calibration.
    """

    def __init__(self, core_name=DEFAULT_CORE_NAME, *, plan=MIG_PLAN):
        self.core_name = _checked_core_name(core_name)
        self.plan = plan.check()
        super().__init__({"clk100": In(1), "button": In(1), "user": In(MIGUserSignature())})
        self.domains = [ClockDomain("mem")]

    def elaborate(self, platform):
        m = Module()
        clocking, core = MIGClocking(self.plan), MIGCore(self.core_name)
        m.submodules.mig_clocking = clocking
        m.submodules.mig = core
        m.d.comb += [clocking.clk100.eq(self.clk100), clocking.button.eq(self.button)]
        m.d.comb += [getattr(core, name).eq(getattr(clocking, name))
                     for name in ("clk0", "clk90", "clkdiv0", "clk200", "locked")]
        m.d.comb += core.sys_rst_n.eq(~self.button)
        wiring.connect(m, wiring.flipped(self.user), core.user)
        m.d.comb += [ClockSignal("mem").eq(core.clk0_tb), ResetSignal("mem").eq(core.rst0_tb)]
        # the UCF (board/ise.py): the core's clock constraints on the PLL outputs; the mem domain's TIG group
        if hasattr(platform, "add_mig_clock_nets"):
            platform.add_mig_clock_nets(clocking.pll_outputs)
        if hasattr(platform, "add_tig_group"):
            platform.add_tig_group("mem", clocking.pll_outputs["clk0"], "mem")
        return m
