"""RomReplayTestbench: the system testbench with its camera loops moved out of Python, for Amaranth's simulator.

The design of the Amaranth replay route, the one that makes a full-resolution run feasible there. Driving each
camera from a Python testbench costs one await per PCLK edge (about 9 million sensor samples), and a testbench
toggling the pixel clock almost 5 million edges per display frame; each ``ctx.set`` makes the simulator settle the
whole design. This testbench does what the fast cocotb route (``sim/testbench/system/verilog_testbench.py``) does for Verilator:

* each camera's pins come from a :class:`sim.replay.sensor.SensorReplay` ROM holding the Python sensor model's
  stream for one frame period (made before the run for the configuration the spec asks for; the runner checks
  that the RTL's I2C init configured the register-file model to exactly that before starting the replay);
* the ``pix`` and camera clocks are free-running simulator clocks (``add_clock`` on the domains ``free_pix``,
  ``free_cam_a``, ``free_cam_b``) gated by ``clock_en``: a clock that is off costs one tiny gate evaluation per edge
  and wakes none of the design. Change an enable only while its free clock is low (:func:`enable_clock` does) so the
  gated clock has no runt pulse.

``sync`` is clocked by the simulator directly. Clock domains: ``sync``, ``pix``, ``cam_a``, ``cam_b`` (those of the
system) and the three free-running ones. Latency: the gates are combinational; the replay as
:class:`~sim.replay.sensor.SensorReplay` says.
"""

from amaranth import ClockDomain, ClockSignal, Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.system import CAMERAS, SystemParameters
from sim.replay.sensor import SensorReplay
from sim.testbench.system.testbench import DOMAINS, SystemTestbench, bench_members, pass_through

__all__ = ["RomReplayTestbench", "GATED_DOMAINS", "ClockGate", "enable_clock"]

#: The domains whose clocks are gated (free-running clock domain ``free_<name>`` each).
GATED_DOMAINS = ("pix", *(f"cam_{c}" for c in CAMERAS))


class ClockGate(wiring.Component):
    """``clk`` = the free-running clock of ``free_domain`` while ``en`` is high. Its own module, so an edge of the
    free clock wakes only this one assignment. Combinational."""

    en: In(1)

    def __init__(self, free_domain, clk):
        self._free_domain = free_domain
        self._clk = clk
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        m.d.comb += self._clk.eq(ClockSignal(self._free_domain) & self.en)
        return m


class RomReplayTestbench(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    replay_words : dict
        ``{camera: ROM words}`` (:func:`sim.replay.sensor.pack_stream` of each camera's stream).
    **system_kwargs
        For :class:`sim.testbench.system.testbench.SystemTestbench`.

    Attributes
    ----------
    (every member of the system testbench but the camera pins)
    clock_en : ``In``, one bit per gated domain (``pix``, ``cam_a``, ``cam_b``)
    replay_run : ``In``, one bit per camera ``cam_a``, ``cam_b``
        Start the camera's replay (its position is ``replays[c].index``).
    free_domains : dict
        ``{gated domain: its free-running ClockDomain}``, for the simulator's ``add_clock``.
    domains : list of ClockDomain
        The system's domains (``sync``, ``pix``, ``cam_a``, ``cam_b``), defined here.
    params : :class:`hdl.system.SystemParameters`
        The system's parameters (``video_timing``: its ``timing``).

    Raises
    ------
    ValueError
        ``replay_words`` without exactly one ROM per camera.
    """

    def __init__(self, *, replay_words, **system_kwargs):
        if set(replay_words) != set(CAMERAS):
            raise ValueError(f"replay_words needs one ROM per camera {CAMERAS}, got {sorted(replay_words)}")
        self.replay_words = replay_words
        self.system_kwargs = system_kwargs
        self.params = SystemParameters(ddr="behavioural", **{k: v for k, v in system_kwargs.items()
                                                             if k != "lock_cycles"})
        self.video_timing = self.params.timing
        self.domains = [ClockDomain(name) for name in DOMAINS]
        cam_pins = {f"cam_{c}" for c in CAMERAS}
        members = {name: member for name, member in bench_members(self.params).items() if name not in cam_pins}
        members.update({
            "clock_en": In(wiring.Signature({name: Out(1) for name in GATED_DOMAINS})),
            "replay_run": In(wiring.Signature({f"cam_{c}": Out(1) for c in CAMERAS})),
        })
        super().__init__(members)
        self.free_domains = {name: ClockDomain(f"free_{name}", reset_less=True) for name in GATED_DOMAINS}

    def elaborate(self, platform):
        m = Module()
        m.domains += list(self.free_domains.values())
        m.submodules.bench = bench = SystemTestbench(define_domains=False, **self.system_kwargs)
        m.domains += self.domains         # defined here: the replays use the camera domains too
        pass_through(m, self, bench)
        domains = {cd.name: cd for cd in self.domains}
        for name in GATED_DOMAINS:
            m.submodules[f"gate_{name}"] = gate = ClockGate(f"free_{name}", domains[name].clk)
            m.d.comb += gate.en.eq(getattr(self.clock_en, name))
        for c in CAMERAS:
            m.submodules[f"replay_{c}"] = replay = SensorReplay(self.replay_words[c], domain=f"cam_{c}")
            wiring.connect(m, replay.pins, getattr(bench, f"cam_{c}"))
            m.d.comb += replay.run.eq(getattr(self.replay_run, f"cam_{c}"))
        return m


async def enable_clock(ctx, bench, name, on=True):
    """Testbench helper: switch gated domain ``name``'s clock on (or off) while its free clock is low."""
    clk = bench.free_domains[name].clk
    if ctx.get(clk):
        await ctx.negedge(clk)
    ctx.set(getattr(bench.clock_en, name), int(on))
