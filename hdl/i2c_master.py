"""I2C master: byte-level START / WRITE / READ / STOP commands on open-drain SCL and SDA.

Pins: ``i2c`` (:data:`I2CSignature`), ``scl`` and ``sda`` each an open-drain pin (:data:`OpenDrainSignature`):
``o`` is always 0 and ``oe`` = 1 pulls the line low; the board top level connects them to an ``amaranth.lib.io``
buffer with a pull-up. ``i`` is asynchronous and passes through a 2-flop synchroniser (``amaranth.lib.cdc``).

Clock domain: ``sync`` (100 MHz on the board, ``clk_hz``). Bus rate ``bus_hz`` (100 kHz default); every bus
interval is derived from ``clk_hz`` and the I2C specification's minimum for that speed class (NXP UM10204
Rev. 7, table 10: standard mode <= 100 kHz, fast mode <= 400 kHz, fast-mode plus <= 1 MHz), see
:class:`I2CTiming`. At 100 MHz / 100 kHz: SCL low 5.00 us, high >= 5.00 us, SDA changes 1.25 us after SCL
falls, START/STOP setup and hold >= 5.00 us, bus free >= 5.00 us.

Command interface: when ``ready`` is high, ``cmd_valid`` with ``cmd`` (and ``wdata`` for WRITE, ``rd_ack`` for
READ: 1 = acknowledge the byte, 0 = NACK the last byte) starts a command. When it ends, ``done`` pulses for
one cycle; ``nack`` (WRITE: the target did not acknowledge), ``rdata`` (READ), ``arb_lost`` and
``timed_out`` describe the result and stay valid until the next command.

* START: from an idle bus, waits until SCL and SDA have been high for the bus-free time, then SDA falls while
  SCL is high. While a transfer is open (``bus_active``) it makes a repeated START.
* WRITE / READ: 8 data bits MSB first plus the acknowledge bit. SCL is held low between commands; SDA
  changes ``hold`` cycles after SCL fell (or at once if the next command came later than that) and SCL is
  released when it has been low for the full low time and SDA has been stable for tSU;DAT.
* STOP: SDA rises while SCL is high; ``bus_active`` falls.

Clock stretching: after releasing SCL the master waits for SCL to read high and counts the high time from
there. Stuck bus: if SCL stays low (or the bus is not free before a START) for ``timeout_us`` the command ends
with ``timed_out`` and both lines released. If SDA alone is held low before a START, the master first tries
the UM10204 bus clear (up to nine SCL pulses, then a STOP). Arbitration / bus error: if SDA reads low while
the master releases it for a 1 data bit, the repeated-START setup or the STOP, the command ends with
``arb_lost`` and both lines released.

Several buses (``buses`` > 1, broadcast): the master drives the same SCL and SDA on every bus at once (the
same ``oe`` to each bus's pins), so every target sees each command at the same clock. Each bus's inputs pass their
own synchroniser and are combined so that every bus's answer counts: SCL reads high only when it is high on every
bus (a stretch on any bus holds all of them: the master waits for the last to let go); for the bus-free check,
the bus clear, arbitration and the repeated-START / STOP checks SDA reads high only when it is high on every bus (a
low SDA on any bus is that bus's error); an acknowledge counts only when SDA is low on every bus (``nack`` when any
bus left it high, ``nack_buses`` says which); a READ gives ``rdata`` (the bits every bus read as 1, the AND) and
``rdata_any`` (the bits some bus read as 1, the OR): bit ``i`` read ``v`` on every bus exactly when
``rdata[i] == rdata_any[i] == v``. ``enable`` (all buses unless driven) selects the buses: the master drives only
those and reads only those (a bus left out is never pulled low and its inputs count for nothing); change it only
between transfers.

Latency: a command takes its bus time (9 bit times for a byte) plus 2-3 cycles of input synchronisation per
SCL rising edge; ``ready`` returns the cycle after ``done``.
"""

from dataclasses import dataclass

from amaranth import C, Cat, Module, Mux, Signal
from amaranth.lib import enum, wiring
from amaranth.lib.cdc import FFSynchronizer
from amaranth.lib.wiring import In, Out

from spec.board import CLOCKS

__all__ = ["OpenDrainSignature", "I2CSignature", "Cmd", "I2CTiming", "I2CMaster", "master_timing", "master_signature",
           "bus_pins"]

#: One open-drain pin as its driver sees it: ``oe`` = 1 with ``o`` = 0 pulls the line low, ``oe`` = 0 releases it
#: (a pull-up makes it high); ``i`` is the line's level, high when idle. A driver must never set ``oe`` with
#: ``o`` = 1 (that would drive the line high against other devices).
OpenDrainSignature = wiring.Signature({"o": Out(1), "oe": Out(1), "i": In(1, init=1)})

#: An I2C bus as a master (or anything driving the bus) sees it: two open-drain pins.
I2CSignature = wiring.Signature({"scl": Out(OpenDrainSignature), "sda": Out(OpenDrainSignature)})


class Cmd(enum.Enum, shape=2):
    START = 0
    WRITE = 1
    READ = 2
    STOP = 3


#: Minimum bus intervals in ns per speed class (NXP UM10204 Rev. 7, 2021, table 10); ``t_vd_dat`` is the
#: maximum data-valid time (SCL low to SDA valid), the bound on the master's SDA change after SCL falls.
I2C_SPEC_NS = {
    100_000: dict(t_low=4700, t_high=4000, t_su_sta=4700, t_hd_sta=4000, t_su_dat=250, t_vd_dat=3450,
                  t_su_sto=4000, t_buf=4700),
    400_000: dict(t_low=1300, t_high=600, t_su_sta=600, t_hd_sta=600, t_su_dat=100, t_vd_dat=900,
                  t_su_sto=600, t_buf=1300),
    1_000_000: dict(t_low=500, t_high=260, t_su_sta=260, t_hd_sta=260, t_su_dat=50, t_vd_dat=450,
                    t_su_sto=260, t_buf=500),
}


def _cycles(ns, clk_hz):
    return -(-ns * clk_hz // 1_000_000_000)   # ceil


@dataclass(frozen=True)
class I2CTiming:
    """Bus intervals in ``sync`` cycles for ``clk_hz`` and ``bus_hz``: the larger of half the bit period and
    the specification's minimum, rounded up. Raises ``ValueError`` when the clock is too slow to meet them."""
    clk_hz: int
    bus_hz: int

    def __post_init__(self):
        if self.bus_hz <= 0 or self.clk_hz <= 0:
            raise ValueError("clock and bus rates must be positive")
        classes = [hz for hz in sorted(I2C_SPEC_NS) if self.bus_hz <= hz]
        if not classes:
            raise ValueError(f"bus rate {self.bus_hz} Hz is above fast-mode plus (1 MHz)")
        spec = I2C_SPEC_NS[classes[0]]
        c = lambda ns: _cycles(ns, self.clk_hz)   # noqa: E731
        period = -(-self.clk_hz // self.bus_hz)
        low = max(c(spec["t_low"]), -(-period // 2))
        high = max(c(spec["t_high"]), period - low)
        hold = max(1, c(300), low // 4)
        values = dict(
            speed_class=classes[0], low=low, high=high, hold=hold,
            su_sta=max(c(spec["t_su_sta"]), high), hd_sta=max(c(spec["t_hd_sta"]), high),
            su_sto=max(c(spec["t_su_sto"]), high), buf=max(c(spec["t_buf"]), low),
            su_dat=max(1, c(spec["t_su_dat"])),
        )
        for k, v in values.items():
            object.__setattr__(self, k, v)
        if hold >= c(spec["t_vd_dat"]) or low - hold < self.su_dat:
            raise ValueError(f"a {self.clk_hz} Hz clock is too slow for I2C at {self.bus_hz} Hz "
                             "(cannot place SDA changes within the SCL low time)")

    def ns(self, cycles):
        return cycles * 1e9 / self.clk_hz


def bus_pins(i2c, buses):
    """The ``I2CSignature`` interfaces of an ``i2c`` member that is one bus (``buses`` = 1) or an array of them."""
    return [i2c] if buses == 1 else [i2c[k] for k in range(buses)]


def master_signature(buses=1):
    """The signature of an :class:`I2CMaster` driving ``buses`` buses (see its Attributes)."""
    members = {
        "cmd": In(Cmd), "cmd_valid": In(1), "wdata": In(8), "rd_ack": In(1),
        "ready": Out(1), "done": Out(1), "nack": Out(1), "rdata": Out(8), "arb_lost": Out(1), "timed_out": Out(1),
        "bus_active": Out(1),
        "i2c": Out(I2CSignature) if buses == 1 else Out(I2CSignature).array(buses),
    }
    if buses > 1:
        members.update({"rdata_any": Out(8), "nack_buses": Out(buses), "enable": In(buses, init=(1 << buses) - 1)})
    return wiring.Signature(members)


def master_timing(clk_hz, bus_hz, timeout_us):
    """``(I2CTiming(clk_hz, bus_hz), time-out in cycles)`` of an :class:`I2CMaster`; ``ValueError`` for a clock too
    slow for the bus rate, a bus rate above 1 MHz, a time-out shorter than the bus-free time."""
    timing = I2CTiming(clk_hz, bus_hz)
    timeout = max(1, -(-timeout_us * clk_hz // 1_000_000))
    if timeout <= timing.buf + 4:
        raise ValueError("timeout_us must be longer than the bus-free time")
    return timing, timeout


class I2CMaster(wiring.Component):
    """Byte-level I2C master on open-drain pins; see the module docstring for the commands, the bus timing,
    clock stretching, bus clear, time-outs and arbitration.

    Parameters
    ----------
    clk_hz : int
        The ``sync`` clock.
    bus_hz : int
        The bus rate (the speed class of :class:`I2CTiming`).
    timeout_us : int
        Stuck-bus time-out.
    buses : int
        The buses the master broadcasts to (see the module docstring).

    Attributes
    ----------
    cmd, cmd_valid, wdata, rd_ack : ``In``
        A command, taken while ``ready``.
    ready, done, nack, rdata, arb_lost, timed_out, bus_active : ``Out``
        ``done`` pulses when a command ends; ``nack``, ``rdata``, ``arb_lost``, ``timed_out`` hold its result until
        the next command.
    rdata_any : ``Out(8)``, nack_buses : ``Out(buses)``, enable : ``In(buses)``
        With ``buses`` > 1 only: the OR of the buses' read bits; the buses that did not acknowledge a WRITE; the
        buses in use (all unless driven).
    i2c : ``Out(I2CSignature)``, with ``buses`` > 1 ``Out(I2CSignature).array(buses)``

    Clock domain ``sync``. Latency: a command takes its bus time (for a byte, 9 SCL periods) plus the 2-flop input
    synchroniser; ``done`` pulses in the cycle after the last bus interval ends.

    Raises
    ------
    ValueError
        A clock too slow for the bus rate, a bus rate above 1 MHz, a time-out shorter than the bus-free time,
        ``buses`` < 1.
    """

    def __init__(self, *, clk_hz=CLOCKS.SYS_HZ, bus_hz=CLOCKS.I2C_HZ, timeout_us=25_000, buses=1):
        self.timing, self.timeout = master_timing(clk_hz, bus_hz, timeout_us)
        if buses < 1:
            raise ValueError("buses must be >= 1")
        self.buses = buses
        super().__init__(master_signature(buses))

    def elaborate(self, platform):
        m = Module()
        fsm_states = _States(self, m)
        with m.FSM() as fsm:
            fsm_states.idle()
            fsm_states.start()
            fsm_states.repeated_start()
            fsm_states.bit()
            fsm_states.stop()
            fsm_states.bus_clear()
            fsm_states.done()
        # Outside the FSM so they are plain continuous assignments in the exported Verilog (an `always @*`
        # block is not run at time 0 by Icarus in its -g2012 mode until one of its inputs changes).
        m.d.comb += [self.ready.eq(fsm.ongoing("IDLE")), self.done.eq(fsm.ongoing("DONE"))]
        return m


class _States:
    """The master's registers and the states of its FSM, a group of states per method (emitted inside the
    ``m.FSM()`` block of :meth:`I2CMaster.elaborate`, in this order)."""

    def __init__(self, master, m):
        self.master, self.m, self.t = master, m, master.timing
        t, n = self.t, master.buses
        self.scl = Signal(init=1)                    # high on every bus
        self.sda = Signal(init=1)                    # high on every bus
        self.scl_low = Signal()
        self.sda_low = Signal()
        pins = bus_pins(master.i2c, n)
        enable = [1] * n if n == 1 else list(master.enable)
        for pin, en in zip(pins, enable):
            m.d.comb += [pin.scl.o.eq(0), pin.sda.o.eq(0), pin.scl.oe.eq(self.scl_low & en),
                         pin.sda.oe.eq(self.sda_low & en)]
        if n == 1:
            m.submodules.scl_sync = FFSynchronizer(pins[0].scl.i, self.scl, init=1)
            m.submodules.sda_sync = FFSynchronizer(pins[0].sda.i, self.sda, init=1)
            self.sda_any = self.sda_bus = self.sda         # high on some bus; per bus
        else:
            scl, sda = [], []
            for k, pin in enumerate(pins):
                scl.append(Signal(init=1, name=f"scl_{k}"))
                sda.append(Signal(init=1, name=f"sda_{k}"))
                m.submodules[f"scl_sync_{k}"] = FFSynchronizer(pin.scl.i, scl[-1], init=1)
                m.submodules[f"sda_sync_{k}"] = FFSynchronizer(pin.sda.i, sda[-1], init=1)
            self.sda_any = Signal(init=1)
            self.sda_bus = Cat(*sda) & master.enable            # a bus left out reads as released
            m.d.comb += [self.scl.eq((Cat(*scl) | ~master.enable).all()),
                         self.sda.eq((Cat(*sda) | ~master.enable).all()), self.sda_any.eq(self.sda_bus.any())]
        longest = max(t.low, t.high, t.hold, t.su_sta, t.hd_sta, t.su_sto, t.buf)
        self.timer = Signal(range(longest + 2))
        self.low_cnt = Signal(range(t.low + 1))      # cycles since the master pulled SCL low (saturating)
        with m.If(~self.scl_low):
            m.d.sync += self.low_cnt.eq(0)
        with m.Elif(self.low_cnt < t.low):
            m.d.sync += self.low_cnt.eq(self.low_cnt + 1)
        self.wait = Signal(range(master.timeout + 2))   # stuck-bus timeout counter
        self.shift = Signal(8)
        self.shift_any = Signal(8) if n > 1 else self.shift
        self.bit_count = Signal(range(9), name="bit")
        self.reading = Signal()
        self.ack_level = Signal()                    # READ: 1 = pull SDA low in the acknowledge slot
        self.pulses = Signal(range(10))              # bus-clear pulses
        self.clearing = Signal()                     # STOP sequence belongs to a bus clear
        self.cleared = Signal()                      # bus clear already tried for this START
        self.res_nack = Signal(n)                    # per bus: SDA high in the acknowledge slot of a WRITE
        self.res_arb = Signal()
        self.res_timeout = Signal()
        m.d.comb += [
            master.nack.eq(self.res_nack.any()), master.arb_lost.eq(self.res_arb),
            master.timed_out.eq(self.res_timeout), master.rdata.eq(self.shift),
        ]
        if n > 1:
            m.d.comb += [master.rdata_any.eq(self.shift_any), master.nack_buses.eq(self.res_nack)]

    @staticmethod
    def reached(counter, n):
        """True in the n-th cycle of a count from 0 (no constant comparison when n <= 1)."""
        return counter >= n - 1 if n > 1 else C(1, 1)

    def fail(self, kind):
        self.m.d.sync += [self.scl_low.eq(0), self.sda_low.eq(0), self.master.bus_active.eq(0), kind.eq(1)]
        self.m.next = "DONE"

    def release_scl(self, prefix, *, then):
        """States ``<prefix>_SETUP`` (SCL low for ``low`` and SDA set up for ``su_dat``, then release SCL) and
        ``<prefix>_WAIT_HIGH`` (wait for SCL to read high -- a target may stretch it -- then go to ``then``; time
        out after ``timeout`` cycles): the same for a repeated START, a bit and a STOP."""
        m, t, timer, wait = self.m, self.t, self.timer, self.wait
        with m.State(f"{prefix}_SETUP"):
            m.d.sync += timer.eq(timer + 1)
            with m.If((self.reached(self.low_cnt, t.low)) & (self.reached(timer, t.su_dat))):
                m.d.sync += [self.scl_low.eq(0), timer.eq(0), wait.eq(0)]
                m.next = f"{prefix}_WAIT_HIGH"
        with m.State(f"{prefix}_WAIT_HIGH"):
            m.d.sync += wait.eq(wait + 1)
            with m.If(self.scl):
                m.next = then
            with m.Elif(wait >= self.master.timeout):
                self.fail(self.res_timeout)

    def hold_then_release(self, prefix, sda_low, *, then):
        """State ``<prefix>_HOLD`` (``hold`` cycles after SCL fell, set SDA to ``sda_low``), then
        :meth:`release_scl`: the first half of a repeated START and of a STOP."""
        m = self.m
        with m.State(f"{prefix}_HOLD"):
            with m.If(self.reached(self.low_cnt, self.t.hold)):
                m.d.sync += [self.sda_low.eq(sda_low), self.timer.eq(0)]
                m.next = f"{prefix}_SETUP"
        self.release_scl(prefix, then=then)

    def idle(self):
        m, master = self.m, self.master
        with m.State("IDLE"):
            with m.If(master.cmd_valid):
                m.d.sync += [self.res_nack.eq(0), self.res_arb.eq(0), self.res_timeout.eq(0), self.timer.eq(0),
                             self.wait.eq(0)]
                with m.Switch(master.cmd):
                    with m.Case(Cmd.START):
                        m.d.sync += self.cleared.eq(0)
                        with m.If(master.bus_active):
                            m.next = "RS_HOLD"
                        with m.Else():
                            m.next = "WAIT_IDLE"
                    with m.Case(Cmd.WRITE):
                        m.d.sync += [self.shift.eq(master.wdata), self.reading.eq(0), self.bit_count.eq(0)]
                        m.next = "BIT_HOLD"
                    with m.Case(Cmd.READ):
                        m.d.sync += [self.reading.eq(1), self.ack_level.eq(master.rd_ack), self.bit_count.eq(0)]
                        m.next = "BIT_HOLD"
                    with m.Case(Cmd.STOP):
                        m.d.sync += self.clearing.eq(0)
                        with m.If(master.bus_active):
                            m.next = "STOP_HOLD"
                        with m.Else():
                            m.next = "DONE"

    def start(self):
        """START from an idle bus."""
        m, t, timer, wait, scl, sda = self.m, self.t, self.timer, self.wait, self.scl, self.sda
        with m.State("WAIT_IDLE"):
            m.d.sync += wait.eq(wait + 1)
            with m.If(scl & sda):
                m.d.sync += timer.eq(timer + 1)
                with m.If(self.reached(timer, t.buf)):
                    m.d.sync += [self.sda_low.eq(1), timer.eq(0)]
                    m.next = "START_HD"
            with m.Else():
                m.d.sync += timer.eq(0)
            with m.If(wait >= self.master.timeout):
                with m.If(scl & ~sda & ~self.cleared):
                    m.d.sync += [self.cleared.eq(1), self.pulses.eq(0), timer.eq(0), self.scl_low.eq(1)]
                    m.next = "CLR_LOW"
                with m.Else():
                    self.fail(self.res_timeout)
        with m.State("START_HD"):                         # SDA low, SCL high: hold the START
            m.d.sync += timer.eq(timer + 1)
            with m.If(self.reached(timer, t.hd_sta)):
                m.d.sync += [self.scl_low.eq(1), self.master.bus_active.eq(1)]
                m.next = "DONE"

    def repeated_start(self):
        """Repeated START (SCL is low when we get here)."""
        m, t, timer = self.m, self.t, self.timer
        self.hold_then_release("RS", 0, then="RS_SU")
        with m.State("RS_SU"):
            m.d.sync += timer.eq(timer + 1)
            with m.If(self.reached(timer, t.su_sta)):
                with m.If(~self.sda | ~self.scl):
                    self.fail(self.res_arb)
                with m.Else():
                    m.d.sync += [self.sda_low.eq(1), timer.eq(0)]
                    m.next = "START_HD"

    def bit(self):
        """One bit: SDA changes ``hold`` after SCL fell, SCL released at ``low``, sampled at the end of high."""
        m, t, timer, bit, reading, sda = self.m, self.t, self.timer, self.bit_count, self.reading, self.sda
        with m.State("BIT_HOLD"):
            with m.If(self.reached(self.low_cnt, t.hold)):
                with m.If(bit == 8):
                    m.d.sync += self.sda_low.eq(reading & self.ack_level)
                with m.Else():
                    m.d.sync += self.sda_low.eq(~reading & ~self.shift[7])
                m.d.sync += timer.eq(0)
                m.next = "BIT_SETUP"
        self.release_scl("BIT", then="BIT_HIGH")
        with m.State("BIT_HIGH"):
            m.d.sync += timer.eq(timer + 1)
            with m.If(self.reached(timer, t.high)):
                m.d.sync += timer.eq(0)
                with m.If(bit == 8):                           # an acknowledge needs SDA low on every bus
                    m.d.sync += [self.res_nack.eq(Mux(reading, 0, self.sda_bus)), self.scl_low.eq(1)]
                    m.next = "DONE"
                with m.Elif(~reading & ~self.sda_low & ~sda):
                    self.fail(self.res_arb)                    # we sent a 1 but SDA is low
                with m.Else():
                    m.d.sync += [self.shift.eq((self.shift << 1) | (reading & sda)), bit.eq(bit + 1),
                                 self.scl_low.eq(1)]
                    if self.shift_any is not self.shift:
                        m.d.sync += self.shift_any.eq((self.shift_any << 1) | (reading & self.sda_any))
                    m.next = "BIT_HOLD"

    def stop(self):
        """STOP (SCL is low when we get here)."""
        m, t, timer, master = self.m, self.t, self.timer, self.master
        self.hold_then_release("STOP", 1, then="STOP_SU")
        with m.State("STOP_SU"):
            m.d.sync += timer.eq(timer + 1)
            with m.If(self.reached(timer, t.su_sto)):
                m.d.sync += [self.sda_low.eq(0), timer.eq(0)]
                m.next = "STOP_CHECK"
        with m.State("STOP_CHECK"):                       # let the release pass the synchroniser
            m.d.sync += timer.eq(timer + 1)
            with m.If(timer >= 3):
                with m.If(~self.sda):
                    self.fail(self.res_arb)
                with m.Elif(self.clearing):
                    m.d.sync += [master.bus_active.eq(0), self.clearing.eq(0), timer.eq(0), self.wait.eq(0)]
                    m.next = "WAIT_IDLE"
                with m.Else():
                    m.d.sync += master.bus_active.eq(0)
                    m.next = "DONE"

    def bus_clear(self):
        """Bus clear (UM10204 3.1.16): SCL pulses until the target releases SDA."""
        m, t, timer, wait = self.m, self.t, self.timer, self.wait
        with m.State("CLR_LOW"):
            with m.If(self.reached(self.low_cnt, t.low)):
                m.d.sync += [self.scl_low.eq(0), timer.eq(0), wait.eq(0)]
                m.next = "CLR_WAIT_HIGH"
        with m.State("CLR_WAIT_HIGH"):
            m.d.sync += wait.eq(wait + 1)
            with m.If(self.scl):
                m.next = "CLR_HIGH"
            with m.Elif(wait >= self.master.timeout):
                self.fail(self.res_timeout)
        with m.State("CLR_HIGH"):
            m.d.sync += timer.eq(timer + 1)
            with m.If(self.reached(timer, t.high)):
                m.d.sync += [timer.eq(0), self.scl_low.eq(1), self.pulses.eq(self.pulses + 1)]
                with m.If(self.sda):
                    m.d.sync += [self.clearing.eq(1), self.master.bus_active.eq(1)]
                    m.next = "STOP_HOLD"
                with m.Elif(self.pulses >= 8):
                    self.fail(self.res_timeout)
                with m.Else():
                    m.next = "CLR_LOW"

    def done(self):
        m = self.m
        with m.State("DONE"):
            m.next = "IDLE"
