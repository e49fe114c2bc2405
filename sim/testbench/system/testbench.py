"""SystemTestbench: the whole system as the simulations run it -- the design, its clocking model and its I2C buses.

:class:`hdl.system.StereoDepthSystem` (behavioural CH7301C output) with :class:`sim.models.clocking.SimClocking` (the
board clocking's simulation model: same domains and reset tree, clocks from the simulator) and one
:class:`sim.models.i2c.bus.OpenDrainBus` per I2C bus, where the board has pads and pull-ups. Every other member of the
system is the bench's own, handed down to the system (forwarded, not copied: :func:`hdl.forward.forward`), so the
exported Verilog's ports are the design's signals under the bench's flat names.

Clock domains: ``sync``, ``pix``, ``cam_a``, ``cam_b``, defined here (unless ``define_domains=False``: then the
parent adds ``bench.domains`` and drives their clocks). A domain's clock comes from the simulator: in Amaranth's
simulator ``add_clock`` or a testbench drives it; for exported Verilog, ``clock_ports=True`` adds the inputs
``clocks.<domain>``. There is no reset port: ``button`` is the reset button, and every domain's
reset comes from the clocking model's reset tree. Latency: the bus resolution is combinational.
"""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from sim.models.clocking import SimClocking
from hdl.forward import forward
from hdl.system import CAMERAS, I2C_BUSES, StereoDepthSystem
from sim.models.i2c.bus import OpenDrainBus, ResolvedBusSignature

__all__ = ["SystemTestbench"]


class SystemTestbench(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    lock_cycles : int
        The clocking model's lock time in ``sync`` clocks.
    cycle_bits : int
        Width of ``cycles``.
    define_domains : bool
        Define the clock domains here (else the parent adds ``domains``).
    clock_ports : bool
        With ``define_domains``: each domain's clock from the input ``clocks.<domain>`` (for Verilog export).
    **system_kwargs
        For :class:`hdl.system.StereoDepthSystem`.

    Attributes
    ----------
    (every member of the system but ``i2c``)
        The system's own interfaces: ``cam_a``, ``cam_b``, ``capture``, ``init``, ``panel``, ``control``, ``video``,
        ``ch7301c``, ``frame_start``, ``settings``.
    button : ``In(1)``, locked : ``Out(1)``
        The clocking model's reset button and lock.
    bus : ``Out``, per I2C bus a :class:`sim.models.i2c.bus.ResolvedBusSignature`
        The resolved lines, the device models' pull-downs and the sticky ``drive_high`` check.
    clocks : ``In``, one bit per domain (with ``clock_ports``)
    cycles : ``Out(cycle_bits)``
        ``sync`` clocks since the simulation started (reset-less: it counts while ``sync`` is in reset too); the
        time base of the Python I2C models.
    """

    def __init__(self, *, lock_cycles=16, cycle_bits=40, define_domains=True, clock_ports=False, **system_kwargs):
        if clock_ports and not define_domains:
            raise ValueError("clock_ports needs define_domains: the clocks of domains defined elsewhere are "
                             "driven there")
        self.define_domains = define_domains
        self.clock_ports = clock_ports
        self.system = StereoDepthSystem(ddr="behavioural", **system_kwargs)
        self.clocking = SimClocking(cam_domains=tuple(f"cam_{c}" for c in CAMERAS), lock_cycles=lock_cycles)
        self.buses = {b: OpenDrainBus(getattr(self.system.i2c, b)) for b in I2C_BUSES}
        own = [name for name in self.system.signature.members if name != "i2c"]
        members = {name: self.system.signature.members[name] for name in own}
        members.update({
            "button": In(1), "locked": Out(1),
            "bus": Out(wiring.Signature({b: Out(ResolvedBusSignature()) for b in I2C_BUSES})),
            "cycles": Out(cycle_bits),
        })
        if clock_ports:
            members["clocks"] = In(wiring.Signature({cd.name: Out(1) for cd in self.clocking.domains}))
        super().__init__(members)
        for name in own:
            forward(self, name, self.system)
        forward(self, "button", self.clocking)
        forward(self, "locked", self.clocking)
        for b in I2C_BUSES:
            forward(self, ("bus", b), self.buses[b], ())

    @property
    def domains(self):
        """The clock domains (``sync``, ``pix``, ``cam_a``, ``cam_b``)."""
        return self.clocking.domains

    def elaborate(self, platform):
        m = Module()
        if self.define_domains:
            m.domains += self.domains
        if self.clock_ports:
            m.d.comb += [cd.clk.eq(getattr(self.clocks, cd.name)) for cd in self.domains]
        m.submodules.clocking = self.clocking
        m.submodules.system = self.system
        for b, bus in self.buses.items():
            m.submodules[f"bus_{b}"] = bus
        cycles = Signal.like(self.cycles, reset_less=True, name="cycle_count")
        m.d.sync += cycles.eq(cycles + 1)
        m.d.comb += self.cycles.eq(cycles)
        return m
