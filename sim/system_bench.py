"""SystemBench: the simulated whole system with its I2C buses resolved, ready for a simulator or Verilog export.

:class:`hdl.system.SimSystem` has open-drain I2C pins (``<bus>_scl_o/oe/i``...). On the board the pads and the
pull-up resistors make the wired-AND bus; here :class:`SystemBench` does: for each bus ``b`` in
``hdl.system.I2C_BUSES`` (``cam_a``, ``cam_b``, ``dvi``) the resolved lines ``b_scl``/``b_sda`` are high unless
the RTL pulls them low (``oe`` with ``o`` = 0) or a device model pulls them low (``b_ext_scl_low`` /
``b_ext_sda_low``, driven by ``sim.i2c_devices`` targets). ``b_drive_high`` turns sticky-high if the RTL ever
drives a line actively high (``oe`` with ``o`` = 1), which an open-drain output must never do. ``cycles``
counts ``sync`` clocks (the time base of the Amaranth-side I2C models).

Every other port of :class:`hdl.system.SimSystem` is passed through under the same name (camera pins, CH7301C
pins, switches, LEDs, status). The domains are defined here. With ``clock_ports=True`` (for Verilog export) their
clocks come from the input ports ``clk`` (sync), ``pix_clk``, ``cam_a_clk``, ``cam_b_clk``; with
``clock_ports=False`` (Amaranth simulator) the simulator drives the domains' clocks directly. There is no reset
port: ``button`` is the reset button, and every domain's reset comes from the clocking model's reset tree.

Clock domains: those of :class:`hdl.system.SimSystem`. Latency: the bus resolution is combinational.
"""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.system import I2C_BUSES, SimSystem

__all__ = ["SystemBench"]

_BUS_PINS = ("scl_o", "scl_oe", "scl_i", "sda_o", "sda_oe", "sda_i")


class SystemBench(wiring.Component):
    """See the module docstring. ``cycle_bits`` is the width of the ``cycles`` counter; with
    ``define_domains=False`` the parent adds ``sim_system.clocking.domains`` (so its other children may use them);
    ``system_kwargs`` go to :class:`hdl.system.SimSystem` (and from there to :class:`hdl.system.StereoDepthSystem`)."""

    def __init__(self, *, cycle_bits=40, clock_ports=False, define_domains=True, **system_kwargs):
        self.clock_ports = clock_ports
        self.define_domains = define_domains
        self.sim_system = SimSystem(define_domains=False, **system_kwargs)
        self.system = self.sim_system.system
        members = {}
        for name, member in self.sim_system.signature.members.items():
            if any(name == f"{b}_{p}" for b in I2C_BUSES for p in _BUS_PINS):
                continue
            members[name] = member
        for b in I2C_BUSES:
            members.update({
                f"{b}_scl": Out(1), f"{b}_sda": Out(1),
                f"{b}_ext_scl_low": In(1), f"{b}_ext_sda_low": In(1),
                f"{b}_drive_high": Out(1),
            })
        members["cycles"] = Out(cycle_bits)
        if clock_ports:
            for cd in self.sim_system.clocking.domains:
                members["clk" if cd.name == "sync" else f"{cd.name}_clk"] = In(1)
        super().__init__(members)

    def elaborate(self, platform):
        m = Module()
        if self.define_domains:
            m.domains += self.sim_system.clocking.domains
        if self.clock_ports:
            for cd in self.sim_system.clocking.domains:
                m.d.comb += cd.clk.eq(getattr(self, "clk" if cd.name == "sync" else f"{cd.name}_clk"))
        m.submodules.dut = dut = self.sim_system
        for name, member in dut.signature.members.items():
            if name not in self.signature.members:
                continue
            ours, theirs = getattr(self, name), getattr(dut, name)
            m.d.comb += (theirs.eq(ours) if member.flow == In else ours.eq(theirs))
        for b in I2C_BUSES:
            p = lambda n, b=b: getattr(self, f"{b}_{n}")          # noqa: E731
            d = lambda n, b=b: getattr(dut, f"{b}_{n}")           # noqa: E731
            scl = ~(d("scl_oe") & ~d("scl_o")) & ~p("ext_scl_low")
            sda = ~(d("sda_oe") & ~d("sda_o")) & ~p("ext_sda_low")
            m.d.comb += [p("scl").eq(scl), p("sda").eq(sda), d("scl_i").eq(scl), d("sda_i").eq(sda)]
            high = Signal(name=f"{b}_high")
            m.d.comb += high.eq((d("scl_oe") & d("scl_o")) | (d("sda_oe") & d("sda_o")))
            with m.If(high):
                m.d.sync += p("drive_high").eq(1)
        # The time base counts from the start of the simulation (it must run while sync is still in reset).
        cycles = Signal.like(self.cycles, reset_less=True, name="cycle_count")
        m.d.sync += cycles.eq(cycles + 1)
        m.d.comb += self.cycles.eq(cycles)
        return m
