"""SystemTestbench: the whole system as the simulations run it -- the design, its clocking model and its I2C buses.

:class:`hdl.system.StereoDepthSystem` (behavioural CH7301C output) with :class:`sim.models.clocking.SimClocking` (the
board clocking's simulation model: same domains and reset tree, clocks from the simulator) and one
:class:`sim.models.i2c.bus.OpenDrainBus` per I2C bus, where the board has pads and pull-ups. Every other member of the
system is the bench's own too, connected to the system's (``wiring.connect``), so the exported Verilog's ports are
the system's members under the bench's flat names.

With a system of ``memory="ddr2"`` the bench also holds the MIG model (:class:`sim.models.mig.MIGModel`, submodule
``mig``) on the system's ``mig`` port, in the ``mem`` domain (125 MHz, MIG's ``clk0``; its reset the clocking
model's, synchronised to it), its window the frame store's buffers; the model's ``latency`` and ``violation`` are the
bench's ``memory`` member. Its storage is an Amaranth memory for Amaranth's simulator, or for exported Verilog
(``mig_storage="verilog"``) an instance of :data:`sim.models.mig.STORAGE_MODULE`, whose text the exporter appends
(:func:`export_text`).

Clock domains: ``sync``, ``pix``, ``cam_a``, ``cam_b`` (and ``mem`` with the DDR2), defined here (unless ``define_domains=False``: then the
parent adds ``bench.domains`` and drives their clocks). A domain's clock comes from the simulator: in Amaranth's
simulator ``add_clock`` or a testbench drives it; for exported Verilog, ``clock_ports=True`` adds the inputs
``clocks.<domain>``. There is no reset port: ``button`` is the reset button, and every domain's
reset comes from the clocking model's reset tree. Latency: the bus resolution is combinational.
"""

from amaranth import ClockDomain, DomainRenamer, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.cdc import ResetSynchronizer
from amaranth.lib.wiring import In, Out

from sim.models.clocking import SimClocking
from hdl.system import CAMERAS, I2C_BUSES, StereoDepthSystem, SystemParameters
from sim.models.i2c.bus import OpenDrainBus, ResolvedBusSignature
from sim.models.mig import READ_LATENCY_RANGE, STORAGE_VERILOG, MIGModel, layout_window
from sim.models.mig.violations import ViolationSignature

__all__ = ["SystemTestbench", "bench_members", "pass_through", "domains_of", "export_text", "DOMAINS",
           "MemoryModelSignature"]

#: The system's clock domains (the block-RAM build).
DOMAINS = ("sync", "pix", *(f"cam_{c}" for c in CAMERAS))

#: The MIG model as the bench presents it: ``latency`` in (the run's read latency, clk0 clocks), ``violation`` out.
MemoryModelSignature = wiring.Signature({
    "latency": In(range(READ_LATENCY_RANGE[1] + 1), init=READ_LATENCY_RANGE[0]),
    "violation": Out(ViolationSignature()),
})


def domains_of(params):
    """The clock domains of a system with parameters ``params``: :data:`DOMAINS`, and ``mem`` with the DDR2."""
    return DOMAINS + (("mem",) if params.memory == "ddr2" else ())


def export_text(design, name):
    """Verilog of ``design`` (a component holding a :class:`SystemTestbench`) as module ``name``, with the MIG
    model's storage module appended when the design has the DDR2 (``mig_storage="verilog"``)."""
    from board.export import export_verilog
    text = export_verilog(design, name)
    return text + STORAGE_VERILOG if "memory" in design.signature.members else text


def pass_through(m, outer, inner):
    """Connect each member of component ``outer`` that its child ``inner`` has to the child's: an interface with
    ``wiring.connect`` (``outer``'s flipped), a port with an assignment in its direction."""
    for name, member in outer.signature.members.items():
        if name not in inner.signature.members:
            continue
        if member.is_signature:
            wiring.connect(m, wiring.flipped(getattr(outer, name)), getattr(inner, name))
        elif member.flow == Out:
            m.d.comb += getattr(outer, name).eq(getattr(inner, name))
        else:
            m.d.comb += getattr(inner, name).eq(getattr(outer, name))


def bench_members(params, *, cycle_bits=40, clock_ports=False):
    """The members of a :class:`SystemTestbench` of a system with parameters ``params``
    (:class:`hdl.system.SystemParameters`)."""
    members = {name: member for name, member in params.signature().members.items() if name not in ("i2c", "mig")}
    members.update({
        "button": In(1), "locked": Out(1),
        "bus": Out(wiring.Signature({b: Out(ResolvedBusSignature()) for b in I2C_BUSES})),
        "cycles": Out(cycle_bits),
    })
    if params.memory == "ddr2":
        members["memory"] = Out(MemoryModelSignature)
    if clock_ports:
        members["clocks"] = In(wiring.Signature({name: Out(1) for name in domains_of(params)}))
    return members


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
    mig_storage : str
        With the DDR2: the MIG model's storage, ``"memory"`` (Amaranth's simulator) or ``"verilog"`` (exported
        Verilog: :func:`export_text` appends its module).
    **system_kwargs
        For :class:`hdl.system.StereoDepthSystem`.

    Attributes
    ----------
    params : :class:`hdl.system.SystemParameters`
        The system's parameters (``geometry``, ``video_timing``: its ``geometry`` and ``timing``).
    domains : list of ClockDomain
        ``sync``, ``pix``, ``cam_a``, ``cam_b`` (and ``mem`` with the DDR2).
    (every member of the system but ``i2c``)
        The system's own interfaces: ``cam_a``, ``cam_b``, ``capture``, ``init``, ``panel``, ``control``, ``video``,
        ``ch7301c``, ``frame_start``, ``settings``.
    button : ``In(1)``, locked : ``Out(1)``
        The clocking model's reset button and lock.
    bus : ``Out``, per I2C bus a :class:`sim.models.i2c.bus.ResolvedBusSignature`
        The resolved lines, the device models' pull-downs and the sticky ``drive_high`` check.
    clocks : ``In``, one bit per domain (with ``clock_ports``)
    memory : ``Out(MemoryModelSignature)``
        With the DDR2: the MIG model's ``latency`` (set it before ``phy_init_done``) and ``violation``.
    cycles : ``Out(cycle_bits)``
        ``sync`` clocks since the simulation started (reset-less: it counts while ``sync`` is in reset too); the
        time base of the Python I2C models.

    Raises
    ------
    ValueError, TypeError
        ``clock_ports`` without ``define_domains``, ``lock_cycles`` below 1, the system's parameter checks.
    """

    def __init__(self, *, lock_cycles=16, cycle_bits=40, define_domains=True, clock_ports=False,
                 mig_storage="memory", **system_kwargs):
        if clock_ports and not define_domains:
            raise ValueError("clock_ports needs define_domains: the clocks of domains defined elsewhere are "
                             "driven there")
        if lock_cycles < 1:
            raise ValueError("lock_cycles must be at least 1")
        self.define_domains = define_domains
        self.clock_ports = clock_ports
        self.lock_cycles = lock_cycles
        self.mig_storage = mig_storage
        self.system_kwargs = dict(ddr="behavioural", **system_kwargs)
        self.params = SystemParameters(**self.system_kwargs)
        self.geometry, self.video_timing = self.params.geometry, self.params.timing
        #: The clock domains, driven by the clocking model's reset tree.
        self.domains = [ClockDomain(name) for name in domains_of(self.params)]
        super().__init__(bench_members(self.params, cycle_bits=cycle_bits, clock_ports=clock_ports))

    def elaborate(self, platform):
        m = Module()
        if self.define_domains:
            m.domains += self.domains
        if self.clock_ports:
            m.d.comb += [cd.clk.eq(getattr(self.clocks, cd.name)) for cd in self.domains]
        m.submodules.clocking = clocking = SimClocking(cam_domains=tuple(f"cam_{c}" for c in CAMERAS),
                                                       lock_cycles=self.lock_cycles)
        m.d.comb += [clocking.button.eq(self.button), self.locked.eq(clocking.locked)]
        m.submodules.system = system = StereoDepthSystem(**self.system_kwargs)
        pass_through(m, self, system)
        if self.params.memory == "ddr2":
            self._memory(m, system, clocking)
        for b in I2C_BUSES:
            m.submodules[f"bus_{b}"] = bus = OpenDrainBus()
            wiring.connect(m, getattr(system.i2c, b), bus.pins)
            wiring.connect(m, wiring.flipped(getattr(self.bus, b)), bus.lines)
        cycles = Signal.like(self.cycles, reset_less=True, name="cycle_count")
        m.d.sync += cycles.eq(cycles + 1)
        m.d.comb += self.cycles.eq(cycles)
        return m

    def _memory(self, m, system, clocking):
        """The MIG model on the system's ``mig`` port, in ``mem``, reset with the clocking model's domains."""
        layout = self.params.store_layout
        m.submodules.mem_reset = ResetSynchronizer(self.button | ~clocking.locked, domain="mem")
        mig = MIGModel(**layout_window(layout), storage=self.mig_storage)
        m.submodules.mig = DomainRenamer("mem")(mig)
        wiring.connect(m, system.mig, mig.user)
        wiring.connect(m, wiring.flipped(self.memory.violation), mig.violation)
        m.d.comb += mig.latency.eq(self.memory.latency)
