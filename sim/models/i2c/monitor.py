"""The I2C bus monitor: :class:`I2CBusMonitor` decodes START/STOP/bytes/ACKs from the two resolved lines and
measures every interval of UM10204 table 10 (its own copy of the standard's numbers, independent of the RTL's)."""

__all__ = ["I2CBusMonitor", "STANDARD_MODE_LIMITS_US", "STANDARD_MODE_TVD_DAT_MAX_US"]


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
