"""Open-drain I2C bus models: register-file targets for the MT9D112 and the CH7301C, a bus monitor that checks
the UM10204 timing, and the wiring that puts them next to the RTL in the Amaranth simulator and in cocotb.

Pure-Python cores (no simulator imports at module level):

* :class:`I2CTarget`: the bit-level target state machine. ``update(scl, sda, now)`` is called with the
  resolved bus levels whenever they may have changed (and when :meth:`I2CTarget.deadline` passes); the target
  then reports what it pulls low in ``scl_low`` / ``sda_low``. Fault injection: NACK its address, NACK a byte
  of a write, stretch SCL after every acknowledged byte, hold SDA or SCL low (for ever, or SDA for a number of
  SCL pulses, like a target stuck in the middle of a read).
* :class:`RegisterTarget`: register address + data framing on top; records every completed write and read.
* :class:`MT9D112Model`, :class:`CH7301CModel`: the two parts at their real addresses, with the behaviour the
  init tables rely on (chip IDs, MCU variables through 0x338C/0x3390, the sequencer command that reads back 0
  when done, PLL lock time, boot time after reset). ``MT9D112Model.sensor_config()`` gives the
  :class:`sim.sensor_config.SensorConfig` the sensor model obeys; ``CH7301CModel.dvi_config()`` the decoded
  DVI settings.
* :class:`I2CBusMonitor`: decodes START/STOP/bytes/ACKs from the two lines and measures every interval of
  UM10204 table 10 (its own copy of the standard's numbers, independent of the RTL's).

The open-drain bus these models sit on in a simulation, and the glue that runs them there (Amaranth simulator and
cocotb), is ``sim/i2c_bus.py``.

Model assumptions where no public datasheet text was available are listed in docs/i2c.md.
"""

from dataclasses import dataclass

from hdl.params import CLOCKS, I2C_ADDR
from sim.sensor_config import SensorConfig

__all__ = [
    "I2CTarget", "RegisterTarget", "MT9D112Model", "CH7301CModel", "DviConfig",
    "I2CBusMonitor", "STANDARD_MODE_LIMITS_US",
]


# --------------------------------------------------------------------------------------------------------
# Bit-level target
# --------------------------------------------------------------------------------------------------------

class I2CTarget:
    """A 7-bit-address I2C target on an open-drain bus (pure Python, event driven).

    Fault options: ``nack_address`` (NACK its own address), ``nack_write_byte`` (index of the byte after the
    address byte to NACK in write transactions; with ``nack_write_reg`` only in writes to that register),
    ``nack_times`` (how often those NACK faults fire; None = always), ``stretch_s`` (hold SCL low that long
    after each acknowledged byte), ``hold_sda_low`` / ``hold_scl_low`` (pull the line low for ever),
    ``hold_sda_pulses`` (pull SDA low until that many SCL falling edges have passed).
    """

    def __init__(self, address, *, name="target", nack_address=False, nack_write_byte=None,
                 nack_write_reg=None, nack_times=None, stretch_s=0.0, hold_sda_low=False,
                 hold_scl_low=False, hold_sda_pulses=0):
        self.address = address
        self.name = name
        self.nack_address = nack_address
        self.nack_write_byte = nack_write_byte
        self.nack_write_reg = nack_write_reg
        self.nack_times = nack_times
        self.stretch_s = stretch_s
        self.hold_sda_low = hold_sda_low
        self.hold_scl_low = hold_scl_low
        self.hold_sda_pulses = hold_sda_pulses
        self.nacks_given = 0
        self.stretches = 0
        self._scl = self._sda = True
        self._state = "idle"
        self._bits = 0
        self._byte = 0
        self._ack = False                # what we drive in the acknowledge slot
        self._rw = 0
        self._tx = 0                     # byte being sent (reads)
        self._drive_sda_low = False
        self._stretch_until = None
        self._falls = 0
        self.now = 0.0

    # ---- outputs ---------------------------------------------------------------------------------------
    @property
    def sda_low(self):
        return self.hold_sda_low or self._falls < self.hold_sda_pulses or self._drive_sda_low

    @property
    def scl_low(self):
        return self.hold_scl_low or self._stretch_until is not None

    def deadline(self):
        """Absolute time (s) at which :meth:`update` must be called again, or None."""
        return self._stretch_until

    # ---- hooks for subclasses ----------------------------------------------------------------------------
    def ready(self):
        """False while the device cannot answer (it then NACKs its address)."""
        return True

    def on_start(self):
        pass

    def on_write(self, index, byte):
        """A byte of a write transaction (index 0 = first byte after the address). Return True to ACK."""
        return True

    def on_read(self, index):
        return 0xFF

    def on_stop(self):
        pass

    # ---- fault helpers -------------------------------------------------------------------------------------
    def _fault_fires(self):
        if self.nack_times is None or self.nacks_given < self.nack_times:
            self.nacks_given += 1
            return True
        return False

    def nack_this_write_byte(self, index, reg):
        if self.nack_write_byte is None or index != self.nack_write_byte:
            return False
        if self.nack_write_reg is not None and reg != self.nack_write_reg:
            return False
        return self._fault_fires()

    # ---- the state machine ---------------------------------------------------------------------------------
    def update(self, scl, sda, now):
        scl, sda = bool(scl), bool(sda)
        self.now = now
        if self._stretch_until is not None and now >= self._stretch_until - 1e-12:
            self._stretch_until = None
        prev_scl, prev_sda = self._scl, self._sda
        self._scl, self._sda = scl, sda
        if scl and prev_scl and sda != prev_sda:
            if not sda:
                self._start()
            else:
                self._stop()
            return
        if scl and not prev_scl:
            self._rise(sda)
        elif prev_scl and not scl:
            self._falls += 1
            self._fall()

    def _start(self):
        if self._state not in ("idle", "ignore"):
            self.on_stop_partial()
        self._state = "addr"
        self._bits = 0
        self._byte = 0
        self._drive_sda_low = False
        self._index = 0
        self.on_start()

    def on_stop_partial(self):
        """A repeated START ended the previous part of a transaction (register pointer stays)."""

    def _stop(self):
        active = self._state != "idle"
        self._state = "idle"
        self._drive_sda_low = False
        if active:
            self.on_stop()

    def _rise(self, sda):
        st = self._state
        if st in ("addr", "write"):
            self._byte = ((self._byte << 1) | sda) & 0xFF
            self._bits += 1
        elif st == "read":
            self._bits += 1
        elif st == "read_ack":
            self._master_acked = not sda

    def _acknowledge(self, ack, state):
        """At the falling SCL edge before the acknowledge bit: ACK (pull SDA low, go to ``state``) or NACK
        (leave SDA released and ignore the rest of the transfer)."""
        if ack:
            self._drive_sda_low = True
            self._state = state
        else:
            self._state = "ignore"

    def _fall(self):
        st = self._state
        if st == "addr" and self._bits == 8:
            self._rw = self._byte & 1
            ok = (self._byte >> 1) == self.address and self.ready()
            if ok and self.nack_address and self._fault_fires():
                ok = False
            self._acknowledge(ok, "addr_ack")
        elif st == "addr_ack":
            self._drive_sda_low = False
            self._stretch()
            if self._rw:
                self._begin_read_byte()
            else:
                self._state, self._bits, self._byte = "write", 0, 0
        elif st == "write" and self._bits == 8:
            ack = self.on_write(self._index, self._byte)
            self._index += 1
            self._acknowledge(ack, "write_ack")
        elif st == "write_ack":
            self._drive_sda_low = False
            self._stretch()
            self._state, self._bits, self._byte = "write", 0, 0
        elif st == "read":
            if self._bits < 8:
                self._drive_sda_low = not (self._tx >> (7 - self._bits)) & 1
            else:
                self._drive_sda_low = False
                self._state = "read_ack"
        elif st == "read_ack":
            if self._master_acked:
                self._begin_read_byte()
            else:
                self._state = "ignore"

    def _begin_read_byte(self):
        self._tx = self.on_read(self._index) & 0xFF
        self._index += 1
        self._bits = 0
        self._state = "read"
        self._drive_sda_low = not (self._tx >> 7) & 1

    def _stretch(self):
        if self.stretch_s > 0:
            self._stretch_until = self.now + self.stretch_s
            self.stretches += 1


class RegisterTarget(I2CTarget):
    """Register-address + data framing: a write transaction is ``reg`` (``reg_bytes``, MSB first) followed by
    ``data_bytes``-wide values (auto-increment by ``data_bytes`` per further value); a read transaction reads
    from the register pointer left by the last write phase. ``writes`` / ``reads`` record every completed
    ``(register, value)`` in order (a value whose bytes were not all acknowledged is not written)."""

    def __init__(self, address, *, reg_bytes, data_bytes, **faults):
        super().__init__(address, **faults)
        self.reg_bytes = reg_bytes
        self.data_bytes = data_bytes
        self.writes = []
        self.reads = []
        self.transactions = 0
        self._ptr = 0
        self._acc = []

    def on_start(self):
        self._acc = []
        self._read_acc = []

    def on_write(self, index, byte):
        if index < self.reg_bytes:
            reg = None
        else:
            reg = self._ptr
        if self.nack_this_write_byte(index, reg):
            return False
        self._acc.append(byte)
        if index == self.reg_bytes - 1:
            self._ptr = int.from_bytes(bytes(self._acc[:self.reg_bytes]), "big")
        elif index >= self.reg_bytes and (index - self.reg_bytes) % self.data_bytes == self.data_bytes - 1:
            value = int.from_bytes(bytes(self._acc[-self.data_bytes:]), "big")
            self.writes.append((self._ptr, value))
            self.write_register(self._ptr, value)
            self._ptr += self.data_bytes
        return True

    def on_read(self, index):
        k = len(self._read_acc) % self.data_bytes
        if k == 0:
            self._read_word = self.read_register(self._ptr) & ((1 << (8 * self.data_bytes)) - 1)
        byte = (self._read_word >> (8 * (self.data_bytes - 1 - k))) & 0xFF
        self._read_acc.append(byte)
        if k == self.data_bytes - 1:
            self.reads.append((self._ptr, self._read_word))
            self._ptr += self.data_bytes
        return byte

    def on_stop(self):
        self.transactions += 1

    def write_register(self, reg, value):
        raise NotImplementedError

    def read_register(self, reg):
        raise NotImplementedError


# --------------------------------------------------------------------------------------------------------
# MT9D112
# --------------------------------------------------------------------------------------------------------

class MT9D112Model(RegisterTarget):
    """The MT9D112's I2C register file (16-bit registers, 16-bit data) at 7-bit address 0x3C.

    The registers, MCU variables and sequencer are :class:`sim.mt9d112_registers.MT9D112Registers` (``self.chip``):
    every write is decoded there and one the model does not understand raises
    :class:`~sim.mt9d112_registers.RegisterError`. :meth:`state` is the resulting sensor state (compared field by
    field with ``golden.part_config.mt9d112_expected``), :meth:`sensor_config` the output the video model
    (``sim/mt9d112.py``) obeys. The device NACKs its address for ``boot_s`` after the start of the simulation
    (reset released at t = 0). ``still_frames``: frames a still capture sends before returning to preview.
    """

    CHIP_VERSION = 0x1580

    def __init__(self, address=I2C_ADDR.MT9D112, *, extclk_hz=CLOCKS.CAM_MCLK_HZ, boot_s=7000 / CLOCKS.CAM_MCLK_HZ,
                 pll_lock_s=1e-3, cmd_busy_reads=2, still_frames=1, **faults):
        super().__init__(address, reg_bytes=2, data_bytes=2, name="mt9d112", **faults)
        from sim.mt9d112_registers import MT9D112Registers
        self.boot_s = boot_s
        self.cmd_busy_reads = cmd_busy_reads
        self.chip = MT9D112Registers(extclk_hz=extclk_hz, pll_lock_s=pll_lock_s, cmd_busy_reads=cmd_busy_reads,
                                     still_frames=still_frames)

    # ---- bus side ----------------------------------------------------------------------------------------
    def ready(self):
        return self.now >= self.boot_s

    def write_register(self, reg, value):
        self.chip.write(reg, value, self.now)

    def read_register(self, reg):
        return self.chip.read(reg, self.now)

    # ---- configuration seen by the sensor model ---------------------------------------------------------
    @property
    def commands_done(self):
        return self.chip.commands_done

    @property
    def streaming(self):
        """Parallel output on (0x301A bits 0x00CC)."""
        return self.chip.parallel_output

    @property
    def pixel_clock_hz(self):
        return self.chip.pclk_hz

    def state(self):
        """The sensor state (``MT9D112Registers.state``)."""
        return self.chip.state()

    def sensor_config(self):
        """The output in force: ``rgb565`` once the active context outputs RGB 5:6:5 without R/B swap, a
        sequencer command has completed and the parallel output is on."""
        st = self.chip.state()
        rgb = st["output_format"] == "rgb565" and not st["rb_swapped"]
        return SensorConfig(width=st["output_width"], height=st["output_height"],
                            rgb565=rgb and st["parallel_output"] and bool(self.chip.commands_done),
                            r_byte_first=st["r_byte_first"])

    def start_frame(self):
        """Called by the video model at each frame boundary; returns the configuration of that frame."""
        self.chip.start_frame()
        return self.sensor_config()

    def problems(self):
        """Writes not understood and inconsistencies found in what was written (empty list = none)."""
        return list(self.chip.errors) + self.chip.consistency()


# --------------------------------------------------------------------------------------------------------
# CH7301C
# --------------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class DviConfig:
    dvi_on: bool            # PM 0x49: DVIP and DVIL set, FPD clear
    idf: int                # input data format (0 = 12-bit multiplexed RGB 8:8:8 on both clock edges)
    hsync_positive: bool    # IDF bit 3 (HSP)
    vsync_positive: bool    # IDF bit 4 (VSP)
    pll_range: str          # "high" (> 65 MHz), "low" (<= 65 MHz) or "unset"


class CH7301CModel(RegisterTarget):
    """The CH7301C's register file (8-bit registers) at 7-bit address 0x76 (AS strap; 0x75 is the other
    choice): :class:`sim.ch7301c_registers.CH7301CRegisters` (``self.chip``) decodes every write (one it does not
    understand raises ``RegisterError``). Version ID 0x4A / device ID 0x4B read ``version_id`` / ``device_id``
    (0x95 / 0x17 by default; another value models a part the table does not expect). :meth:`state` is the
    transmitter's mode, :meth:`dvi_config` the summary the older tests use."""

    def __init__(self, address=I2C_ADDR.CH7301C, *, version_id=0x95, device_id=0x17, **faults):
        super().__init__(address, reg_bytes=1, data_bytes=1, name="ch7301c", **faults)
        from sim.ch7301c_registers import CH7301CRegisters
        self.chip = CH7301CRegisters(version_id=version_id, device_id=device_id)

    def write_register(self, reg, value):
        self.chip.write(reg & 0xFF, value)

    def read_register(self, reg):
        return self.chip.read(reg & 0xFF)

    def state(self):
        return self.chip.state()

    def problems(self):
        return list(self.chip.errors)

    def dvi_config(self):
        st = self.chip.state()
        rng = {"> 65 MHz": "high", "<= 65 MHz": "low"}.get(st["dvi_pll"], "unset")
        return DviConfig(dvi_on=st["dvi_output"], idf=self.chip.regs[0x1F] & 0x7,
                         hsync_positive=st["hsync_positive"], vsync_positive=st["vsync_positive"], pll_range=rng)


# --------------------------------------------------------------------------------------------------------
# Bus monitor
# --------------------------------------------------------------------------------------------------------

#: NXP UM10204 Rev. 7 (2021), table 10, standard mode, in microseconds: minimum unless noted.
STANDARD_MODE_LIMITS_US = {
    "tHD;STA": 4.0, "tLOW": 4.7, "tHIGH": 4.0, "tSU;STA": 4.7, "tHD;DAT": 0.0,
    "tSU;DAT": 0.25, "tSU;STO": 4.0, "tBUF": 4.7, "tSCL": 10.0,      # tSCL = 1 / fSCL(max 100 kHz)
}
#: Maximum SDA change time after SCL falls (data valid time tVD;DAT), standard mode.
STANDARD_MODE_TVD_DAT_MAX_US = 3.45


class I2CBusMonitor:
    """Watches the two resolved lines. ``observe(t_s, scl, sda)`` on every change. Keeps the smallest and largest
    value of each UM10204 interval (``minimum``/``maximum``, seconds), the largest SDA hold (``max_hold``),
    decoded ``transactions`` (lists of ``(byte, acked)`` with ``"Sr"`` markers), ``last_edge``, ``edges``,
    ``scl_rises`` and protocol errors. The lines are assumed high (idle) before the first call."""

    def __init__(self):
        self.minimum = {}
        self.maximum = {}
        self.count = {}
        self.scl_rises = 0
        self.max_hold = 0.0
        self.transactions = []
        self.protocol_errors = []
        self.last_edge = None
        self.edges = 0
        self._scl = self._sda = True
        self._t_scl_rise = self._t_scl_fall = self._t_start = self._t_stop = None
        self._t_sda_low_change = None
        self._prev_rise = None
        self._in_transfer = False
        self._bits = []
        self._pending_bit = None
        self._cur = None

    def _note(self, name, value):
        self.count[name] = self.count.get(name, 0) + 1
        if name not in self.minimum or value < self.minimum[name]:
            self.minimum[name] = value
        if name not in self.maximum or value > self.maximum[name]:
            self.maximum[name] = value

    def observe(self, t, scl, sda):
        scl, sda = bool(scl), bool(sda)
        if scl == self._scl and sda == self._sda:
            return
        self.edges += 1
        self.last_edge = t
        if scl != self._scl and sda != self._sda:
            self.protocol_errors.append((t, "SCL and SDA changed at the same instant"))
        if sda != self._sda:
            if self._scl and scl:                          # SDA changes while SCL high: START or STOP
                self._pending_bit = None
                if not sda:
                    if self._in_transfer:
                        if self._t_scl_rise is not None:
                            self._note("tSU;STA", t - self._t_scl_rise)
                        if self._bits:
                            self.protocol_errors.append((t, "repeated START inside a byte"))
                        self._cur.append("Sr")
                    else:
                        if self._t_stop is not None:
                            self._note("tBUF", t - self._t_stop)
                        self._cur = []
                        self.transactions.append(self._cur)
                    self._in_transfer = True
                    self._t_start = t
                    self._bits = []
                else:
                    if self._t_scl_rise is not None:
                        self._note("tSU;STO", t - self._t_scl_rise)
                    if self._bits:
                        self.protocol_errors.append((t, "STOP inside a byte"))
                    self._in_transfer = False
                    self._t_stop = t
                    self._bits = []
            elif not self._scl:                            # data change while SCL low
                if self._t_scl_fall is not None:
                    hold = t - self._t_scl_fall
                    self._note("tHD;DAT", hold)
                    self.max_hold = max(self.max_hold, hold)
                self._t_sda_low_change = t
            self._sda = sda
        if scl != self._scl:
            if scl:
                self.scl_rises += 1
                if self._t_scl_fall is not None:
                    self._note("tLOW", t - self._t_scl_fall)
                if self._t_sda_low_change is not None:
                    self._note("tSU;DAT", t - self._t_sda_low_change)
                    self._t_sda_low_change = None
                if self._prev_rise is not None and self._in_transfer:
                    self._note("tSCL", t - self._prev_rise)
                self._prev_rise = t
                self._t_scl_rise = t
                self._pending_bit = sda if self._in_transfer else None
            else:
                if self._pending_bit is not None and self._in_transfer:
                    self._bits.append(self._pending_bit)
                    if len(self._bits) == 9:
                        byte = int("".join("1" if b else "0" for b in self._bits[:8]), 2)
                        self._cur.append((byte, not self._bits[8]))
                        self._bits = []
                self._pending_bit = None
                if self._t_scl_rise is not None:
                    self._note("tHIGH", t - self._t_scl_rise)
                if self._t_start is not None and self._in_transfer:
                    self._note("tHD;STA", t - self._t_start)
                    self._t_start = None
                self._t_scl_fall = t
                self._t_sda_low_change = None
            self._scl = scl

    def violations(self, limits_us=None, tvd_max_us=STANDARD_MODE_TVD_DAT_MAX_US, require_all=True):
        """``[(name, measured_us, limit_us)]`` for every interval below its minimum (and tHD;DAT above the
        data-valid maximum); empty when the bus met the standard-mode timing. With ``require_all`` intervals
        never observed are reported as missing (measured None) so a test cannot pass vacuously."""
        limits = STANDARD_MODE_LIMITS_US if limits_us is None else limits_us
        out = []
        for name, lim in limits.items():
            if name not in self.minimum:
                if require_all:
                    out.append((name, None, lim))
            elif self.minimum[name] * 1e6 < lim - 1e-9:
                out.append((name, self.minimum[name] * 1e6, lim))
        if self.max_hold * 1e6 > tvd_max_us + 1e-9:
            out.append(("tVD;DAT(max)", self.max_hold * 1e6, tvd_max_us))
        return out
