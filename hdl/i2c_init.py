"""InitSequencer: plays an I2C initialisation table from a ROM through an :class:`I2CMaster`.

A sequencer plays one table on one bus, or the same table on several buses at once (``buses`` > 1): each VmodCAM
camera has its own bus (both MT9D112 answer at the same address) and one sequencer with a broadcasting
:class:`~hdl.i2c_master.I2CMaster` plays the MT9D112 table on both, every transaction on both buses at the same
clock; the CH7301C has the Genesys's bus. A sequencer can also play several tables in turn, each on its own buses
(phases, :class:`Phase`): the system's one sequencer plays the CH7301C table on its bus, then the MT9D112 table on
both camera buses. The table (``hdl/init_tables.py``) is packed into an ``amaranth.lib.memory.Memory``
ROM (synchronous read), one word per entry. Out of reset the sequencer runs the table once:

* ``Write``: ``S addr+W reg.. data.. P`` (most significant byte first).
* ``Wait``: counts the given time.
* ``Poll``: ``S addr+W reg.. Sr addr+R data.. P`` until ``data & mask == value``; ``attempts`` reads at most,
  ``interval_us`` apart. A one-attempt poll is an ID check that stops the table on a mismatch.
* ``Check``: one read as for a poll; ``data & mask != value`` sets the sticky ``mismatch`` status and the table
  goes on (identification bytes that are shown, not enforced).
* ``Barrier``: ``barrier`` is high while the sequencer holds there; it goes on at the clock ``release`` is high
  (the parent releases the sequencers that share the barrier together once all of them hold).

Several buses: every entry must succeed on every bus. A write (and the address and register bytes of a read)
needs an acknowledge from every bus; a NACK from any bus is a NACK (the transaction is repeated on all buses: a
register write twice is harmless). A read compares each bus's value: it keeps the AND and the OR of the buses'
bits (the master's ``rdata`` and ``rdata_any``) and matches when ``AND & mask == value`` and
``OR & mask == value``, which holds exactly when every bus read ``data & mask == value`` (a bit of ``value``
that is 1 is 1 on every bus when the AND has it, a 0 is 0 on every bus when the OR has it). So a one-attempt
``Poll`` (the MT9D112's chip version) passes only when every sensor has that version, a ``Poll`` until a value
(the sequencer command reads 0) goes on only once every sensor reads it, and a ``Check`` shows a mismatch when any
bus read another value. A clock stretch on any bus holds all of them; a stuck line or a lost arbitration on any
bus is the error of all. ``nacked`` says which buses did not acknowledge the last NACKed byte (so, with a NACK
``error_code``, which bus failed).

Phases: one ROM holds every phase's entries (each word as wide as the widest device's register and data); while
a phase runs the master's ``enable`` holds its buses and the step programs are its device's. Each phase has its
own status (``status.<name>``); an error ends that phase only (its status as below) and the next phase starts.

Faults: a NACK (address or data byte) or a lost arbitration ends the transaction with a STOP; the sequencer
waits ``retry_delay_us`` and repeats the whole transaction, at most ``retries`` more times, then stops with
``error``. A bus stuck low (the master's timeout) stops at once. A poll that never matches stops with
``error``. After an error the sequencer leaves the bus idle for good (with phases: the error's phase's buses; it
goes on with the next phase): it never goes on to the next entry and never raises ``done`` (only a reset restarts
it).

Outputs: ``i2c`` (:data:`hdl.i2c_master.I2CSignature`, an array of ``buses`` of them when ``buses`` > 1,
connected to the master's pins) and ``status``
(:class:`InitStatusSignature`, all ``sync``, registered): ``busy`` until the table ends or fails; ``done``
(sticky) once every entry has completed; ``error`` (sticky) with ``error_code`` (:class:`ErrorCode`) and
``entry`` = index of the failing entry (while running: the current entry; after ``done``: the table length);
``mismatch`` (sticky) once a ``Check`` read another value. ``done`` and ``error`` are never high together.

Clock domain: ``sync`` (``clk_hz``, 100 MHz on the board). Latency: the bus time of the table plus its waits;
about 0.46 ms per MT9D112 write and 0.30 ms per CH7301C write at 100 kHz.
"""

from dataclasses import dataclass

from amaranth import Module, Mux, Signal, unsigned
from amaranth.lib import data, enum, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from hdl.i2c_master import Cmd, I2CMaster, I2CSignature, bus_pins, master_timing
from hdl.init_tables import Barrier, Check, InitTable, Wait, Write
from spec.board import CLOCKS
from hdl.signature import ParametricSignature

__all__ = ["ErrorCode", "InitStatusSignature", "InitSequencer", "Phase", "check_parameters"]


class ErrorCode(enum.Enum, shape=3):
    NONE = 0
    NACK_ADDR = 1     # the device address was not acknowledged (after all retries)
    NACK_DATA = 2     # a register-address or data byte was not acknowledged (after all retries)
    STUCK = 3         # SCL or SDA held low longer than the timeout (bus clear failed)
    POLL = 4          # a polled register never read the expected value (includes ID checks)
    ARB = 5           # SDA low while the master released it (arbitration lost / bus error), after retries


class InitStatusSignature(ParametricSignature):
    """What an init sequencer reports for a table of ``entries`` entries: ``busy``, ``done``, ``error``,
    ``error_code`` (:class:`ErrorCode`), ``mismatch`` (a ``Check`` read another value) and ``entry``
    (0 .. ``entries``)."""

    def __init__(self, entries):
        super().__init__({"busy": Out(1), "done": Out(1), "error": Out(1), "error_code": Out(ErrorCode),
                          "mismatch": Out(1), "entry": Out(range(entries + 1))}, entries=entries)


_OP_WRITE, _OP_WAIT, _OP_POLL, _OP_CHECK = 0, 1, 2, 3


def _us_to_cycles(us, clk_hz):
    return -(-us * clk_hz // 1_000_000)


@dataclass(frozen=True)
class Phase:
    """One table of a sequencer that plays several in turn: ``name`` (its status member), ``table``, ``buses``
    (indices of the sequencer's buses it is played on)."""
    name: str
    table: InitTable
    buses: tuple


def _phases(table, buses):
    """``table`` (an ``InitTable``, played on every bus, or a sequence of :class:`Phase`) as a tuple of phases;
    ``TypeError`` / ``ValueError`` for what :class:`InitSequencer` rejects."""
    if isinstance(table, InitTable):
        return (Phase("table", table, tuple(range(buses))),)
    phases = tuple(table) if isinstance(table, (tuple, list)) else ()
    if not phases or not all(isinstance(p, Phase) and isinstance(p.table, InitTable) for p in phases):
        raise TypeError("table must be an hdl.init_tables.InitTable or a non-empty sequence of Phase")
    if len({p.name for p in phases}) != len(phases):
        raise ValueError("the phases' names must differ")
    for p in phases:
        if not p.buses or not all(0 <= b < buses for b in p.buses) or len(p.table) == 0:
            raise ValueError(f"phase {p.name!r}: needs entries and buses among 0 .. {buses - 1}")
    return phases


def check_parameters(table, *, clk_hz=CLOCKS.SYS_HZ, bus_hz=CLOCKS.I2C_HZ, retries=3, timeout_us=25_000, buses=1):
    """``TypeError`` / ``ValueError`` for what :class:`InitSequencer` rejects (see its Raises)."""
    if buses < 1:
        raise ValueError("buses must be >= 1")
    _phases(table, buses)
    if retries < 0:
        raise ValueError("retries must be >= 0")
    master_timing(clk_hz, bus_hz, timeout_us)


class InitSequencer(wiring.Component):
    """Plays ``table`` once after reset; see the module docstring for the entries, the faults and the status.

    Parameters
    ----------
    table : :class:`hdl.init_tables.InitTable`, or a sequence of :class:`Phase`
        One table played on every bus, or tables played in turn, each on its own buses (see the module docstring).
    clk_hz, bus_hz : int
        The ``sync`` clock and the bus rate (:class:`~hdl.i2c_master.I2CMaster`).
    retries : int
        Further attempts of a transaction after a NACK or a lost arbitration.
    retry_delay_us, timeout_us : int
        Wait before a retry; stuck-bus time-out.
    buses : int
        The buses the table is played on at once (see the module docstring).

    Attributes
    ----------
    i2c : ``Out(I2CSignature)``, with ``buses`` > 1 ``Out(I2CSignature).array(buses)``
        Connected to the master's pins (the submodule ``master``).
    status : ``Out(InitStatusSignature(len(table)))``
        With phases: ``status.<phase name>``, each phase's own ``InitStatusSignature``.
    nacked : ``Out(buses)``
        With ``buses`` > 1 only: the buses that did not acknowledge the last NACKed byte (``sync``, registered).
    barrier : ``Out(1)``, release : ``In(1)``
        Held at a ``Barrier`` entry; released (see the module docstring). ``release`` is high unless driven: a
        sequencer that shares its barrier with none goes straight through it.

    Raises
    ------
    TypeError
        ``table`` is not an ``InitTable`` or a sequence of ``Phase``.
    ValueError
        Negative ``retries``, ``buses`` < 1, a phase without entries or on a bus the sequencer does not have, two
        phases of one name, or timing the master rejects.
    """

    def __init__(self, table, *, clk_hz=CLOCKS.SYS_HZ, bus_hz=CLOCKS.I2C_HZ, retries=3,
                 retry_delay_us=1000, timeout_us=25_000, buses=1):
        check_parameters(table, clk_hz=clk_hz, bus_hz=bus_hz, retries=retries, timeout_us=timeout_us, buses=buses)
        self.phases = _phases(table, buses)
        self.table = table
        self.buses = buses
        self.clk_hz = clk_hz
        self.bus_hz = bus_hz
        self.retries = retries
        self.timeout_us = timeout_us
        self.retry_delay = max(1, _us_to_cycles(retry_delay_us, clk_hz))
        status = (InitStatusSignature(len(table)) if isinstance(table, InitTable) else
                  wiring.Signature({p.name: Out(InitStatusSignature(len(p.table))) for p in self.phases}))
        members = {"i2c": Out(I2CSignature) if buses == 1 else Out(I2CSignature).array(buses),
                   "status": Out(status), "barrier": Out(1), "release": In(1, init=1)}
        if buses > 1:
            members["nacked"] = Out(buses)
        super().__init__(members)

    def phase_status(self):
        """Each phase's status interface, in phase order."""
        if isinstance(self.table, InitTable):
            return [self.status]
        return [getattr(self.status, p.name) for p in self.phases]

    def _rom(self):
        devices = [p.table.device for p in self.phases]
        rb, db = 8 * max(d.reg_bytes for d in devices), 8 * max(d.data_bytes for d in devices)
        words = []
        for e in (e for p in self.phases for e in p.table.entries):
            if isinstance(e, Write):
                words.append(dict(op=_OP_WRITE, reg=e.reg, value=e.value, mask=0, count=0, attempts=0))
            elif isinstance(e, Wait):
                words.append(dict(op=_OP_WAIT, reg=0, value=0, mask=0,
                                  count=_us_to_cycles(e.us, self.clk_hz), attempts=0))
            elif isinstance(e, Barrier):         # a wait that ends on release: marked by attempts = 1
                words.append(dict(op=_OP_WAIT, reg=0, value=0, mask=0, count=0, attempts=1))
            elif isinstance(e, Check):
                words.append(dict(op=_OP_CHECK, reg=e.reg, value=e.value & ((1 << db) - 1),
                                  mask=e.mask & ((1 << db) - 1), count=0, attempts=1))
            else:
                words.append(dict(op=_OP_POLL, reg=e.reg, value=e.value & ((1 << db) - 1),
                                  mask=e.mask & ((1 << db) - 1),
                                  count=_us_to_cycles(e.interval_us, self.clk_hz), attempts=e.attempts))
        max_count = max([w["count"] for w in words] + [self.retry_delay, 1])
        max_attempts = max([w["attempts"] for w in words] + [1])
        layout = data.StructLayout({
            "op": 2, "reg": rb, "value": db, "mask": db,
            "count": unsigned(max_count.bit_length()), "attempts": range(max_attempts + 1),
        })
        return layout, words, max_count, max_attempts

    def elaborate(self, platform):
        m = Module()
        m.submodules.master = master = I2CMaster(clk_hz=self.clk_hz, bus_hz=self.bus_hz, timeout_us=self.timeout_us,
                                                 buses=self.buses)
        for own, pins in zip(bus_pins(self.i2c, self.buses), bus_pins(master.i2c, self.buses)):
            wiring.connect(m, wiring.flipped(own), pins)
        states = _States(self, master, m)
        for status in self.phase_status():
            m.d.comb += status.busy.eq(~status.done & ~status.error)
        with m.FSM() as fsm:
            states.entry()
            states.transaction()
            states.retry()
            states.complete()
            states.end()
        states.drive_master(fsm)
        return m


class _States:
    """The sequencer's ROM, registers and step programs, and the states of its FSM, a group per method (emitted
    inside the ``m.FSM()`` block of :meth:`InitSequencer.elaborate`, in this order)."""

    def __init__(self, seq, master, m):
        self.seq, self.m, self.master = seq, m, master
        phases = seq.phases
        self.status = seq.phase_status()
        self.starts = [sum(len(p.table) for p in phases[:i]) for i in range(len(phases))]
        self.ends = [start + len(p.table) for start, p in zip(self.starts, phases)]
        n = self.n = self.ends[-1]
        layout, words, max_count, max_attempts = seq._rom()
        # ROM_STYLE: a few dozen words; XST would otherwise spend block RAM on it (XST User Guide, ROM_STYLE)
        m.submodules.rom = rom = Memory(shape=layout, depth=n, init=words, attrs={"ROM_STYLE": "distributed"})
        rd = rom.read_port(domain="sync")            # synchronous ROM: the word of `pc` one cycle later
        self.pc = Signal(range(n + 1), name="pc")
        # The phase being played; its table's entries are ROM words starts[phase] .. ends[phase] - 1.
        self.phase = Signal(range(len(phases)), name="phase")
        # pc reaches n (the last table's end) when the last entry completes; the ROM is never addressed past its
        # end (sim/formal/harnesses/i2c.py).
        m.d.comb += rd.addr.eq(Mux(self.pc < n, self.pc, 0))
        self._entries(m)
        self.e = e = rd.data
        # Step programs of each phase: what the master does in each step of a write / a poll read.
        self.programs = [self._steps(p.table.device, e) for p in phases]
        longest = max(len(steps) for program in self.programs for steps in program)
        self.step = Signal(range(longest), name="step")
        self.last_step = Signal(name="last_step")
        self.is_addr = Signal(name="is_addr")
        self.is_write = Signal(name="is_write")
        self.timer = Signal(range(max_count + 2), name="timer")
        self.attempt = Signal(range(seq.retries + 1), name="attempt")
        self.polls = Signal(range(max_attempts + 1), name="polls")
        data_bits = 8 * max(p.table.device.data_bytes for p in phases)
        self.rx = Signal(data_bits, name="rx")                  # the AND of the buses' bytes
        self.rx_any = Signal(data_bits, name="rx_any") if seq.buses > 1 else None   # their OR
        self.fail_code = Signal(ErrorCode, name="fail_code")

    @staticmethod
    def _steps(dev, e):
        """``(write steps, read steps)`` for device ``dev``: each step ``(cmd, wdata, rd_ack, address step?)``."""
        addr_w = dev.address << 1
        addr_r = addr_w | 1
        reg_bytes = [e.reg[8 * i:8 * i + 8] for i in reversed(range(dev.reg_bytes))]      # MSB first
        val_bytes = [e.value[8 * i:8 * i + 8] for i in reversed(range(dev.data_bytes))]
        write = ([(Cmd.START, 0, 0, False), (Cmd.WRITE, addr_w, 0, True)]
                 + [(Cmd.WRITE, b, 0, False) for b in reg_bytes]
                 + [(Cmd.WRITE, b, 0, False) for b in val_bytes]
                 + [(Cmd.STOP, 0, 0, False)])
        read = ([(Cmd.START, 0, 0, False), (Cmd.WRITE, addr_w, 0, True)]
                + [(Cmd.WRITE, b, 0, False) for b in reg_bytes]
                + [(Cmd.START, 0, 0, False), (Cmd.WRITE, addr_r, 0, True)]
                + [(Cmd.READ, 0, int(i < dev.data_bytes - 1), False) for i in range(dev.data_bytes)]
                + [(Cmd.STOP, 0, 0, False)])
        return write, read

    def _entries(self, m):
        """Each phase's ``entry``: 0 before it starts, ``pc - start`` while it runs (and after it failed, for the
        last phase, which stays there), its failing entry (a register) or its length after it."""
        self.failed_at = []
        last = len(self.status) - 1
        for i, (status, start, end) in enumerate(zip(self.status, self.starts, self.ends)):
            failed = Signal(range(end - start + 1), name=f"failed_at_{i}") if i < last else None
            self.failed_at.append(failed)
            here = self.pc - start
            if last == 0:
                m.d.comb += status.entry.eq(here)
                continue
            with m.If(self.phase == i):
                m.d.comb += status.entry.eq(here)
            if i < last:
                with m.Elif(self.phase > i):
                    m.d.comb += status.entry.eq(Mux(status.error, failed, end - start))

    def each_phase(self):
        """``(index, status)`` of each phase inside a ``Switch`` on the current phase (no switch for one)."""
        m = self.m
        if len(self.status) == 1:
            yield 0, self.status[0]
            return
        with m.Switch(self.phase):
            for i, status in enumerate(self.status):
                with m.Case(i):
                    yield i, status

    def clear_rx(self):
        return [self.rx.eq(0)] + ([] if self.rx_any is None else [self.rx_any.eq(0)])

    def next_phase(self, mark, *, last):
        """For the current phase: ``mark(i, status)``, then go on with the next phase (from its first entry), or to
        state ``last`` after the last one."""
        m = self.m
        for i, status in self.each_phase():
            mark(i, status)
            if i == len(self.status) - 1:
                m.next = last
            else:
                m.d.sync += [self.phase.eq(i + 1), self.pc.eq(self.starts[i + 1]), self.polls.eq(0),
                             self.attempt.eq(0)]
                m.next = "LOAD"

    def finish_entry(self):
        self.m.d.sync += [self.pc.eq(self.pc + 1), self.polls.eq(0), self.attempt.eq(0)]
        self.m.next = "LOAD"

    def retry_or_fail(self):
        m, retries = self.m, self.seq.retries
        if retries == 0:
            m.next = "ERROR"
            return
        with m.If(self.attempt < retries):
            m.d.sync += [self.attempt.eq(self.attempt + 1), self.timer.eq(0)]
            m.next = "RETRY_WAIT"
        with m.Else():
            m.next = "ERROR"

    def entry(self):
        """Load the next entry: done after the last one, a wait, or a transaction to issue."""
        m, e, timer = self.m, self.e, self.timer
        with m.State("LOAD"):                          # the ROM reads the word of the new pc
            m.next = "FETCH"
        with m.State("FETCH"):
            m.d.sync += [self.step.eq(0), *self.clear_rx(), timer.eq(0)]
            phase_end = Signal(range(self.n + 1), name="phase_end")
            for i, _ in self.each_phase():
                m.d.comb += phase_end.eq(self.ends[i])
            with m.If(self.pc == phase_end):           # the phase's table has run: done, then the next phase
                self.next_phase(lambda i, status: m.d.sync.__iadd__(status.done.eq(1)), last="DONE")
            with m.Elif(e.op == _OP_WAIT):
                m.next = "WAIT"
            with m.Else():
                m.next = "ISSUE"
        with m.State("WAIT"):
            with m.If(e.attempts != 0):                # a Barrier
                m.d.comb += self.seq.barrier.eq(1)
                with m.If(self.seq.release):
                    self.finish_entry()
            with m.Else():
                m.d.sync += timer.eq(timer + 1)
                with m.If(timer + 1 >= e.count):
                    self.finish_entry()

    def transaction(self):
        """Issue the steps of a write or a poll read one by one; a NACK, a lost arbitration or a stuck bus ends it."""
        m, master, fail_code = self.m, self.master, self.fail_code
        with m.State("ISSUE"):
            with m.If(master.ready):
                m.next = "BUSY"
        with m.State("BUSY"):
            with m.If(master.done):
                with m.If(master.timed_out):
                    m.d.sync += fail_code.eq(ErrorCode.STUCK)
                    m.next = "ERROR"
                with m.Elif(master.arb_lost):
                    m.d.sync += fail_code.eq(ErrorCode.ARB)
                    self.retry_or_fail()
                with m.Elif(self.is_write & master.nack):
                    if self.rx_any is not None:
                        m.d.sync += self.seq.nacked.eq(master.nack_buses)
                    with m.If(self.is_addr):
                        m.d.sync += fail_code.eq(ErrorCode.NACK_ADDR)
                    with m.Else():
                        m.d.sync += fail_code.eq(ErrorCode.NACK_DATA)
                    m.next = "ABORT"
                with m.Elif(self.last_step):
                    m.next = "COMPLETE"
                with m.Else():
                    with m.If(master.cmd == Cmd.READ):
                        m.d.sync += self.rx.eq((self.rx << 8) | master.rdata)
                        if self.rx_any is not None:
                            m.d.sync += self.rx_any.eq((self.rx_any << 8) | master.rdata_any)
                    m.d.sync += self.step.eq(self.step + 1)
                    m.next = "ISSUE"

    def retry(self):
        """STOP after a NACK, then wait and retry the transaction, or give up."""
        m, master, timer = self.m, self.master, self.timer
        with m.State("ABORT"):
            with m.If(master.ready):
                m.next = "ABORT_WAIT"
        with m.State("ABORT_WAIT"):
            with m.If(master.done):
                with m.If(master.timed_out):
                    m.d.sync += self.fail_code.eq(ErrorCode.STUCK)
                    m.next = "ERROR"
                with m.Else():
                    self.retry_or_fail()
        with m.State("RETRY_WAIT"):
            m.d.sync += timer.eq(timer + 1)
            with m.If(timer + 1 >= self.seq.retry_delay):
                m.d.sync += [self.step.eq(0), *self.clear_rx(), timer.eq(0)]
                m.next = "ISSUE"

    def complete(self):
        """A finished write, or a poll read that matched, did not match yet, or ran out of attempts."""
        m, e, timer, polls = self.m, self.e, self.timer, self.polls
        # Registered every clock: rx last changes in BUSY two steps before COMPLETE (the STOP step follows the
        # last read), so in COMPLETE ``matched`` is the comparison of the final rx.
        matched = Signal(name="matched")
        if self.rx_any is None:
            m.d.sync += matched.eq((self.rx & e.mask) == e.value)
        else:                                          # every bus read the value (see the module docstring)
            m.d.sync += matched.eq(((self.rx & e.mask) == e.value) & ((self.rx_any & e.mask) == e.value))
        with m.State("COMPLETE"):
            with m.If(e.op == _OP_WRITE):
                self.finish_entry()
            with m.Elif(e.op == _OP_CHECK):
                with m.If(~matched):
                    for _, status in self.each_phase():
                        m.d.sync += status.mismatch.eq(1)
                self.finish_entry()
            with m.Elif(matched):
                self.finish_entry()
            with m.Elif(polls + 1 >= e.attempts):
                m.d.sync += self.fail_code.eq(ErrorCode.POLL)
                m.next = "ERROR"
            with m.Else():
                m.d.sync += [polls.eq(polls + 1), self.attempt.eq(0), timer.eq(0)]
                m.next = "POLL_WAIT"
        with m.State("POLL_WAIT"):
            m.d.sync += timer.eq(timer + 1)
            with m.If(timer + 1 >= e.count):
                m.d.sync += [self.step.eq(0), *self.clear_rx(), timer.eq(0)]
                m.next = "ISSUE"

    def end(self):
        """ERROR ends the current phase with its error code (the sequencer goes on with the next phase, or stops
        after the last); DONE: every phase has ended, the bus stays idle."""
        m = self.m

        def failed(i, status):
            m.d.sync += [status.error.eq(1), status.error_code.eq(self.fail_code)]
            if self.failed_at[i] is not None:
                m.d.sync += self.failed_at[i].eq(self.pc - self.starts[i])

        with m.State("DONE"):
            pass
        with m.State("ERROR"):
            self.next_phase(failed, last="STOPPED")
        with m.State("STOPPED"):
            pass

    def drive_master(self, fsm):
        """What the master does in each step. Kept out of the FSM and gated by the FSM state so that the exported
        Verilog re-evaluates it when the state changes (Icarus -g2012 does not run `always @*` at time 0)."""
        m, master, e = self.m, self.master, self.e
        # The step's flags the BUSY state tests are registered copies of the decode (one clock later: the step
        # changes on the way into ISSUE, which lasts at least one clock), so BUSY's next-state logic starts at
        # registers.
        is_addr, is_write, last_step = Signal(), Signal(), Signal()
        m.d.sync += [self.is_addr.eq(is_addr), self.is_write.eq(is_write), self.last_step.eq(last_step)]
        aborting = fsm.ongoing("ABORT")
        m.d.comb += master.cmd_valid.eq(fsm.ongoing("ISSUE") | aborting)
        with m.If(aborting):
            m.d.comb += master.cmd.eq(Cmd.STOP)
        with m.Elif(~fsm.ongoing("LOAD")):
            for p, _ in self.each_phase():
                write_steps, read_steps = self.programs[p]
                for steps, ops in ((write_steps, (_OP_WRITE,)), (read_steps, (_OP_POLL, _OP_CHECK))):
                    with m.If(e.op.matches(*ops)):
                        with m.Switch(self.step):
                            for i, (cmd, wdata, rd_ack, addr_step) in enumerate(steps):
                                with m.Case(i):
                                    m.d.comb += [
                                        master.cmd.eq(cmd), master.wdata.eq(wdata), master.rd_ack.eq(rd_ack),
                                        is_addr.eq(addr_step), is_write.eq(cmd == Cmd.WRITE),
                                        last_step.eq(i == len(steps) - 1),
                                    ]
        # The buses of the current phase (when the phases use different ones), registered: the phase changes at
        # least two clocks (LOAD, FETCH) before the phase's first command, and the master's bus reads start at a
        # register.
        masks = [sum(1 << b for b in phase.buses) for phase in self.seq.phases]
        if any(mask != (1 << self.seq.buses) - 1 for mask in masks):
            for p, _ in self.each_phase():
                m.d.sync += master.enable.eq(masks[p])
