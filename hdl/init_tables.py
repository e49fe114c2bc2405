"""The I2C initialisation tables of the MT9D112 sensors and the CH7301C DVI transmitter, as data.

An :class:`InitTable` is the ordered program an :class:`hdl.i2c_init.InitSequencer` plays from its ROM for one
device on one bus. Its entries are:

* :class:`Write`: one register write (``reg``, ``value``), one I2C transaction
  ``S addr+W reg.. value.. P``, most significant byte first.
* :class:`Wait`: a pause of ``us`` microseconds (after reset, after powering the PLL, before polling).
* :class:`Poll`: read ``reg`` (``S addr+W reg.. Sr addr+R data.. P``) until ``data & mask == value``, at most
  ``attempts`` reads, ``interval_us`` apart; with ``attempts=1`` it is a one-shot check that stops the
  bring-up on a mismatch (the MT9D112 chip version).
* :class:`Check`: read ``reg`` once and compare ``data & mask`` with ``value``; a mismatch is recorded (the
  sequencer's sticky ``mismatch`` output, an LED on the board) and the bring-up carries on. For identification
  bytes no public data sheet confirms (the CH7301C's version and device IDs).

Each entry carries a comment saying what it sets. Register addresses/values are those of the sources below;
the project did not invent values. Where a source's comment is the only documentation of a bit (no public
datasheet text in reach), docs/i2c.md says so.

MT9D112 (:data:`MT9D112_TABLE`, 16-bit register address, 16-bit data, 7-bit address ``I2C_ADDR.MT9D112``)
    Digilent "VmodCAM Reference Design 2", ``CamCtl.vhd`` (Elod Gyorgy, 2011): the configuration Digilent
    ships for this very camera board, "video capture mode in 1600x1200 @ 80 MHz pixel clock", RGB output in
    context B. Copied entry for entry in the same order (chip version check, MCU reset, slew rate, PLL,
    standby, context-B variables, capture mode, sequencer command, poll, output enable). Cross-checked against
    the Linux OMAP driver ``sensor_mt9d112.c`` (Wind River, 2007: ``0x338C``/``0x3390`` variable access, chip
    version register ``0x3000`` = ``0x1580``, context-B RGB565 = variable ``0x2797`` bit 5, crop variables
    ``0x275F``..``0x2765``) and the MT9D111 drivers (sister SOC with the same firmware variables: Espressif
    ``esp_cam_sensor`` RGB565 = ``0x0020``, byte-swapped ``0x0022``; G. Marcelino's driver RGB565 ``0x20``,
    RGB555 ``0x60``).

    Variable access: ``0x338C`` takes the variable address (bit 15: 8-bit access, bit 13: logical address,
    bits 12:8 driver ID, bits 7:0 offset), ``0x3390`` then reads/writes its value. Driver 7 is the mode/context
    driver, driver 1 the sequencer.

    Byte order: ``0x2797`` = ``0x0030`` leaves bit 1 (swap odd/even bytes) clear, so each RGB565 pixel comes
    out high byte first: R[4:0]G[5:3] on the first PCLK, G[2:0]B[4:0] on the second ("R byte first"), which
    is the capture path's default. Digilent's ``CamCtl`` captures the first byte into D[15:8] accordingly.

CH7301C (:data:`CH7301C_TABLE`, 8-bit register address, 8-bit data, 7-bit address ``I2C_ADDR.CH7301C``)
    Register map and bit names: Xorg ``xf86-video-intel`` ``ch7xxx_reg.h``/``ch7xxx.c`` (Dave Airlie, 2006)
    and U-Boot ``ch7301.c`` (Dirk Eibach, 2014). Values: VLSI-EDA PoC ``vga_phy_ch7301c`` (used on the Xilinx
    ML505, a Virtex-5 board with the same CH7301C wiring) and the Xorg driver, using the "pixel clock
    > 65 MHz" DVI PLL settings because 1080p60 runs at 148.5 MHz. Input format IDF = 0 (12-bit multiplexed
    RGB 8:8:8, one 1x clock, data on both edges), the CH7301C's dual-edge mode; the clock mode register 0x1C
    is left at its power-on default as in every reference (1x clock, both edges).
"""

from dataclasses import dataclass, field

from spec.board import I2C_ADDR
from spec.video import CEA_1080P60

__all__ = [
    "I2CDeviceSpec", "Write", "Wait", "Poll", "Check", "InitTable", "MT9D112", "CH7301C", "MT9D112_TABLE",
    "CH7301C_TABLE", "ch7301c_table"
]


@dataclass(frozen=True)
class I2CDeviceSpec:
    """A target on a bus: its name, 7-bit address and register-address / data widths in bytes."""
    name: str
    address: int
    reg_bytes: int
    data_bytes: int

    def __post_init__(self):
        if not 0x08 <= self.address <= 0x77:
            raise ValueError(f"{self.name}: 7-bit address 0x{self.address:02x} is reserved or out of range")
        if self.reg_bytes not in (1, 2) or self.data_bytes not in (1, 2):
            raise ValueError(f"{self.name}: register and data widths must be 1 or 2 bytes")


@dataclass(frozen=True)
class Write:
    reg: int
    value: int
    comment: str = ""


@dataclass(frozen=True)
class Wait:
    us: int
    comment: str = ""


@dataclass(frozen=True)
class Poll:
    reg: int
    value: int
    mask: int = 0xFFFF
    attempts: int = 1
    interval_us: int = 0
    comment: str = ""


@dataclass(frozen=True)
class Check:
    reg: int
    value: int
    mask: int = 0xFFFF
    comment: str = ""


@dataclass(frozen=True)
class Barrier:
    """Hold until every sequencer that shares the barrier has reached it; they all go on at the same clock (the
    two cameras' tables: the start of streaming written to both sensors at the same instant)."""
    comment: str = ""


@dataclass(frozen=True)
class InitTable:
    """An ordered list of :class:`Write` / :class:`Wait` / :class:`Poll` / :class:`Check` / :class:`Barrier`
    entries for one device."""
    device: I2CDeviceSpec
    entries: tuple = field(default_factory=tuple)

    def __post_init__(self):
        reg_max = (1 << (8 * self.device.reg_bytes)) - 1
        data_max = (1 << (8 * self.device.data_bytes)) - 1
        if not self.entries:
            raise ValueError(f"{self.device.name}: an init table needs at least one entry")
        for i, e in enumerate(self.entries):
            where = f"{self.device.name} entry {i}"
            if isinstance(e, (Write, Poll, Check)):
                if not 0 <= e.reg <= reg_max:
                    raise ValueError(f"{where}: register 0x{e.reg:x} does not fit {self.device.reg_bytes} byte(s)")
                if not 0 <= e.value <= data_max:
                    raise ValueError(f"{where}: value 0x{e.value:x} does not fit {self.device.data_bytes} byte(s)")
            if isinstance(e, Poll):
                if e.attempts < 1:
                    raise ValueError(f"{where}: a poll needs at least one attempt")
                if e.interval_us < 0:
                    raise ValueError(f"{where}: negative poll interval")
            elif isinstance(e, Wait):
                if e.us < 0:
                    raise ValueError(f"{where}: negative wait")
            elif not isinstance(e, (Write, Check, Barrier)):
                raise TypeError(f"{where}: {e!r} is not a Write, Wait, Poll, Check or Barrier")

    def __len__(self):
        return len(self.entries)

    def writes(self):
        """The register writes of the table, in order, as ``(register, value)``."""
        return [(e.reg, e.value) for e in self.entries if isinstance(e, Write)]


MT9D112 = I2CDeviceSpec("mt9d112", I2C_ADDR.MT9D112, reg_bytes=2, data_bytes=2)
CH7301C = I2CDeviceSpec("ch7301c", I2C_ADDR.CH7301C, reg_bytes=1, data_bytes=1)

# MT9D112 registers and variables used below.
_MCU_BOOT_MODE = 0x3386        # MCU reset control
_VAR_ADDRESS = 0x338C          # MCU variable address
_VAR_DATA = 0x3390             # MCU variable data


def mt9d112_var(driver, offset, value, comment, *, bits=16):
    """The two writes that set MCU variable (``driver``, ``offset``) to ``value`` (bit 13: logical address,
    bit 15: 8-bit access)."""
    address = 0x2000 | (driver << 8) | offset | (0x8000 if bits == 8 else 0)
    return (Write(_VAR_ADDRESS, address, f"variable address {driver}:0x{offset:02x} ({comment})"),
            Write(_VAR_DATA, value, comment))


#: MT9D112 to 1600 x 1200 RGB565 (R byte first), 80 MHz PCLK from a 24 MHz MCLK, context B (capture).
MT9D112_TABLE = InitTable(MT9D112, (
    Wait(1000, "after reset: >= 7000 MCLK cycles (292 us at 24 MHz, CamCtl RST_T4) before the first access"),
    Poll(0x3000, 0x1580, attempts=1, comment="chip version register reads 0x1580 (MT9D112)"),
    Write(_MCU_BOOT_MODE, 0x0501, "MCU reset"),
    Write(_MCU_BOOT_MODE, 0x0500, "MCU released from reset"),
    Write(0x3214, 0x0D85, "slew rate control: PCLK 5, D 5"),
    Write(0x341E, 0x8F0B, "PLL control: bypassed, powered down"),
    Write(0x341C, 0x0250, "PLL dividers M=80, N=2: 24 MHz * 80 / (N+1) / 8 = 80 MHz"),
    Write(0x341E, 0x8F09, "PLL control: PLL powered up (still bypassed)"),
    Wait(1000, "PLL lock: 1 ms after powering up the PLL (CamCtl)"),
    Write(0x341E, 0x8F08, "PLL control: bypass off, the sensor runs from the PLL"),
    Write(0x3202, 0x0008, "standby control: wake up"),
    *mt9d112_var(7, 0x97, 0x0030, "output format context B: RGB (bit 5) 565 (bits 7:6 = 0), no byte swap, "
                                  "BT.656 codes (bit 4)"),
    *mt9d112_var(7, 0x2F, 0x0004, "sensor row start context B = 4"),
    *mt9d112_var(7, 0x33, 0x04BB, "sensor row end context B = 1211"),
    *mt9d112_var(7, 0x31, 0x0004, "sensor column start context B = 4"),
    *mt9d112_var(7, 0x35, 0x064B, "sensor column end context B = 1611"),
    *mt9d112_var(7, 0x07, 0x0640, "output width context B = 1600"),
    *mt9d112_var(7, 0x09, 0x04B0, "output height context B = 1200"),
    *mt9d112_var(7, 0x5F, 0x0000, "crop X0 context B = 0"),
    *mt9d112_var(7, 0x63, 0x0000, "crop Y0 context B = 0"),
    *mt9d112_var(7, 0x61, 0x0640, "crop X1 context B = 1600"),
    *mt9d112_var(7, 0x65, 0x04B0, "crop Y1 context B = 1200"),
    *mt9d112_var(7, 0x41, 0x0169, "sensor_fine_IT_min context B = 361"),
    *mt9d112_var(1, 0x20, 0x00F2, "sequencer capture mode options: AWB, AE, HG on, video (continuous)", bits=8),
    *mt9d112_var(1, 0x03, 0x0002, "sequencer command: go to capture (context B)", bits=8),
    Wait(1000, "before polling: give the MCU time to take the command"),
    Poll(_VAR_DATA, 0x0000, attempts=1000, interval_us=1000,
         comment="sequencer command variable reads 0 once the command is done (<= 1 s)"),
    Barrier("both cameras' tables meet here: the start of streaming goes to both sensors at the same clock"),
    Write(0x301A, 0x02CC, "reset/output control: parallel interface on, drive pins, start streaming"),
))


def ch7301c_table(timing=CEA_1080P60, device=CH7301C):
    """The CH7301C table for a video mode: DVI output of the 12-bit dual-edge RGB input, DVI PLL settings for
    the mode's pixel clock (the references' two ranges, <= 65 MHz and > 65 MHz), sync polarities of the mode."""
    fast = timing.pixel_hz > 65_000_000
    idf = 0x80 | (0x08 if timing.hsync_positive else 0) | (0x10 if timing.vsync_positive else 0)
    polarity = (f"hsync {'+' if timing.hsync_positive else '-'}, vsync {'+' if timing.vsync_positive else '-'}")
    rng = "> 65 MHz" if fast else "<= 65 MHz"
    return InitTable(device, (
        Check(0x4A, 0x95, mask=0xFF, comment="version ID 0x95 (Linux/Xorg CH7301_VID); a mismatch is shown, "
                                             "not fatal: no data sheet confirms it for the CH7301C"),
        Check(0x4B, 0x17, mask=0xFF, comment="device ID 0x17 (U-Boot's CH7301 probe, Xorg CH7xxx_DID)"),
        Write(0x1F, idf, f"input data format: IDF 0 (12-bit multiplexed RGB 8:8:8, both clock edges), {polarity}"),
        Write(0x33, 0x06 if fast else 0x08, f"DVI PLL charge pump (TPCP), pixel clock {rng}"),
        Write(0x34, 0x26 if fast else 0x16, f"DVI PLL divider (TPD), pixel clock {rng}"),
        Write(0x36, 0xA0 if fast else 0x60, f"DVI PLL filter (TPF), pixel clock {rng}"),
        Write(0x49, 0xC0, "power management: DVI transmitter and link on (DVIP, DVIL), full power-down off"),
    ))


#: CH7301C to DVI output for the 1080p60 display (148.5 MHz, positive syncs).
CH7301C_TABLE = ch7301c_table()
