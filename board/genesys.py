"""The Digilent Genesys board (Virtex-5 XC5VLX50T-1FF1136) as an Amaranth ``XilinxPlatform``: its resources and
its VHDC connector, in the manner of amaranth-boards' board files (``amaranth_boards/atlys.py``).

Declared: the resources this design uses -- the 100 MHz oscillator, the reset button, SW0..SW7, LD0..LD7, the
CH7301C DVI transmitter (12-bit dual-edge data, XCLK pair, H/V sync, DE, reset, its I2C bus) -- and the VHDC
connector (``Connector("vhdc", 0, ...)``, :data:`VHDC`) with the VmodCAM on it as an add-on
(:func:`board.vmodcam.VmodCAMResources`: the cameras' pins are VHDC connector pins), and the DDR2 SODIMM's 113 pins
(``ddr2``, :data:`DDR2_SUBSIGNALS`, for the MIG core of board/mig.py; a resource only appears in the UCF once a
design requests it). The ISE build (templates, UCF
rendering, options) is :class:`board.ise.ISEFlow`; the ``--pins`` file is read by :mod:`board.pin_file`.

Every pin location carries its source in :data:`PIN_SOURCES`. The sources are public, stored copies read with
the project's search tool (docs/board.md has the table):

* ``strfry/nesfpga`` ``nes_top.ucf`` -- a working Genesys design whose UCF header says it is derived from
  "a general .ucf for Genesys rev C board" (Digilent's master UCF): the oscillator (``AG18``, GCLK0), LD0..LD7,
  the whole HDMI/CH7301C group with bank, pin name and schematic net name, the I2C bus, the reset input.
* ``strfry/nesfpga`` ``build.py`` -- the same project's pin list: SW0..SW7.
* ``d-hawkins/digilent_genesys`` ``doc/genesys_tutorial/sections/examples.tex`` -- GCLK0 = AG18 (bank 4, 3.3 V,
  LVCMOS33) and LD0..LD7 (bank 22, 3.3 V, LVCMOS33, 4 mA, SLOW): an independent second source that agrees.
* ``freecores/genesys_ddr2`` ``par/test_DDR2_wb.ucf`` -- the UCF MIG 3.6.1 wrote for a DDR2 design on this board
  (the one public MIG pinout for the Genesys, reported as run on the board): the DDR2 pins and IO standards.

**Unconfirmed:** the FPGA pin behind each VHDC connector pin. Which connector pin carries which camera signal is
known (board/vmodcam.py gives the sources); the Genesys's own connector map is not: no stored copy of the Genesys
VHDC pin-out could be read (the reference manual and schematic copies in ``d-hawkins/digilent_genesys`` are Git
LFS pointers without their content; the master-UCF copies found have no VHDC section). So the connector's 40
signal pins have *placeholder* locations named ``UNCONFIRMED_VHDC_<connector pin>`` (:data:`VHDC`, the one place
they are written; :data:`UNCONFIRMED` lists them). ISE's ``ngdbuild`` rejects such a LOC, so a bitstream can never
be built with guessed camera pins: give the real locations with ``stereodepth verilog --pins FILE`` (or write them
into :data:`VHDC`) after reading them off the Genesys schematic. The IO standard of the VHDC bank (LVCMOS33) and
the reset button's identity are unconfirmed too.
"""

from amaranth.build import Attrs, Clock, Connector, Pins, PinsN, Resource, Subsignal
from amaranth.vendor import XilinxPlatform

from board.ise import UNCONFIRMED_PREFIX, ISEFlow
from board.vmodcam import VHDC_IO_PINS, VHDC_PINS, VmodCAMResources
from spec.board import CLOCKS

__all__ = ["GenesysPlatform", "PIN_SOURCES", "VHDC", "UNCONFIRMED", "OSC_HZ", "DDR2_SUBSIGNALS"]

# --- Sources ------------------------------------------------------------------------------------------------

_NESFPGA_UCF = "strfry/nesfpga nes_top.ucf (derived from Digilent's 'general .ucf for Genesys rev C board')"
_NESFPGA_BUILD = "strfry/nesfpga build.py (Genesys pin list)"
_HAWKINS = "d-hawkins/digilent_genesys doc/genesys_tutorial/sections/examples.tex (table 'blinky pins')"
_GENESYS_DDR2 = ("freecores/genesys_ddr2 par/test_DDR2_wb.ucf (MIG 3.6.1's UCF of a DDR2 design reported as run on the "
                 "Genesys)")

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
    "vhdc": "UNCONFIRMED: no stored copy of the Genesys VHDC pin-out (reference manual, schematic, master UCF)",
    "vmodcam": "VHDC connector pins: board/vmodcam.py (Digilent's Atlys VmodCAM UCF through the Atlys VHDC map); "
               "their FPGA pins: as vhdc",
    "vmodcam_vdden": "as vmodcam",
    "ddr2": f"{_GENESYS_DDR2}: the 113 ddr2_* LOCs (bank 15 address/control, banks 17, 19, 21 data) and their "
            "IOSTANDARDs (SSTL18_II, SSTL18_II_DCI, DIFF_SSTL18_II_DCI, DIFF_SSTL18_II)",
}

#: The 100 MHz oscillator, used as the ``sync`` clock and the reference of the DCM/PLLs.
OSC_HZ = CLOCKS.SYS_HZ

#: The VHDC connector's map, connector pin -> FPGA pin, for the 40 signal pins (the others are ground and supply).
#: UNCONFIRMED: every FPGA pin is a placeholder named after its connector pin (module docstring).
VHDC = {str(pin): f"{UNCONFIRMED_PREFIX}VHDC_{pin}" for pin in VHDC_IO_PINS}

#: Placeholder pin names (the unconfirmed locations), in connector pin order.
UNCONFIRMED = tuple(pin for pin in VHDC.values() if pin.startswith(UNCONFIRMED_PREFIX))

#: The VHDC bank's IO standard, on every camera pin. Unconfirmed: the bank voltage was not read from a source.
_VHDC_BANK = Attrs(IOSTANDARD="LVCMOS33")
_LVCMOS33 = Attrs(IOSTANDARD="LVCMOS33")

#: CH7301C data, H, V, DE: fast edges (the data pins change at 297 Mb/s, twice per pixel clock; the PoC ML505 DVI
#: UCF, the same CH7301C wiring, sets SLEW = FAST on every DVI pin) and a stated drive of 12 mA (LVCMOS33's
#: default made explicit: no Genesys source gives one for these pins; the XCLK pair keeps the source's 24 mA).
#: Check the edges on the first power-up (docs/board.md).
_DVI_DATA = Attrs(DRIVE="12", SLEW="FAST")

#: The DDR2 SODIMM's pins as MIG's generated top module names them (``ddr2_<name>``): the ``ddr2`` resource's
#: subsignals in MIG's port order, ``name -> (direction, FPGA pins bit 0 first, IOSTANDARD)``. Source:
#: :data:`PIN_SOURCES` ``["ddr2"]``. The IO buffers of these pins are inside the MIG core (board/mig.py), so each
#: pin is a plain single-ended port of the top level, the differential pairs (DQS, CK) included, as MIG's top module
#: has them (``ddr2_dqs`` and ``ddr2_dqs_n`` are two ports).
DDR2_SUBSIGNALS = {
    "dq": ("io", "AF30 AK31 AF31 AD30 AJ30 AF29 AD29 AE29 AH27 AF28 AH28 AA28 AG25 AJ26 AG28 AB28 "
                 "AC28 AB25 AC27 AA26 AB26 AA24 AB27 AA25 AC29 AB30 W31 V30 AC30 W29 V27 W27 "
                 "V29 Y27 Y26 W24 V28 W25 W26 V24 R24 P25 N24 P26 T24 N25 P27 N28 "
                 "M28 L28 F25 H25 K27 K28 H24 G26 G25 M26 J24 L26 J27 M25 L25 L24", "SSTL18_II_DCI"),
    "a": ("o", "L30 M30 N29 P29 K31 L31 P31 P30 M31 R28 J31 R29 T31", "SSTL18_II"),
    "ba": ("o", "G31 J30", "SSTL18_II"),
    "ras_n": ("o", "H30", "SSTL18_II"),
    "cas_n": ("o", "E31", "SSTL18_II"),
    "we_n": ("o", "K29", "SSTL18_II"),
    "cs_n": ("o", "L29", "SSTL18_II"),
    "odt": ("o", "F31", "SSTL18_II"),
    "cke": ("o", "T28", "SSTL18_II"),
    "dm": ("o", "AJ31 AE28 Y24 Y31 V25 P24 F26 J25", "SSTL18_II_DCI"),
    "dqs": ("io", "AA29 AK28 AK26 AB31 Y28 E26 H28 G27", "DIFF_SSTL18_II_DCI"),
    "dqs_n": ("io", "AA30 AK27 AJ27 AA31 Y29 E27 G28 H27", "DIFF_SSTL18_II_DCI"),
    "ck": ("o", "AK29 E28", "DIFF_SSTL18_II"),
    "ck_n": ("o", "AJ29 F28", "DIFF_SSTL18_II"),
}


def _ddr2_resource():
    """The ``ddr2`` resource: one subsignal per MIG pin group (:data:`DDR2_SUBSIGNALS`)."""
    return Resource("ddr2", 0, *(
        Subsignal(name, Pins(pins, dir=direction), Attrs(IOSTANDARD=standard))
        for name, (direction, pins, standard) in DDR2_SUBSIGNALS.items()))


class GenesysPlatform(ISEFlow, XilinxPlatform):
    """Digilent Genesys: XC5VLX50T, FF1136 package, speed grade -1, built with Xilinx ISE (14.7).

    Parameters
    ----------
    pins : dict of str to str
        FPGA pins for VHDC placeholders (``{"UNCONFIRMED_VHDC_12": "AB12", ...}``), for when the connector's map has
        been read off the Genesys schematic: they replace their placeholders in the connector's map.
    **kwargs
        For :class:`board.ise.ISEFlow`: ``allow_unconfirmed``, ``files``, ``toolchain``, ``mig``.

    Raises
    ------
    ValueError
        A ``pins`` name that is not one of :data:`UNCONFIRMED`.
    """

    device = "xc5vlx50t"
    package = "ff1136"
    speed = "1"
    default_clk = "clk100"
    default_rst = "rst"
    resources = [
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
        *VmodCAMResources(_VHDC_BANK, vhdc=0),
        _ddr2_resource(),
    ]
    connectors = [Connector("vhdc", 0, VHDC)]

    def __init__(self, *, pins=None, **kwargs):
        pins = dict(pins or {})
        unknown = sorted(set(pins) - set(UNCONFIRMED))
        if unknown:
            raise ValueError(f"pin override for unknown placeholder(s): {', '.join(unknown)}")
        if pins:     # read by Platform.__init__ in place of the class's list
            self.connectors = [Connector("vhdc", 0, {conn: pins.get(fpga, fpga) for conn, fpga in VHDC.items()})]
        super().__init__(**kwargs)

    @property
    def unconfirmed_in_use(self):
        """Placeholder locations the VmodCAM's pins still resolve to (after ``pins``), in signal order."""
        vhdc = dict(self.connectors["vhdc", 0])
        located = (vhdc[f"vhdc_0:{pin}"] for pins in VHDC_PINS.values() for pin in pins.split())
        return tuple(fpga for fpga in located if fpga.startswith(UNCONFIRMED_PREFIX))
