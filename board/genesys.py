"""The Digilent Genesys board (Virtex-5 XC5VLX50T-1FF1136) as an Amaranth ``XilinxPlatform``: its resources and
its VHDC connector, in the manner of amaranth-boards' board files (``amaranth_boards/atlys.py``).

Declared: the resources this design uses -- the 100 MHz oscillator, the reset button, SW0..SW7, LD0..LD7, the
CH7301C DVI transmitter (12-bit dual-edge data, XCLK pair, H/V sync, DE, reset, its I2C bus) -- and the VHDC
connector (``Connector("vhdc", 0, ...)``, :data:`VHDC`) with the VmodCAM on it as an add-on
(:func:`board.vmodcam.VmodCAMResources`: the cameras' pins are VHDC connector pins). The ISE build (templates, UCF
rendering, options) is :class:`board.ise.ISEFlow`; the ``--pins`` file is read by :mod:`board.pin_file`.

Every pin location carries its source in :data:`PIN_SOURCES`. The sources are public, stored copies read with
the project's search tool (docs/board.md has the table):

* ``strfry/nesfpga`` ``nes_top.ucf`` -- a working Genesys design whose UCF header says it is derived from
  "a general .ucf for Genesys rev C board" (Digilent's master UCF): the oscillator (``AG18``, GCLK0), LD0..LD7,
  the whole HDMI/CH7301C group with bank, pin name and schematic net name, the I2C bus, the reset input.
* ``strfry/nesfpga`` ``build.py`` -- the same project's pin list: SW0..SW7.
* ``d-hawkins/digilent_genesys`` ``doc/genesys_tutorial/sections/examples.tex`` -- GCLK0 = AG18 (bank 4, 3.3 V,
  LVCMOS33) and LD0..LD7 (bank 22, 3.3 V, LVCMOS33, 4 mA, SLOW): an independent second source that agrees.

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

__all__ = ["GenesysPlatform", "PIN_SOURCES", "VHDC", "UNCONFIRMED", "OSC_HZ"]

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
    "vhdc": "UNCONFIRMED: no stored copy of the Genesys VHDC pin-out (reference manual, schematic, master UCF)",
    "vmodcam": "VHDC connector pins: board/vmodcam.py (Digilent's Atlys VmodCAM UCF through the Atlys VHDC map); "
               "their FPGA pins: as vhdc",
    "vmodcam_vdden": "as vmodcam",
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


class GenesysPlatform(ISEFlow, XilinxPlatform):
    """Digilent Genesys: XC5VLX50T, FF1136 package, speed grade -1, built with Xilinx ISE (14.7).

    Parameters
    ----------
    pins : dict of str to str
        FPGA pins for VHDC placeholders (``{"UNCONFIRMED_VHDC_12": "AB12", ...}``), for when the connector's map has
        been read off the Genesys schematic: they replace their placeholders in the connector's map.
    **kwargs
        For :class:`board.ise.ISEFlow`: ``allow_unconfirmed``, ``files``, ``toolchain``.

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
