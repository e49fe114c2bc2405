"""AmaranthFastBench: :class:`sim.system_bench.SystemBench` with its camera loops moved out of Python.

For a full-resolution run in Amaranth's simulator. :func:`sim.system_amaranth.run_amaranth` normally drives each
camera from a Python testbench, one await per PCLK edge (about 9 million sensor samples), and starts the pixel
clock with a testbench that toggles it (almost 5 million edges per display frame); a testbench's every
``ctx.set`` makes the simulator settle the whole design. Measured at full size this put a run at 3-3.5 hours.
This bench does what the fast cocotb route (``sim/system_fast.py``) does for Verilator:

* each camera's pins come from a :class:`sim.sensor_replay.SensorReplay` ROM holding the Python sensor model's
  stream for one frame period (made before the run for the configuration the spec asks for; the runner checks
  that the RTL's I2C init configured the register-file model to exactly that before starting the replay);
* the ``pix`` and camera clocks are free-running simulator clocks (``add_clock`` on the domains ``free_pix``,
  ``free_cam_a``, ``free_cam_b``) gated by enables (``pix_en``, ``cam_<c>_en``): a clock that is off costs
  one tiny gate evaluation per edge and wakes none of the design. Change an enable only while its free clock is
  low (:func:`enable_clock` does) so the gated clock has no runt pulse.

``sync`` is clocked by the simulator directly. Every port of :class:`SystemBench` is reached through this
bench's ``bench`` attribute (the camera pins are driven here). Measured: a full-size end-to-end frame in
6,424 s instead of 3-3.5 hours (see README.md, the full-size figures). Clock domains: ``sync``, ``pix``,
``cam_a``, ``cam_b`` (those of the system) and the three free-running ones. Latency: the gates are
combinational; the replay as :class:`SensorReplay` says.
"""

from amaranth import ClockDomain, ClockSignal, Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In

from hdl.system import CAMERAS
from sim.sensor_replay import SensorReplay
from sim.system_bench import SystemBench

__all__ = ["AmaranthFastBench", "GATED_DOMAINS", "enable_clock"]

#: The domains whose clocks are gated (free-running clock domain ``free_<name>`` each).
GATED_DOMAINS = ("pix", *(f"cam_{c}" for c in CAMERAS))


class _ClockGate(wiring.Component):
    """``clk`` = the free-running clock of ``free_domain`` while ``en`` is high. Its own module, so an edge of the
    free clock wakes only this one assignment. Combinational."""

    def __init__(self, free_domain, clk):
        self._free_domain = free_domain
        self._clk = clk
        super().__init__({"en": In(1)})

    def elaborate(self, platform):
        m = Module()
        m.d.comb += self._clk.eq(ClockSignal(self._free_domain) & self.en)
        return m


class _PinForward(wiring.Component):
    """The replay's outputs onto the bench's camera pins (its own module, woken only by the pins' changes)."""

    def __init__(self, replay, data, lv, fv):
        self._pairs = ((data, replay.data), (lv, replay.lv), (fv, replay.fv))
        super().__init__({})

    def elaborate(self, platform):
        m = Module()
        m.d.comb += [pin.eq(source) for pin, source in self._pairs]
        return m


class AmaranthFastBench(wiring.Component):
    """See the module docstring. ``replay_words``: ``{camera: ROM words}`` (:func:`sim.sensor_replay.stream_words`
    of each camera's stream); ``system_kwargs`` go to :class:`SystemBench`. Ports: ``pix_en``; per camera
    ``cam_<c>_en`` (its PCLK) and ``cam_<c>_run`` (the replay; its position is ``replays[c].index``)."""

    def __init__(self, *, replay_words, **system_kwargs):
        if set(replay_words) != set(CAMERAS):
            raise ValueError(f"replay_words needs one ROM per camera {CAMERAS}, got {sorted(replay_words)}")
        self.bench = SystemBench(define_domains=False, **system_kwargs)
        self.replays = {c: SensorReplay(replay_words[c], domain=f"cam_{c}") for c in CAMERAS}
        members = {"pix_en": In(1)}
        for c in CAMERAS:
            members.update({f"cam_{c}_en": In(1), f"cam_{c}_run": In(1)})
        super().__init__(members)
        self.domains = {name: ClockDomain(f"free_{name}", reset_less=True) for name in GATED_DOMAINS}

    def gated_clock(self, name):
        """The simulator's free-running clock domain behind gated domain ``name``."""
        return self.domains[name]

    def elaborate(self, platform):
        m = Module()
        m.domains += list(self.domains.values())
        m.submodules.bench = bench = self.bench
        m.domains += bench.sim_system.clocking.domains        # here: the replays use the camera domains too
        domains = {cd.name: cd for cd in bench.sim_system.clocking.domains}
        for name in GATED_DOMAINS:
            m.submodules[f"gate_{name}"] = gate = _ClockGate(f"free_{name}", domains[name].clk)
            m.d.comb += gate.en.eq(getattr(self, f"{name}_en"))
        for c in CAMERAS:
            replay = self.replays[c]
            m.submodules[f"replay_{c}"] = replay
            m.submodules[f"pins_{c}"] = _PinForward(replay, getattr(bench, f"cam_{c}_data"),
                                                    getattr(bench, f"cam_{c}_lv"), getattr(bench, f"cam_{c}_fv"))
            m.d.comb += replay.run.eq(getattr(self, f"cam_{c}_run"))
        return m


async def enable_clock(ctx, bench, name, on=True):
    """Testbench helper: switch gated domain ``name``'s clock on (or off) while its free clock is low."""
    clk = bench.gated_clock(name).clk
    if ctx.get(clk):
        await ctx.negedge(clk)
    ctx.set(getattr(bench, f"{name}_en"), int(on))
