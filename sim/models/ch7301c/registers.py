"""What the CH7301C does with each register the init table writes: the decoding behind
:class:`sim.models.ch7301c.target.CH7301CModel`.

:class:`CH7301CRegisters` holds the register file and turns it into the transmitter's mode
(:meth:`CH7301CRegisters.state`, a dict with the keys of ``golden.part_config.ch7301c_expected``). A register or
bit pattern the model does not know is a :class:`RegisterError` (raised and kept in ``errors``).

Sources (register names and bits; docs/i2c.md): [XORG] ``xf86-video-intel`` ``ch7xxx_reg.h`` / ``ch7xxx.c`` and
Linux ``dvo_ch7xxx.c`` (0x1F IDF: bits 2:0 input format, bit 3 HSP, bit 4 VSP; 0x49 PM: bit 0 FPD, bits 3:1
DAC power-down, bit 6 DVIL, bit 7 DVIP; 0x4A version 0x95 = CH7301, 0x4B device ID 0x17; 0x33 TPCP, 0x34 TPD,
0x36 TPF), [UBOOT] U-Boot ``ch7301.c`` (device ID 0x17 in 0x4B; register names), [POC] VLSI-EDA PoC
``vga_phy_ch7301c`` (ML505: 0x1F = 0x80 with bit 7 set, the DVI PLL triples for <= 65 MHz and > 65 MHz,
0x49 = 0xC0). IDF 0 = 12-bit multiplexed RGB 8:8:8 on both XCLK edges [POC; Xilinx xps_tft].

Model assumptions: power-on PM = 0x01 (full power-down), IDF = 0x00, PLL registers unset; bit 7 of IDF is
recorded as ``idf_bit7`` (PoC sets it; its name, IBS, comes from the project's hardware notes, no data sheet
text says what it does); bits 6:5 of IDF and 5:4 of PM are not understood.
"""

__all__ = ["RegisterError", "CH7301CRegisters", "DVI_PLL_SETTINGS", "VERSION_ID", "DEVICE_ID"]

from sim.models.mt9d112.registers import RegisterError

VERSION_ID = 0x95
DEVICE_ID = 0x17
IDF, TPCP, TPD, TPF, PM, VID, DID = 0x1F, 0x33, 0x34, 0x36, 0x49, 0x4A, 0x4B

#: (TPCP, TPD, TPF) -> pixel-clock range [POC, XORG, Xilinx iic_init.v].
DVI_PLL_SETTINGS = {(0x08, 0x16, 0x60): "<= 65 MHz", (0x06, 0x26, 0xA0): "> 65 MHz"}
_WRITABLE = {IDF: 0x9F, TPCP: 0xFF, TPD: 0xFF, TPF: 0xFF, PM: 0xCF}    # register -> bits understood
_INPUT_FORMATS = {0: "12-bit multiplexed RGB 8:8:8, both XCLK edges"}


class CH7301CRegisters:
    """The CH7301C's register file (8-bit registers). ``version_id`` / ``device_id``: what 0x4A / 0x4B read."""

    def __init__(self, *, version_id=VERSION_ID, device_id=DEVICE_ID):
        self.regs = {PM: 0x01, IDF: 0x00, VID: version_id, DID: device_id}
        self.errors = []

    def _error(self, message):
        self.errors.append(message)
        raise RegisterError(message)

    def write(self, reg, value):
        if reg not in _WRITABLE:
            self._error(f"write to register 0x{reg:02x}: not a register the model knows (or read-only)")
        if value & ~_WRITABLE[reg]:
            self._error(f"register 0x{reg:02x} = 0x{value:02x}: bits 0x{value & ~_WRITABLE[reg]:02x} not understood")
        if reg == IDF and (value & 0x7) not in _INPUT_FORMATS:
            self._error(f"IDF = 0x{value:02x}: input format {value & 0x7} not modelled")
        self.regs[reg] = value

    def read(self, reg):
        if reg not in self.regs:
            self._error(f"read of register 0x{reg:02x}: not a register the model knows")
        return self.regs[reg]

    @property
    def dvi_pll(self):
        """The DVI PLL setting: a range of :data:`DVI_PLL_SETTINGS`, ``"unset"``, or an error for a mix."""
        triple = tuple(self.regs.get(r) for r in (TPCP, TPD, TPF))
        if triple == (None, None, None):
            return "unset"
        if triple not in DVI_PLL_SETTINGS:
            self._error("DVI PLL registers (TPCP, TPD, TPF) = " + ", ".join("--" if v is None else f"0x{v:02x}"
                                                                           for v in triple)
                        + ": not one of the documented settings")
        return DVI_PLL_SETTINGS[triple]

    def state(self):
        """The transmitter's mode: the keys of ``golden.part_config.ch7301c_expected``."""
        pm, idf = self.regs[PM], self.regs[IDF]
        return {
            "full_power_down": bool(pm & 0x01),
            "dvi_output": bool(pm & 0x80) and bool(pm & 0x40) and not pm & 0x01,
            "dac_powered_down": (pm >> 1) & 0x7 == 0x7,
            "input_format": _INPUT_FORMATS[idf & 0x7],
            "hsync_positive": bool(idf & 0x08), "vsync_positive": bool(idf & 0x10), "idf_bit7": bool(idf & 0x80),
            "dvi_pll": self.dvi_pll,
        }
