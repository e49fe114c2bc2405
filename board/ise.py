"""The Genesys ISE build: what Amaranth's ``XilinxPlatform`` prepares for ISE, as this project writes it.

:class:`ISEFlow` is a mixin of :class:`board.genesys.GenesysPlatform` (``class GenesysPlatform(ISEFlow,
XilinxPlatform)``): it replaces Amaranth's ISE templates with the project's (:mod:`board.ise_templates`), renders
the UCF line by line (:func:`ucf_net_line`), adds the timing constraints of the board's interfaces (the cameras'
OFFSET IN, the CH7301C's OFFSET OUT, the TIGs between unrelated clocks) and selects which files a build plan holds.
The board's pins and resources are in :mod:`board.genesys`; this module knows only the port names the resources
give (``vmodcam_<n>__...``, ``ch7301c_0__...``, ``clk100_0__io``).
"""

from board import ise_templates
from board.vmodcam import CAM_OFFSET_IN_NS, CAM_VALID_NS
from spec.video import CEA_1080P60

#: Where the build folder holds the MIG core's RTL (copied from the user's core folder).
MIG_BUILD_FOLDER = "mig"
MIG_PAR = "user_design/par"

__all__ = ["ISEFlow", "MIG_BUILD_FOLDER", "UNCONFIRMED_PREFIX", "XST_OPTIONS", "TIMING_MET", "MAP_OPTIONS", "PAR_OPTIONS",
           "TRCE_OPTIONS", "DVI_OUT_GROUP", "DVI_OFFSET_OUT_NS", "ucf_net_line"]

#: A pin location starting with this prefix is a placeholder (not confirmed from a source): written as is into the
#: UCF, where ``ngdbuild`` rejects it, or left out with ``allow_unconfirmed``.
UNCONFIRMED_PREFIX = "UNCONFIRMED_"

#: UCF group of the CH7301C data, H, V and DE pads, and their OFFSET OUT bound against the oscillator pad: one
#: pixel clock period (a stated bound, not a CH7301C figure: its setup/hold table could not be read here; what
#: matters is the skew to XCLK, which trce reports through REFERENCE_PIN).
DVI_OUT_GROUP = "DVI_OUT"
DVI_OFFSET_OUT_NS = 1e9 / CEA_1080P60.pixel_hz

#: XST options of the command-line script (Amaranth's ``top.xst`` template) that the Project Navigator TCL
#: must carry too (``Other XST Command Line Options``): the same synthesis whichever flow is used.
#: ``-hierarchy_separator /`` and ``-bus_delimiter <>``: the UCF names hierarchical nets with ``/`` and bus bits
#: as ``port<3>`` (both XST's defaults, stated so the UCF does not depend on them). No ``-use_new_parser``: no
#: source confirms XST 14.7 takes it for Virtex-5 (the new parser was introduced for Virtex-6/Spartan-6, Xilinx
#: AR 33038), and top.v is written for both parsers (docs/board.md).
XST_OPTIONS = ("-hierarchy_separator /", "-bus_delimiter <>", "-keep_hierarchy no")

#: What trce writes into its report when every constraint is met (the build stops before bitgen otherwise).
TIMING_MET = "All constraints were met."

#: Options of the implementation steps (docs/board.md): ``map`` timing-driven with high placer effort,
#: ``par`` high effort, ``trce`` a verbose report of the 10 worst paths per constraint plus 10 unconstrained ones.
MAP_OPTIONS = ("-w", "-ol high", "-timing")
PAR_OPTIONS = ("-w", "-ol high")
TRCE_OPTIONS = ("-v 10", "-u 10")


class ISEFlow:
    """The ISE flow of a ``XilinxPlatform`` (a mixin: put it before ``XilinxPlatform`` in the bases).

    Parameters
    ----------
    allow_unconfirmed : bool
        Leave the LOC of every pin still a placeholder (``UNCONFIRMED_...``) out of the UCF (ISE then places those
        ports itself): for trial synthesis and place and route only -- never program a board with such a
        bitstream.
    files : tuple of str or None
        Limit the build plan to the files whose names end with one of these suffixes (e.g. ``(".ucf",)``,
        ``(".il",)``); by default the plan has the ISE files Amaranth prepares (``top.v``, ``top.prj``,
        ``top.xst``, ``top.ucf``, ``build_top.sh``/``.bat``) plus ``top_ise_project.tcl`` (an ``xtclsh`` script
        creating an ISE project for the GUI); ``top.il`` (RTLIL of the whole design, for the Yosys resource
        estimate) only when asked for.
    toolchain : str
        ``"ISE"``.
    mig : :class:`board.mig_core.MIGCoreFiles` or None
        The user's MIG core (``stereodepth verilog --mig DIR``): its RTL goes into the build folder's ``mig/``,
        listed in ``top.prj`` and the project TCL; its UCF is merged into ``top.ucf``
        (:func:`board.mig_ucf.merge_mig_ucf`).

    Raises
    ------
    board.mig_ucf.MIGUCFError
        The core's UCF contradicts the board's DDR2 pins.
    """

    xst_options = XST_OPTIONS
    timing_met = TIMING_MET
    map_options = MAP_OPTIONS
    par_options = PAR_OPTIONS
    trce_options = TRCE_OPTIONS

    def __init__(self, *, allow_unconfirmed=False, files=None, toolchain="ISE", mig=None):
        self.allow_unconfirmed = allow_unconfirmed
        self._files = None if files is None else tuple(files)
        self._tig_groups = {}
        self._mig_clock_nets = {}
        super().__init__(toolchain=toolchain)
        self.mig = mig
        self._mig_lines = []
        if mig is not None:
            from board.mig_ucf import merge_mig_ucf
            self._mig_lines = merge_mig_ucf(mig.ucf_text, source=str(mig.folder / MIG_PAR / mig.ucf_name))
            for file_name, text in mig.rtl:
                self.add_file(f"{MIG_BUILD_FOLDER}/{file_name}", text)

    # --- UCF -------------------------------------------------------------------------------------------------
    # The UCF is rendered by ucf_net_line (one line per port bit, UCF syntax of the ISE Constraints Guide UG625:
    # value attributes as `KEY = VALUE`, PULLUP as a flag) instead of Amaranth's default ISE template, so the
    # checked-in constraints/genesys.ucf and the build's UCF are the same text from the same function.

    @property
    def file_templates(self):
        templates = dict(super().file_templates)
        if self.toolchain == "ISE":
            templates["{{name}}.ucf"] = ise_templates.UCF
            templates["{{name}}.v"] = ise_templates.VERILOG
            templates["{{name}}.xst"] = ise_templates.XST
            templates["{{name}}_ise_project.tcl"] = ise_templates.ISE_PROJECT
            templates["{{name}}.il"] = "{{emit_rtlil()}}"
            templates["build_{{name}}.sh"] = ise_templates.BUILD_SH
            templates["build_{{name}}.bat"] = ise_templates.BUILD_BAT
        if self._files is not None:
            return {k: v for k, v in templates.items() if k.endswith(self._files)}
        default = (".v", ".prj", ".xst", ".ucf", ".sh", ".bat", ".tcl")
        return {k: v for k, v in templates.items() if k.endswith(default) and not k.endswith(".debug.v")}

    def ucf_port_lines(self):
        """UCF lines for every port bit of the prepared design (call inside a build, i.e. from a template)."""
        return "\n".join(ucf_net_line(port, pin, attrs, allow_unconfirmed=self.allow_unconfirmed)
                         for port, pin, attrs in self.iter_port_constraints_bits())

    def ucf_camera_offset_lines(self):
        """OFFSET IN constraints of each camera's D, LV, FV against its PCLK pin (call inside a build)."""
        lines = []
        ports = [port for port, _, _ in self.iter_port_constraints_bits()]
        for number in (0, 1):
            prefix = f"vmodcam_{number}__"
            group = f"CAM{number}_IN"
            for port in ports:
                if port.startswith((prefix + "d__io", prefix + "lv__io", prefix + "fv__io")):
                    lines.append(f'NET "{_ucf_port_name(port)}" TNM = "{group}";')
            lines.append(f'TIMEGRP "{group}" OFFSET = IN {CAM_OFFSET_IN_NS} ns VALID {CAM_VALID_NS} ns BEFORE '
                         f'"{prefix}pclk__io" RISING;')
        return "\n".join(lines)

    @staticmethod
    def board_verilog_text(rtlil_text):
        """The board's ``top.v`` (the XST input) from the design's RTLIL: :func:`board.export.xst_verilog`."""
        from board.export import xst_verilog
        return xst_verilog(rtlil_text)

    def toolchain_prepare(self, fragment, name, **kwargs):
        # No source locations in the netlist: they would be absolute paths of the machine that built it.
        kwargs.setdefault("emit_src", False)
        return super().toolchain_prepare(fragment, name, **kwargs)

    def add_tig_group(self, name, net, family):
        """A timing group ``TIG_<name>`` for the UCF's TIGs: a ``TNM_NET`` on ``net`` (a signal: a DCM/PLL output
        net, or a port name: a clock pad). Groups of different families are asynchronous to each other and get a
        ``TIG`` in both directions. These are second groups, apart from the PERIOD groups on the pads: a PERIOD
        group used in a FROM-TO is not traced through a DCM/PLL (Xilinx AR 6905, migen#43)."""
        self._tig_groups[name] = (net, family)

    def ucf_tig_groups(self):
        """``(group, net)`` per TIG group (call inside a build): ``net`` a signal or a port name."""
        return [(f"TIG_{name}", net) for name, (net, _) in self._tig_groups.items()]

    def ucf_tig_pairs(self):
        """Ordered pairs of TIG group names in different families (call inside a build)."""
        groups = self._tig_groups
        return [(f"TIG_{a}", f"TIG_{b}") for a in groups for b in groups if groups[a][1] != groups[b][1]]

    def add_mig_clock_nets(self, nets):
        """The nets that carry the MIG core's clocks (``{port: signal}``, the PLL output nets of
        :class:`board.clocking.MIGClocking`): the core UCF's clock constraints go onto them."""
        self._mig_clock_nets.update(nets)

    def ucf_mig_lines(self):
        """The MIG core's UCF merged (:func:`board.mig_ucf.merge_mig_ucf`): ``(line, net)`` pairs, ``net`` the
        signal whose hierarchical name replaces ``@NET@`` in the line, or ``None`` (call inside a build)."""
        lines = []
        for line, clock in self._mig_lines:
            if clock is not None and clock not in self._mig_clock_nets:
                raise ValueError(f"the MIG core's UCF constrains clock {clock}, which the design does not drive")
            lines.append((line, None if clock is None else self._mig_clock_nets[clock]))
        return lines

    def ucf_dvi_offset_lines(self):
        """OFFSET OUT of the CH7301C data and syncs (both pixel clock edges) against the oscillator pad, with
        the forwarded XCLK_P as the reference pin (trce reports each pin's skew to it; call inside a build)."""
        ports = [port for port, _, _ in self.iter_port_constraints_bits()]
        lines = [f'NET "{_ucf_port_name(port)}" TNM = "{DVI_OUT_GROUP}";' for port in ports
                 if port.startswith(("ch7301c_0__d__io", "ch7301c_0__h__io", "ch7301c_0__v__io",
                                     "ch7301c_0__de__io"))]
        for edge in ("RISING", "FALLING"):
            lines.append(f'TIMEGRP "{DVI_OUT_GROUP}" OFFSET = OUT {DVI_OFFSET_OUT_NS:.3f} ns AFTER "clk100_0__io" '
                         f'REFERENCE_PIN "ch7301c_0__xclk_p__io" {edge};')
        return "\n".join(lines)


def _ucf_port_name(port):
    return port.replace("[", "<").replace("]", ">")


def ucf_net_line(port, pin, attrs, *, allow_unconfirmed=False):
    """One UCF line: ``NET "port<3>" LOC = "AG18" | IOSTANDARD = LVCMOS33 | PULLUP;``.

    A placeholder (unconfirmed) location is written as is, which ``ngdbuild`` rejects, unless
    ``allow_unconfirmed`` is set: then the LOC is left out and the line says why.
    """
    parts = []
    unconfirmed = pin.startswith(UNCONFIRMED_PREFIX)
    if not (unconfirmed and allow_unconfirmed):
        parts.append(f'LOC = "{pin}"')
    for key, value in attrs.items():
        if value is None:
            continue
        if key == "PULLUP" and str(value).upper() == "TRUE":
            parts.append("PULLUP")
        else:
            parts.append(f"{key} = {value}")
    line = f'NET "{_ucf_port_name(port)}" ' + " | ".join(parts) + ";"
    if unconfirmed:
        line += f"  # {pin}: location not confirmed from a source (docs/board.md)"
    return line
