"""The Digilent Genesys board (Virtex-5 XC5VLX50T-1FF1136) as an Amaranth ``XilinxPlatform`` for Xilinx ISE.

Only the resources this design uses are declared: the 100 MHz oscillator, the reset button, SW0..SW7, LD0..LD7,
the CH7301C DVI transmitter (12-bit dual-edge data, XCLK pair, H/V sync, DE, reset, its I2C bus) and the two
VmodCAM cameras on the VHDC connector.

Every pin location carries its source in :data:`PIN_SOURCES`. The sources are public, stored copies read with
the project's search tool (docs/board.md has the table):

* ``strfry/nesfpga`` ``nes_top.ucf`` -- a working Genesys design whose UCF header says it is derived from
  "a general .ucf for Genesys rev C board" (Digilent's master UCF): the oscillator (``AG18``, GCLK0), LD0..LD7,
  the whole HDMI/CH7301C group with bank, pin name and schematic net name, the I2C bus, the reset input.
* ``strfry/nesfpga`` ``build.py`` -- the same project's pin list: SW0..SW7.
* ``d-hawkins/digilent_genesys`` ``doc/genesys_tutorial/sections/examples.tex`` -- GCLK0 = AG18 (bank 4, 3.3 V,
  LVCMOS33) and LD0..LD7 (bank 22, 3.3 V, LVCMOS33, 4 mA, SLOW): an independent second source that agrees.

**Unconfirmed:** the VmodCAM signals on the VHDC connector. No stored copy of the Genesys VHDC pin-out (Digilent
reference manual / schematic) or of Digilent's VmodCAM reference design for the Genesys could be read, so these
pins have *placeholder* locations named ``UNCONFIRMED_...`` (see :data:`UNCONFIRMED`). ISE's ``ngdbuild`` rejects
such a LOC, so a bitstream can never be built with guessed camera pins: give the real locations with
``stereodepth verilog --pins FILE`` (or edit :data:`VMODCAM_PINS`) after reading them off the Genesys schematic.
The IO standard of the VHDC pins (LVCMOS33) and the reset button's identity are unconfirmed too.
"""

import re

from amaranth.build import Attrs, Clock, Pins, PinsN, Resource, Subsignal
from amaranth.vendor import XilinxPlatform

from spec.board import CLOCKS
from spec.video import CEA_1080P60

__all__ = [
    "GenesysPlatform", "PIN_SOURCES", "UNCONFIRMED", "VMODCAM_PINS", "CAM_PCLK_MAX_HZ", "CAM_OFFSET_IN_NS",
    "CAM_VALID_NS", "XST_OPTIONS", "MAP_OPTIONS", "PAR_OPTIONS", "TRCE_OPTIONS", "parse_pin_file", "ucf_net_line",
]

# --- Sources ------------------------------------------------------------------------------------------------

_NESFPGA_UCF = "strfry/nesfpga nes_top.ucf (derived from Digilent's 'general .ucf for Genesys rev C board')"
_NESFPGA_BUILD = "strfry/nesfpga build.py (Genesys pin list)"
_HAWKINS = "d-hawkins/digilent_genesys doc/genesys_tutorial/sections/examples.tex (table 'blinky pins')"

#: resource name -> where its locations come from.
PIN_SOURCES = {
    "clk100": f"{_NESFPGA_UCF}: AG18, bank 4, IO_L6P_GC_4, GCLK0; {_HAWKINS}: GCLK0 AG18, bank 4, 3.3 V, LVCMOS33",
    "rst": f"{_NESFPGA_UCF}: 'rstn' E7, LVCMOS25, PULLUP, active low (the board label of this button is not "
           "given there: unconfirmed which push button it is)",
    "switches": f"{_NESFPGA_BUILD}: sw<0..7> = J19 L18 K18 H18 H17 K17 G16 G15 (no IO standard given: ISE "
                "default, as in that design)",
    "leds": f"{_NESFPGA_UCF}: Led<0..7> AG8 AH8 AH9 AG10 AH10 AG11 AF11 AE11 (Sch LD0..LD7, bank 22); "
            f"{_HAWKINS}: same pins, LVCMOS33, 4 mA, SLOW",
    "ch7301c": f"{_NESFPGA_UCF}: HDMI-D0..D11, HDMI-CLK_P/N (K11/J11, LVCMOS33, DRIVE 24, FAST), HDMI-H, HDMI-V, "
               "HDMI-DE, HDMI-RST (AF23), banks 20/18/2, all LVCMOS33",
    "ch7301c_i2c": f"{_NESFPGA_UCF}: I2C-SCL U8, I2C-SDA V8, LVCMOS33, PULLUP (bank 18)",
    "vmodcam": "UNCONFIRMED: no stored copy of the Genesys VHDC pin-out or of a Genesys VmodCAM reference UCF",
    "vmodcam_vdden": "UNCONFIRMED: as vmodcam",
}

#: The 100 MHz oscillator, used as the ``sync`` clock and the reference of the DCM/PLLs.
OSC_HZ = CLOCKS.SYS_HZ

#: PERIOD constraint put on each camera's PCLK input: what the MT9D112 init table programs.
CAM_PCLK_MAX_HZ = CLOCKS.CAM_PCLK_HZ

_CAM_SIGNALS = ("d", "pclk", "lv", "fv", "mclk", "scl", "sda", "rst_n", "pwdn")


def _placeholder(cam, signal, width=1):
    if width == 1:
        return f"UNCONFIRMED_CAM{cam}_{signal.upper()}"
    return " ".join(f"UNCONFIRMED_CAM{cam}_{signal.upper()}{i}" for i in range(width))


#: VmodCAM pin locations, by ``(camera, signal)``; camera "A" (left) is resource number 0, "B" (right) 1.
#: All placeholders (unconfirmed): replace them with the Genesys VHDC locations before building a bitstream.
VMODCAM_PINS = {
    (cam, sig): _placeholder(cam, sig, 8 if sig == "d" else 1)
    for cam in ("A", "B") for sig in _CAM_SIGNALS
}
VMODCAM_PINS[("X", "vdden")] = "UNCONFIRMED_CAMX_VDDEN"

#: Pins whose location is not confirmed from a source: every placeholder name starts with this prefix.
UNCONFIRMED_PREFIX = "UNCONFIRMED_"


def _unconfirmed_names():
    names = []
    for pins in VMODCAM_PINS.values():
        names.extend(pins.split())
    return tuple(names)


#: Placeholder pin names (the unconfirmed locations).
UNCONFIRMED = _unconfirmed_names()

_LVCMOS33 = Attrs(IOSTANDARD="LVCMOS33")
#: CH7301C data, H, V, DE: fast edges (the data pins change at 297 Mb/s, twice per pixel clock; the PoC ML505 DVI
#: UCF, the same CH7301C wiring, sets SLEW = FAST on every DVI pin) and a stated drive of 12 mA (LVCMOS33's
#: default made explicit: no Genesys source gives one for these pins; the XCLK pair keeps the source's 24 mA).
#: Check the edges on the first power-up (docs/board.md).
_DVI_DATA = Attrs(DRIVE="12", SLEW="FAST")

#: OFFSET IN of each camera's D, LV, FV against its PCLK rising edge: data valid from 1.25 ns before the edge,
#: for 7.5 ns. Source: Digilent's VmodCAM reference design for the Atlys (the same camera board, 80 MHz PCLK):
#: ``OFFSET = IN 1.25 ns VALID 7.5 ns BEFORE "CAMA_PCLK_I" RISING`` (system.ucf, stored copy in
#: tariqmuh/XPS_VmodCam IP1_VideoIn/implementation/system.ucf). The MT9D112 data sheet's output timing figures
#: could not be read here; Digilent's numbers are the constraint its own design meets with this sensor.
CAM_OFFSET_IN_NS = 1.25
CAM_VALID_NS = 7.5

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


def _vmodcam_resource(number, cam, pins):
    def p(sig):
        return pins[(cam, sig)]
    return Resource(
        "vmodcam", number,
        Subsignal("d", Pins(p("d"), dir="i", assert_width=8)),
        Subsignal("pclk", Pins(p("pclk"), dir="i"), Clock(CAM_PCLK_MAX_HZ)),
        Subsignal("lv", Pins(p("lv"), dir="i")),
        Subsignal("fv", Pins(p("fv"), dir="i")),
        Subsignal("mclk", Pins(p("mclk"), dir="o")),
        Subsignal("scl", Pins(p("scl"), dir="io")),
        Subsignal("sda", Pins(p("sda"), dir="io")),
        Subsignal("rst_n", Pins(p("rst_n"), dir="o")),   # sensor RESET_BAR, active low
        Subsignal("pwdn", Pins(p("pwdn"), dir="o")),     # sensor STANDBY / power-down, active high
        Attrs(IOSTANDARD="LVCMOS33"),                     # unconfirmed: VHDC bank voltage not read from a source
    )


class GenesysPlatform(XilinxPlatform):
    """Digilent Genesys: XC5VLX50T, FF1136 package, speed grade -1, built with Xilinx ISE (14.7).

    ``pins`` overrides pin locations by placeholder name (``{"UNCONFIRMED_CAMA_D0": "AB12", ...}``), for when the
    VmodCAM locations have been read off the Genesys schematic. ``allow_unconfirmed=True`` leaves the LOC of any
    pin still unconfirmed out of the UCF (ISE then places those ports itself): for trial synthesis and place and
    route only -- never program a board with such a bitstream. ``files`` limits the build plan to the files whose
    names end with one of the given suffixes (e.g. ``(".ucf",)``, ``(".il",)``); by default the plan has the
    ISE files Amaranth prepares (``top.v``, ``top.prj``, ``top.xst``, ``top.ucf``, ``build_top.sh``/``.bat``)
    plus ``top_ise_project.tcl`` (an ``xtclsh`` script creating an ISE project for the GUI) and, when asked
    for, ``top.il`` (RTLIL of the whole design, for the Yosys resource estimate).
    """

    device = "xc5vlx50t"
    xst_options = XST_OPTIONS
    timing_met = TIMING_MET
    map_options = MAP_OPTIONS
    par_options = PAR_OPTIONS
    trce_options = TRCE_OPTIONS
    package = "ff1136"
    speed = "1"
    default_clk = "clk100"
    default_rst = "rst"

    def __init__(self, *, pins=None, allow_unconfirmed=False, files=None, toolchain="ISE"):
        self._pin_overrides = dict(pins or {})
        self._files = None if files is None else tuple(files)
        unknown = sorted(set(self._pin_overrides) - set(UNCONFIRMED))
        if unknown:
            raise ValueError(f"pin override for unknown placeholder(s): {', '.join(unknown)}")
        self.allow_unconfirmed = allow_unconfirmed
        self.resources = self._make_resources()   # read by Platform.__init__
        self._tig_groups = {}
        super().__init__(toolchain=toolchain)

    resources = []
    connectors = []

    def _make_resources(self):
        pins = {}
        for key, names in VMODCAM_PINS.items():
            pins[key] = " ".join(self._pin_overrides.get(n, n) for n in names.split())
        return [
            Resource("clk100", 0, Pins("AG18", dir="i"), Clock(OSC_HZ), Attrs(IOSTANDARD="LVCMOS33")),
            Resource("rst", 0, PinsN("E7", dir="i"), Attrs(IOSTANDARD="LVCMOS25", PULLUP="TRUE")),
            Resource("switches", 0, Pins("J19 L18 K18 H18 H17 K17 G16 G15", dir="i", assert_width=8)),
            Resource("leds", 0, Pins("AG8 AH8 AH9 AG10 AH10 AG11 AF11 AE11", dir="o", assert_width=8),
                     Attrs(IOSTANDARD="LVCMOS33", DRIVE="4", SLEW="SLOW")),
            Resource(
                "ch7301c", 0,
                Subsignal("d", Pins("G10 G8 B12 D12 C12 D11 F10 D10 E9 F9 E8 F8", dir="o", assert_width=12),
                          _DVI_DATA),
                Subsignal("xclk_p", Pins("K11", dir="o"), Attrs(DRIVE="24", SLEW="FAST")),
                Subsignal("xclk_n", Pins("J11", dir="o"), Attrs(DRIVE="24", SLEW="FAST")),
                Subsignal("h", Pins("H8", dir="o"), _DVI_DATA),
                Subsignal("v", Pins("F13", dir="o"), _DVI_DATA),
                Subsignal("de", Pins("V10", dir="o"), _DVI_DATA),
                Subsignal("reset_n", Pins("AF23", dir="o"), Attrs(PULLUP="TRUE")),
                _LVCMOS33,
            ),
            Resource(
                "ch7301c_i2c", 0,
                Subsignal("scl", Pins("U8", dir="io")),
                Subsignal("sda", Pins("V8", dir="io")),
                Attrs(IOSTANDARD="LVCMOS33", PULLUP="TRUE"),
            ),
            _vmodcam_resource(0, "A", pins),
            _vmodcam_resource(1, "B", pins),
            Resource("vmodcam_vdden", 0, Pins(pins[("X", "vdden")], dir="o"), Attrs(IOSTANDARD="LVCMOS33")),
        ]

    # --- UCF -------------------------------------------------------------------------------------------------
    # The UCF is rendered by ucf_net_line (one line per port bit, UCF syntax of the ISE Constraints Guide UG625:
    # value attributes as `KEY = VALUE`, PULLUP as a flag) instead of Amaranth's default ISE template, so the
    # checked-in constraints/genesys.ucf and the build's UCF are the same text from the same function.

    @property
    def file_templates(self):
        templates = dict(super().file_templates)
        if self.toolchain == "ISE":
            templates["{{name}}.ucf"] = _UCF_TEMPLATE
            templates["{{name}}.v"] = _VERILOG_TEMPLATE
            templates["{{name}}.xst"] = _XST_TEMPLATE
            templates["{{name}}_ise_project.tcl"] = _ISE_PROJECT_TEMPLATE
            templates["{{name}}.il"] = "{{emit_rtlil()}}"
            templates["build_{{name}}.sh"] = _BUILD_SH_TEMPLATE
            templates["build_{{name}}.bat"] = _BUILD_BAT_TEMPLATE
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

    @property
    def unconfirmed_in_use(self):
        """Placeholder pins still present in the resources (after ``pins`` overrides)."""
        return tuple(n for n in UNCONFIRMED if n not in self._pin_overrides)


_UCF_TEMPLATE = r"""
    # {{autogenerated}}
    # Digilent Genesys (xc5vlx50t-ff1136-1). Pin sources: board/genesys.py PIN_SOURCES, docs/board.md.
    # Locations named UNCONFIRMED_* are placeholders: ngdbuild rejects them until the real VHDC pins are given.
    {{platform.ucf_port_lines()}}
    # Clocks: a PERIOD on each clock pad only. ngdbuild derives the DCM/PLL outputs' PERIODs from the
    # oscillator's (a PERIOD group used in nothing else is traced through a DCM/PLL: Xilinx AR 6905).
    {% for port, frequency in platform.iter_port_clock_constraints() -%}
    NET "{{port|hierarchy("/")}}" TNM_NET = "PRD{{port|hierarchy("/")}}";
    TIMESPEC "TS{{port|hierarchy("__")}}" = PERIOD "PRD{{port|hierarchy("/")}}" {{"%.4f"|format(1000000000/frequency)}} ns HIGH 50%;
    {% endfor %}
    # Asynchronous clocks: second groups on the PLL output nets and the PCLK pads, a TIG between groups of
    # different sources (all crossings go through synchronisers or dual-clock block RAM).
    {% for group, net in platform.ucf_tig_groups() -%}
    NET "{{net if net is string else net|hierarchy("/")}}" TNM_NET = "{{group}}";
    {% endfor %}
    {% for a, b in platform.ucf_tig_pairs() -%}
    TIMESPEC "TS_{{a}}_TO_{{b}}" = FROM "{{a}}" TO "{{b}}" TIG;
    {% endfor %}
    # Camera inputs: D, LV, FV valid 1.25 ns before PCLK rises, for 7.5 ns (Digilent's VmodCAM design; the input
    # registers are IOB flip-flops, board/top.py).
    {{platform.ucf_camera_offset_lines()}}
    # CH7301C outputs: data, H, V, DE leave IOB registers / ODDRs on both pixel clock edges; XCLK_P is the
    # reference pin, so trce reports each pin's skew to the forwarded clock (docs/board.md).
    {{platform.ucf_dvi_offset_lines()}}
    {{get_override("add_constraints")|default("# (no additional constraints)")}}
"""

_VERILOG_TEMPLATE = r"""
    /* {{autogenerated}} */
    {{platform.board_verilog_text(emit_rtlil())}}
"""

_XST_TEMPLATE = r"""
    # {{autogenerated}}
    run
    -ifn {{name}}.prj
    -ofn {{name}}.ngc
    -top {{name}}
    {% for option in platform.xst_options -%}
    {{option}}
    {% endfor -%}
    -p {{platform.device}}{{platform.package}}-{{platform.speed}}
    {{get_override("script_after_run")|default("# (script_after_run placeholder)")}}
"""


# The command-line flow (replacing Amaranth's: trce after par, and bitgen only when timing is met). Every step
# overwrites its outputs (xst, ngdbuild and trce rewrite theirs; map and par with -w), so a second run in the same
# folder works.
_BUILD_SH_TEMPLATE = r"""
    #!/bin/sh
    # {{autogenerated}}
    # ISE 14.7 command-line flow: xst, ngdbuild, map, par, trce; bitgen only if trce reports every constraint met.
    set -e
    if [ -z "$BASH" ] ; then exec /bin/bash "$0" "$@"; fi
    [ -n "$AMARANTH_ENV_ISE" ] && . "$AMARANTH_ENV_ISE"
    : ${XST:=xst}
    : ${NGDBUILD:=ngdbuild}
    : ${MAP:=map}
    : ${PAR:=par}
    : ${TRCE:=trce}
    : ${BITGEN:=bitgen}
    "$XST" -ifn {{name}}.xst
    "$NGDBUILD" -quiet -uc {{name}}.ucf -p {{platform.device}}{{platform.package}}-{{platform.speed}} {{name}}.ngc {{name}}.ngd
    "$MAP" {{platform.map_options|join(" ")}} -o {{name}}_map.ncd {{name}}.ngd {{name}}.pcf
    "$PAR" {{platform.par_options|join(" ")}} {{name}}_map.ncd {{name}}_par.ncd {{name}}.pcf
    "$TRCE" {{platform.trce_options|join(" ")}} -o {{name}}.twr {{name}}_par.ncd {{name}}.pcf
    if ! grep -q "{{platform.timing_met}}" {{name}}.twr ; then
      echo "timing not met: see {{name}}.twr; no bitstream written" >&2
      exit 1
    fi
    "$BITGEN" -g Compress -w -g Binary:Yes {{name}}_par.ncd {{name}}.bit
"""

_BUILD_BAT_TEMPLATE = r"""
    @rem {{autogenerated}}
    @rem ISE 14.7 command-line flow: xst, ngdbuild, map, par, trce; bitgen only if trce reports every constraint met.
    @echo off
    SetLocal EnableDelayedExpansion
    if defined AMARANTH_ENV_ISE call "%AMARANTH_ENV_ISE%"
    if [!XST!] equ [] set XST=xst
    if [!NGDBUILD!] equ [] set NGDBUILD=ngdbuild
    if [!MAP!] equ [] set MAP=map
    if [!PAR!] equ [] set PAR=par
    if [!TRCE!] equ [] set TRCE=trce
    if [!BITGEN!] equ [] set BITGEN=bitgen
    "%XST%" -ifn {{name}}.xst || exit /b
    "%NGDBUILD%" -quiet -uc {{name}}.ucf -p {{platform.device}}{{platform.package}}-{{platform.speed}} {{name}}.ngc {{name}}.ngd || exit /b
    "%MAP%" {{platform.map_options|join(" ")}} -o {{name}}_map.ncd {{name}}.ngd {{name}}.pcf || exit /b
    "%PAR%" {{platform.par_options|join(" ")}} {{name}}_map.ncd {{name}}_par.ncd {{name}}.pcf || exit /b
    "%TRCE%" {{platform.trce_options|join(" ")}} -o {{name}}.twr {{name}}_par.ncd {{name}}.pcf || exit /b
    findstr /C:"{{platform.timing_met}}" {{name}}.twr >nul || (echo timing not met: see {{name}}.twr; no bitstream written & exit /b 1)
    "%BITGEN%" -g Compress -w -g Binary:Yes {{name}}_par.ncd {{name}}.bit || exit /b
"""

_ISE_PROJECT_TEMPLATE = r"""
    # {{autogenerated}}
    # Creates an ISE 14.7 project for the generated design: `xtclsh {{name}}_ise_project.tcl`, then open
    # {{name}}.xise in Project Navigator (or run build_{{name}}.sh for the command-line flow instead).
    # Commands as in the project scripts ISE itself writes (project new / project set / xfile add).
    # A second run starts from a new project: `project new` fails when the project file exists.
    if {[file exists {{name}}.xise]} { file delete -force {{name}}.xise {{name}}.gise }
    project new {{name}}.xise
    project set family "Virtex5"
    project set device "{{platform.device}}"
    project set package "{{platform.package}}"
    project set speed "-{{platform.speed}}"
    project set top_level_module_type "HDL"
    project set synthesis_tool "XST (VHDL/Verilog)"
    project set "Preferred Language" "Verilog"
    project set "Other XST Command Line Options" "{{platform.xst_options|join(" ")}}" -process "Synthesize - XST"
    xfile add "{{name}}.v"
    xfile add "{{name}}.ucf"
    project set top "{{name}}"
    project close
"""


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


_PIN_LINE = re.compile(r"^\s*(UNCONFIRMED_[A-Z0-9_]+)\s*[=:\s]\s*([A-Z]{1,2}[0-9]{1,2})\s*(#.*)?$")


def parse_pin_file(text):
    """Pin overrides from a text file: one ``PLACEHOLDER LOC`` (or ``PLACEHOLDER = LOC``) per line, ``#``
    comments. Returns ``{placeholder: loc}``; raises ``ValueError`` naming the first bad line."""
    pins = {}
    for number, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        match = _PIN_LINE.match(line.upper())
        if not match:
            raise ValueError(f"line {number}: expected 'UNCONFIRMED_<name> <FF1136 pin>', got {raw.strip()!r}")
        name, loc = match.group(1), match.group(2)
        if name not in UNCONFIRMED:
            raise ValueError(f"line {number}: {name} is not a placeholder pin of this platform")
        pins[name] = loc
    return pins
