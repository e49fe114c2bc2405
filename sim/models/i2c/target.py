"""I2C targets on an open-drain bus, as pure-Python event-driven state machines (no simulator imports).

* :class:`I2CTarget`: the bit-level target. ``update(scl, sda, now)`` is called with the resolved bus levels
  whenever they may have changed (and when :meth:`I2CTarget.deadline` passes); the target then reports what it
  pulls low in ``scl_low`` / ``sda_low``. Fault injection: NACK its address, NACK a byte of a write, stretch SCL
  after every acknowledged byte, hold SDA or SCL low (for ever, or SDA for a number of SCL pulses, like a target
  stuck in the middle of a read).
* :class:`RegisterTarget`: register address + data framing on top; records every completed write and read.

The parts' register files build on :class:`RegisterTarget`: :class:`sim.models.mt9d112.target.MT9D112Model`,
:class:`sim.models.ch7301c.target.CH7301CModel`. Model assumptions where no public datasheet text was available are
listed in docs/i2c.md.
"""

__all__ = ["I2CTarget", "RegisterTarget"]


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
