"""What the MT9D112 does with each register and firmware variable the init tables write: the decoding behind
:class:`sim.models.mt9d112.target.MT9D112Model`.

:class:`MT9D112Registers` holds the register file and the MCU's variables and turns them into the sensor's state
(:meth:`MT9D112Registers.state`, a dict with the keys of ``golden.part_config.mt9d112_expected``) and output
configuration. Every write is decoded when it arrives; a register, variable or bit pattern the model does not
know is a :class:`RegisterError` (raised, and kept in :attr:`MT9D112Registers.errors`), never ignored.

Sources (no public MT9D112 data sheet or developer guide was in reach; docs/i2c.md):

* [CAMCTL] Digilent VmodCAM Reference Design 2, ``CamCtl.vhd``: every value of our table and its comments.
* [MSM] Linux ``drivers/staging/dream/camera/mt9d112.c`` (Qualcomm): 0x3386 MCU boot 0x0501 -> 0x0500 ("Put MCU
  into Reset" / "Pull MCU from Reset"), 0x3202 standby control 0x0008, 0x301A 0x0ACC, the PLL sequence 0x341E
  0x8F09 / 0x341C 0x0250 / 0x341E 0x8F08, the context-B variables (0x272F.. rows 4..1211, columns 4..1611,
  0x2741 Sensor_Fine_IT_min, 0x275F.. crop), the sequencer commands (0xA103: 1 preview, 2 capture, 5 refresh
  mode, 6 refresh) and the snapshot switch (0xA120 <- 2, 0xA103 <- 2).
* [MT9D111] the sister SOC's firmware (same drivers 1 and 7): G. Marcelino's driver -- "seq.captureParams.mode[1]
  = 1" with "seq.cmd = 2" switches to capture and stays (video), mode[1] = 0 with seq.cmd = 1 goes back to
  preview; RGB565 = output format 0x20, RGB555 0x60; Espressif's driver: byte swap = 0x0022.
* [OMAP] Linux OMAP ``sensor_mt9d112.c``: 0x3000 = 0x1580, context-B RGB = variable 0x2797 bit 5.
* [MT9T111] Aptina MT9T111 developer guide table 23: output format bit 0 swaps R and B, bit 1 swaps the bytes.

Model assumptions (stated, not from a source): the power-on values in :data:`POWER_ON_REGS` /
:data:`POWER_ON_VARS`; the PCLK formula ``MCLK x M / (N + 1) / 8`` with M = 0x341C[7:0], N = 0x341C[13:8]
(it gives CamCtl's "80 MHz" from 0x0250); a still capture (captureParams.mode[1] = 0) outputs
``still_frames`` frames in context B and returns to preview (context A); bits whose meaning no source gives must
keep the value the references write (listed per register in :data:`RESERVED`).
"""

__all__ = ["RegisterError", "MT9D112Registers", "POWER_ON_REGS", "POWER_ON_VARS", "KNOWN_VARIABLES",
           "KNOWN_REGISTERS", "decode_output_format"]


class RegisterError(ValueError):
    """A write the model does not understand (unknown register, variable or bit pattern)."""


CHIP_VERSION = 0x1580
# registers
MCU_BOOT, SLEW, PLL_DIV, PLL_CTRL, STANDBY, RESET_CTRL, VAR_ADDR, VAR_DATA, CHIP = (
    0x3386, 0x3214, 0x341C, 0x341E, 0x3202, 0x301A, 0x338C, 0x3390, 0x3000)

#: Register -> what it is. Reading 0x3000 and 0x3390 is also modelled.
KNOWN_REGISTERS = {
    MCU_BOOT: "MCU boot mode: bit 0 holds the MCU in reset [MSM, CAMCTL]",
    SLEW: "slew rate: PCLK [10:8], data [2:0] [CAMCTL 'PCLK 5, D 5']",
    PLL_DIV: "PLL dividers: M [7:0], N [13:8] [CAMCTL, MSM]",
    PLL_CTRL: "PLL control: bit 0 bypass, bit 1 power-down [CAMCTL, MSM]",
    STANDBY: "standby control: 0x0008 = awake [CAMCTL 'wake up', MSM]",
    RESET_CTRL: "reset/output control: bits 7, 6, 3, 2 (0x00CC) = parallel output on [CAMCTL, MSM]",
    VAR_ADDR: "MCU variable address: bit 15 8-bit access, bit 13 logical address, [12:8] driver, [7:0] offset",
    VAR_DATA: "MCU variable data",
}

#: Bits of a register whose meaning no source gives: they must equal what the references write.
RESERVED = {MCU_BOOT: (0xFFFE, {0x0500}), SLEW: (0xF8F8, {0x0880}), PLL_DIV: (0xC000, {0x0000}),
            PLL_CTRL: (0xFFFC, {0x8F08}), RESET_CTRL: (0xFF33, {0x0200, 0x0A00})}

#: (driver, offset) -> (name, bits). Driver 7 = mode/context, driver 1 = sequencer.
KNOWN_VARIABLES = {
    (7, 0x03): ("output_width_a", 16), (7, 0x05): ("output_height_a", 16),
    (7, 0x07): ("output_width_b", 16), (7, 0x09): ("output_height_b", 16),
    (7, 0x2F): ("row_start_b", 16), (7, 0x31): ("col_start_b", 16),
    (7, 0x33): ("row_end_b", 16), (7, 0x35): ("col_end_b", 16),
    (7, 0x41): ("fine_it_min_b", 16),
    (7, 0x5F): ("crop_x0_b", 16), (7, 0x61): ("crop_x1_b", 16),
    (7, 0x63): ("crop_y0_b", 16), (7, 0x65): ("crop_y1_b", 16),
    (7, 0x95): ("output_format_a", 16), (7, 0x97): ("output_format_b", 16),
    (1, 0x03): ("seq_cmd", 8), (1, 0x20): ("capture_mode", 8),
}

#: Register file at power-on (model assumption: PLL bypassed and powered down, MCU running, output off).
POWER_ON_REGS = {CHIP: CHIP_VERSION, MCU_BOOT: 0x0500, PLL_CTRL: 0x8F0B, PLL_DIV: 0x0000, RESET_CTRL: 0x0200,
                 STANDBY: 0x0008, SLEW: 0x0D85, VAR_ADDR: 0x0000}
#: Variables at power-on (model assumption: preview = context A 800 x 600, capture = context B 1600 x 1200,
#: both YUV; the context-B window of [MSM]; still capture).
POWER_ON_VARS = {
    "output_width_a": 800, "output_height_a": 600, "output_width_b": 1600, "output_height_b": 1200,
    "row_start_b": 4, "col_start_b": 4, "row_end_b": 1211, "col_end_b": 1611, "fine_it_min_b": 361,
    "crop_x0_b": 0, "crop_x1_b": 1600, "crop_y0_b": 0, "crop_y1_b": 1200,
    "output_format_a": 0x0000, "output_format_b": 0x0000, "seq_cmd": 0, "capture_mode": 0x00,
}
#: Output-format bits the model knows: 0 swap R/B, 1 swap bytes [MT9T111]; 4 BT.656 codes [CAMCTL];
#: 5 RGB [OMAP, MT9D111]; 7:6 RGB format (0 = 5:6:5, 1 = 5:5:5) [MT9D111].
_FORMAT_KNOWN = 0x00F3
#: Capture-mode bits: 1 = video (continuous) [MT9D111, MSM]; 7:4 = CamCtl's 0xF ("AWB, AE, HG on", no source
#: gives the individual bits, so no other value is understood); bits 0, 2, 3: not understood (must be 0).
_CAPTURE_OPTIONS = 0xF0
SEQ_COMMANDS = {1: "go to preview", 2: "go to capture", 5: "refresh mode", 6: "refresh"}


def decode_output_format(value):
    """``(format, r_byte_first, rb_swapped, bt656_codes)`` of an output-format variable; raises
    :class:`RegisterError` on bits or an RGB format the model does not know."""
    if value & ~_FORMAT_KNOWN:
        raise RegisterError(f"output format 0x{value:04x}: bits 0x{value & ~_FORMAT_KNOWN:04x} not understood")
    if not value & 0x20:
        fmt = "yuv"
    else:
        fmt = {0: "rgb565", 1: "rgb555"}.get((value >> 6) & 3)
        if fmt is None:
            raise RegisterError(f"output format 0x{value:04x}: RGB format {(value >> 6) & 3} not modelled")
    return fmt, not value & 0x2, bool(value & 0x1), bool(value & 0x10)


class MT9D112Registers:
    """The register file, the MCU variables and the sequencer of one MT9D112 (see the module docstring).

    ``write(reg, value, now)`` / ``read(reg, now)`` are the register accesses (``now`` in seconds, for the PLL
    lock check); ``state()`` the resulting sensor state; ``start_frame()`` advances a still capture by one
    frame. ``cmd_busy_reads``: reads of the command variable that still return the command before it completes.
    """

    def __init__(self, *, extclk_hz=24_000_000, pll_lock_s=1e-3, cmd_busy_reads=2, still_frames=1):
        self.extclk_hz = extclk_hz
        self.pll_lock_s = pll_lock_s
        self.cmd_busy_reads = cmd_busy_reads
        self.still_frames = still_frames
        self.regs = dict(POWER_ON_REGS)
        self.vars = dict(POWER_ON_VARS)
        self.errors = []
        self.problems = []
        self.commands_done = []
        self.context = "A"
        self.sequencer_state = "preview"
        self.latched = self._latch("A")
        self._cmd_reads = 0
        self._pll_up_at = None
        self._still_left = None

    # ---- register accesses ----------------------------------------------------------------------------------
    def _error(self, message):
        self.errors.append(message)
        raise RegisterError(message)

    def write(self, reg, value, now=0.0):
        if reg == VAR_ADDR:
            self._check_var_address(value)
        elif reg == VAR_DATA:
            self._write_var(value)
        elif reg in (MCU_BOOT, SLEW, PLL_DIV, RESET_CTRL):
            self._check_reserved(reg, value)
            if reg == RESET_CTRL and (value & 0x00CC) not in (0, 0x00CC):
                self._error(f"0x301A = 0x{value:04x}: the output bits 0x00CC are neither all set nor all clear")
        elif reg == PLL_CTRL:
            self._check_reserved(reg, value)
            self._pll_control(value, now)
        elif reg == STANDBY:
            if value != 0x0008:
                self._error(f"0x3202 = 0x{value:04x}: only 0x0008 (awake) is understood")
        else:
            self._error(f"write to register 0x{reg:04x}: not a register the model knows (or read-only)")
        self.regs[reg] = value

    def read(self, reg, now=0.0):
        if reg == VAR_DATA:
            return self._read_var()
        if reg not in self.regs:
            self._error(f"read of register 0x{reg:04x}: not a register the model knows")
        return self.regs[reg]

    def _check_reserved(self, reg, value):
        mask, allowed = RESERVED[reg]
        if value & mask not in allowed:
            self._error(f"register 0x{reg:04x} = 0x{value:04x}: bits 0x{value & mask:04x} under mask "
                        f"0x{mask:04x} not understood (the references write {sorted(map(hex, allowed))})")

    def _pll_control(self, value, now):
        old = self.regs[PLL_CTRL]
        if (old & 0x2) and not (value & 0x2):
            self._pll_up_at = now
        if (old & 0x1) and not (value & 0x1):
            if self._pll_up_at is None or value & 0x2:
                self.problems.append("PLL bypass turned off while the PLL is powered down")
            elif now - self._pll_up_at < self.pll_lock_s:
                self.problems.append(f"PLL bypass turned off {1e6 * (now - self._pll_up_at):.0f} us after "
                                     f"power-up (lock time {1e6 * self.pll_lock_s:.0f} us)")

    # ---- MCU variables ---------------------------------------------------------------------------------------
    def _var(self):
        a = self.regs[VAR_ADDR]
        key = ((a >> 8) & 0x1F, a & 0xFF)
        if key not in KNOWN_VARIABLES:
            self._error(f"access to 0x3390 with variable address 0x{a:04x}: not a variable the model knows")
        return KNOWN_VARIABLES[key], bool(a & 0x8000)

    def _check_var_address(self, a):
        key = ((a >> 8) & 0x1F, a & 0xFF)
        if not a & 0x2000 or a & 0x4000:
            self._error(f"variable address 0x{a:04x}: only logical addressing (bit 13) is modelled")
        if key not in KNOWN_VARIABLES:
            self._error(f"variable {key[0]}:0x{key[1]:02x} (address 0x{a:04x}) is not one the model knows")
        name, bits = KNOWN_VARIABLES[key]
        if bool(a & 0x8000) != (bits == 8):
            self._error(f"variable {name} is {bits}-bit but address 0x{a:04x} selects "
                        f"{'8' if a & 0x8000 else '16'}-bit access")

    def _write_var(self, value):
        (name, bits), _ = self._var()
        if value >> bits:
            self._error(f"variable {name} = 0x{value:x} does not fit {bits} bits")
        if name in ("output_format_a", "output_format_b"):
            decode_output_format(value)
        elif name == "capture_mode" and value & ~0x02 != _CAPTURE_OPTIONS:
            self._error(f"capture mode 0x{value:02x}: only bit 1 (video) with bits 7:4 = 0xF is understood")
        elif name == "seq_cmd" and value not in SEQ_COMMANDS and value != 0:
            self._error(f"sequencer command {value} is not one the model knows {sorted(SEQ_COMMANDS)}")
        self.vars[name] = value
        if name == "seq_cmd" and value:
            self._cmd_reads = 0

    def _read_var(self):
        (name, bits), _ = self._var()
        value = self.vars[name]
        if name == "seq_cmd" and value and self.mcu_running:
            self._cmd_reads += 1
            if self._cmd_reads > self.cmd_busy_reads:
                self._execute(value)
                value = self.vars[name] = 0
        return value

    # ---- sequencer -------------------------------------------------------------------------------------------
    @property
    def mcu_running(self):
        return not self.regs[MCU_BOOT] & 0x1

    def _execute(self, cmd):
        if cmd == 1:
            self.context, self.sequencer_state, self._still_left = "A", "preview", None
        elif cmd == 2:
            self.context, self.sequencer_state = "B", "capture"
            video = bool(self.vars["capture_mode"] & 0x02)
            self._still_left = None if video else self.still_frames
        self.latched = self._latch(self.context)          # 5 / 6 (refresh): the new variables take effect
        self.commands_done.append(cmd)

    def start_frame(self):
        """A frame starts: a still capture counts it down and returns to preview after its last frame."""
        if self._still_left is not None:
            if self._still_left == 0:
                self._execute(1)
            else:
                self._still_left -= 1

    def _latch(self, context):
        c = context.lower()
        out = {"width": self.vars[f"output_width_{c}"], "height": self.vars[f"output_height_{c}"],
               "format": self.vars[f"output_format_{c}"]}
        if context == "B":
            out.update({k: self.vars[f"{k}_b"] for k in ("row_start", "row_end", "col_start", "col_end",
                                                        "crop_x0", "crop_x1", "crop_y0", "crop_y1", "fine_it_min")})
        return out

    # ---- the resulting state ---------------------------------------------------------------------------------
    @property
    def pll_enabled(self):
        return not self.regs[PLL_CTRL] & 0x3

    @property
    def pclk_hz(self):
        if not self.pll_enabled:
            return self.extclk_hz
        div = self.regs[PLL_DIV]
        return self.extclk_hz * (div & 0xFF) / (((div >> 8) & 0x3F) + 1) / 8

    @property
    def parallel_output(self):
        return (self.regs[RESET_CTRL] & 0x00CC) == 0x00CC

    def state(self):
        """The sensor state: the keys of ``golden.part_config.mt9d112_expected`` (see there for each)."""
        lat = self.latched
        fmt, r_first, rb_swap, bt656 = decode_output_format(lat["format"])
        s = {
            "mcu_running": self.mcu_running, "pll_enabled": self.pll_enabled, "pclk_hz": self.pclk_hz,
            "standby": self.regs[STANDBY] != 0x0008,
            "slew_pclk": (self.regs[SLEW] >> 8) & 7, "slew_data": self.regs[SLEW] & 7,
            "context": self.context, "sequencer_state": self.sequencer_state,
            "capture_video": bool(self.vars["capture_mode"] & 0x02),
            "capture_options": self.vars["capture_mode"] >> 4,
            "output_width": lat["width"], "output_height": lat["height"], "output_format": fmt,
            "r_byte_first": r_first, "rb_swapped": rb_swap, "bt656_codes": bt656,
            "parallel_output": self.parallel_output,
        }
        if self.context == "B":
            s.update({"sensor_rows": (lat["row_start"], lat["row_end"]),
                      "sensor_cols": (lat["col_start"], lat["col_end"]),
                      "crop": (lat["crop_x0"], lat["crop_y0"], lat["crop_x1"], lat["crop_y1"]),
                      "fine_it_min": lat["fine_it_min"]})
        return s

    def consistency(self):
        """Inconsistencies of the active context's window (empty list = none), plus the PLL-lock problems."""
        out = list(self.problems)
        lat = self.latched
        if self.context == "B":
            if lat["crop_x1"] - lat["crop_x0"] < lat["width"] or lat["crop_y1"] - lat["crop_y0"] < lat["height"]:
                out.append("output size larger than the crop window (the resizer only scales down)")
            if (lat["col_end"] - lat["col_start"] + 1 < lat["crop_x1"]
                    or lat["row_end"] - lat["row_start"] + 1 < lat["crop_y1"]):
                out.append("crop window larger than the sensor window")
        return out
