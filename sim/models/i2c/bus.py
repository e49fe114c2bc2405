"""The open-drain I2C bus around a design in simulation, and the glue that runs the ``sim.models`` models on it.

On the board, the pads and the pull-up resistors make each I2C bus a wired AND. In simulation
:class:`OpenDrainBus` does: the bus lines are high unless the design pulls them low (``oe`` with ``o`` = 0), a
Python device model pulls them low (``ext_scl_low`` / ``ext_sda_low``) or, with ``peer=True``, a cocotbext-i2c
device does (``peer_scl_o`` / ``peer_sda_o`` = 0). ``drive_high`` turns sticky-high if the design ever drives a
line actively high (``oe`` with ``o`` = 1), which an open-drain output must never do. This is the one bus
resolver: the I2C benches (:func:`I2CBench`) and the whole-system testbench (``sim/testbench/system/testbench.py``) both use it.

* :func:`amaranth_target_process` / :func:`start_cocotb_targets`: run a list of ``sim.models`` targets on a
  resolved bus in the Amaranth simulator / in cocotb (time from a ``sync`` cycle counter / from the simulator);
  :func:`start_cocotb_monitor` feeds an :class:`sim.models.i2c.monitor.I2CBusMonitor` from a bus without targets.
"""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.i2c_master import I2CSignature
from hdl.signature import ParametricSignature

__all__ = ["ResolvedBusSignature", "OpenDrainBus", "I2CBench", "bench_buses", "i2c_bench_waves",
           "amaranth_target_process", "start_cocotb_targets", "start_cocotb_monitor"]


class ResolvedBusSignature(ParametricSignature):
    """One resolved bus as a testbench sees it: the lines ``scl``, ``sda``; the device models' pull-downs
    ``ext_scl_low``, ``ext_sda_low``; with ``peer``, a cocotbext-i2c device's outputs ``peer_scl_o``,
    ``peer_sda_o`` (1 = released); ``drive_high`` (sticky: the design drove a line high)."""

    def __init__(self, *, peer=False):
        members = {"scl": Out(1), "sda": Out(1), "ext_scl_low": In(1), "ext_sda_low": In(1), "drive_high": Out(1)}
        if peer:
            members.update({"peer_scl_o": In(1, init=1), "peer_sda_o": In(1, init=1)})
        super().__init__(members, peer=peer)


class OpenDrainBus(wiring.Component):
    """Wired-AND resolution of a design's open-drain pins.

    Parameters
    ----------
    peer : bool
        With a cocotbext-i2c device's outputs (:class:`ResolvedBusSignature`).

    Attributes
    ----------
    pins : ``In(I2CSignature)``
        The design's ``hdl.i2c_master.I2CSignature`` interface (this block drives its ``i``).
    lines : ``Out(ResolvedBusSignature(peer=peer))``
        The resolved bus.

    Clock domain of ``lines.drive_high``: ``sync``. Latency: the lines are combinational.
    """

    def __init__(self, *, peer=False):
        super().__init__({"pins": In(I2CSignature), "lines": Out(ResolvedBusSignature(peer=peer))})

    def elaborate(self, platform):
        m = Module()
        pins, lines = self.pins, self.lines
        scl = ~(pins.scl.oe & ~pins.scl.o) & ~lines.ext_scl_low
        sda = ~(pins.sda.oe & ~pins.sda.o) & ~lines.ext_sda_low
        if "peer_scl_o" in lines.signature.members:
            scl &= lines.peer_scl_o
            sda &= lines.peer_sda_o
        m.d.comb += [lines.scl.eq(scl), lines.sda.eq(sda), pins.scl.i.eq(scl), pins.sda.i.eq(sda)]
        driven_high = Signal()
        m.d.comb += driven_high.eq((pins.scl.oe & pins.scl.o) | (pins.sda.oe & pins.sda.o))
        with m.If(driven_high):
            m.d.sync += lines.drive_high.eq(1)
        return m


def bench_buses(name, dut):
    """The bus names :func:`I2CBench` gives the DUT ``name``: ``[name]`` for an ``i2c`` member that is one
    ``I2CSignature``, ``[name_0, name_1, ...]`` for an array of them (a broadcasting DUT, one bus each)."""
    member = dut.signature.members["i2c"]
    if not member.dimensions:
        return [name]
    return [f"{name}_{k}" for k in range(member.dimensions[0])]


def I2CBench(duts, *, counter_bits=40):
    """A component wiring each DUT of ``duts`` (``{name: component}``, each with an ``i2c`` member, one
    ``I2CSignature`` or an array of them) to an :class:`OpenDrainBus` per bus (with a cocotbext-i2c peer; the bus
    names are :func:`bench_buses`'s). Members: ``bus.<b>`` (each resolved bus), ``status.<name>`` (connected to
    the DUT's ``status`` interface, for DUTs that have one) and ``cycles`` (``sync`` clocks: the time base of the
    Python models)."""
    with_status = {b: dut for b, dut in duts.items() if "status" in dut.signature.members}
    buses = {name: bench_buses(name, dut) for name, dut in duts.items()}

    class _Bench(wiring.Component):
        def __init__(self):
            members = {"cycles": Out(counter_bits),
                       "bus": Out(wiring.Signature({b: Out(ResolvedBusSignature(peer=True))
                                                    for names in buses.values() for b in names}))}
            if with_status:
                members["status"] = Out(wiring.Signature(
                    {b: Out(dut.signature.members["status"].signature) for b, dut in with_status.items()}))
            super().__init__(members)

        def elaborate(self, platform):
            m = Module()
            m.d.sync += self.cycles.eq(self.cycles + 1)
            for name, dut in duts.items():
                m.submodules[name] = dut
                pins = list(dut.i2c) if dut.signature.members["i2c"].dimensions else [dut.i2c]
                for b, pin in zip(buses[name], pins):
                    m.submodules[f"{b}_bus"] = bus = OpenDrainBus(peer=True)
                    wiring.connect(m, pin, bus.pins)
                    wiring.connect(m, wiring.flipped(getattr(self.bus, b)), bus.lines)
            for b, dut in with_status.items():
                wiring.connect(m, wiring.flipped(getattr(self.status, b)), dut.status)
            return m

    return _Bench()


def i2c_bench_waves(buses):
    """What the save file of an :func:`I2CBench` run under cocotb marks (a :class:`sim.waves.cocotb.RunWaves`):
    each bus's sequencer done or in error."""
    from sim.waves.cocotb import RunWaves
    from sim.waves.gtkw import Event
    return RunWaves(events=[Event(f"{b} init {what}", f"status__{b}__{what}") for b in buses
                            for what in ("done", "error")])


def _step(targets, monitor, scl, sda, now):
    """Give the targets (and the monitor) the bus levels at ``now``; returns ``(pulls, deadline)``: whether any
    target pulls SCL / SDA low, and the earliest time a target wants to be called again (or None)."""
    if monitor is not None:
        monitor.observe(now, scl, sda)
    for t in targets:
        t.update(scl, sda, now)
    pulls = (any(t.scl_low for t in targets), any(t.sda_low for t in targets))
    deadlines = [d for d in (t.deadline() for t in targets) if d is not None]
    return pulls, (min(deadlines) if deadlines else None)


def amaranth_target_process(bus, targets, clk_hz, cycles, monitor=None):
    """An ``add_process`` coroutine that runs ``targets`` on the resolved bus ``bus`` (a
    :class:`ResolvedBusSignature` interface) in the Amaranth simulator and feeds ``monitor``; time =
    ``cycles / clk_hz``."""

    async def process(ctx):
        state = (None, None)
        scl, sda, count = 1, 1, 0
        while True:
            now = count / clk_hz
            pulls, deadline = _step(targets, monitor, scl, sda, now)
            if pulls != state:
                ctx.set(bus.ext_scl_low, pulls[0])
                ctx.set(bus.ext_sda_low, pulls[1])
                state = pulls
            trigger = ctx.changed(bus.scl, bus.sda)
            if deadline is not None:
                trigger = trigger.delay(max(deadline - now, 0) + 0.5 / clk_hz)
                scl, sda, _, count = await trigger.sample(cycles)
            else:
                scl, sda, count = await trigger.sample(cycles)

    return process


def _levels(bus):
    try:
        return int(bus.scl.value), int(bus.sda.value)
    except ValueError:
        return None


def start_cocotb_targets(bus, targets, monitor=None):
    """Start a cocotb task that runs ``targets`` on the resolved bus ``bus`` of an exported design (cocotb handles
    ``scl``, ``sda``, ``ext_scl_low``, ``ext_sda_low``, e.g. ``sim.runners.cocotb.TopPorts(dut).bus.cam_a``); time
    from the simulator. Returns the task."""
    import cocotb
    from cocotb.simtime import get_sim_time
    from cocotb.triggers import First, Timer

    bus.ext_scl_low.value = 0
    bus.ext_sda_low.value = 0

    async def run():
        state = (False, False)
        while True:
            now = get_sim_time("ns") * 1e-9
            levels = _levels(bus)
            if levels is None:                        # before reset: X/Z, nothing to react to
                await First(bus.scl.value_change, bus.sda.value_change)
                continue
            pulls, deadline = _step(targets, monitor, *levels, now)
            if pulls != state:
                bus.ext_scl_low.value = int(pulls[0])
                bus.ext_sda_low.value = int(pulls[1])
                state = pulls
            triggers = [bus.scl.value_change, bus.sda.value_change]
            if deadline is not None:
                triggers.append(Timer(max(1, round((deadline - now) * 1e9)), unit="ns"))
            await First(*triggers)

    return cocotb.start_soon(run())


def start_cocotb_monitor(bus, monitor):
    """Start a cocotb task feeding ``monitor`` with every change of the resolved bus ``bus`` (sim time)."""
    import cocotb
    from cocotb.simtime import get_sim_time
    from cocotb.triggers import First

    async def run():
        while True:
            await First(bus.scl.value_change, bus.sda.value_change)
            levels = _levels(bus)
            if levels is not None:
                monitor.observe(get_sim_time("ns") * 1e-9, *levels)

    return cocotb.start_soon(run())
