"""The whole system end to end in Amaranth's simulator: stereo pair in, rebuilt HDMI frame out.

:func:`run_amaranth` simulates a :class:`sim.testbench.system.setup.SystemSetup` through a *route* (how the cameras and the
clocks are driven), every clock at its real frequency (``sync`` 100 MHz, ``pix`` from the video timing, each
camera's PCLK from its sensor model), in the phases a reader can follow in :meth:`_Run.controller`:

1. **reset**: the reset button is pressed and released; the clocking model locks and releases the domain resets;
2. **init**: the RTL's three init sequencers configure the two MT9D112 register-file models and the CH7301C model
   over their I2C buses (``sim.models``, time from the ``cycles`` counter); then the pixel clock starts (with
   ``setup.pix_after_init``) and the switches are set: SW7 = 1 with the disparity, then SW7 = 0 with the
   rectification;
3. **capture**: each sensor streams its image once its register file says RGB565 and streaming (see
   ``sim/testbench/system/setup.py`` for this shortcut), the same image every frame, until both captures complete a frame;
4. **display**: the HDMI sink model (``sim.models.ch7301c.hdmi_sink``) samples the CH7301C pins from the next display frame start
   for one whole frame and rebuilds it;
5. **check** (after the simulation): :func:`sim.testbench.system.result.check_run` against the golden frame.

Routes (:data:`ROUTES`): :class:`PythonSensors` drives each camera's pins from the sensor model in a testbench, per
PCLK (:class:`sim.testbench.system.testbench.SystemTestbench`); :class:`ReplayedSensors` replays each camera's frame-period stream
from a ROM inside the simulated design and gates free-running simulator clocks
(:class:`sim.testbench.system.rom_testbench.RomReplayTestbench`): the full-resolution route.
"""

import time

from amaranth.sim import Simulator

from hdl.system import CAMERAS, DISPLAY_LATENCY, I2C_BUSES
from sim.waves.gtkw import recording
from sim.models.ch7301c.hdmi_sink import HdmiSink, amaranth_sink_testbench
from sim.models.i2c.bus import amaranth_target_process
from sim.models.i2c.monitor import I2CBusMonitor
from sim.models.mt9d112.sensor import drive_amaranth
from sim.models.mt9d112.config import expected_sensor_config
from sim.replay.sensor import pack_stream
from sim.testbench.system.testbench import SystemTestbench
from sim.testbench.system.result import SystemResult, SystemTimeout, check_run
from sim.testbench.system.rom_testbench import GATED_DOMAINS, RomReplayTestbench, enable_clock

__all__ = ["AmaranthRoute", "PythonSensors", "ReplayedSensors", "ROUTES", "run_amaranth"]


class AmaranthRoute:
    """How a route builds the design and drives its cameras and clocks. A route is stateless; ``run`` is the
    :class:`_Run` in progress."""

    name = None

    def design(self, run):
        """The component to simulate; it has :class:`~sim.testbench.system.testbench.SystemTestbench`'s members."""
        raise NotImplementedError

    def add_clocks(self, run, sim):
        """Add the simulator clocks and the clock testbenches."""
        raise NotImplementedError

    async def start_pix(self, run, ctx):
        """Start the pixel clock (with ``setup.pix_after_init``, once the I2C init is done)."""
        raise NotImplementedError

    def camera(self, run, c, seed):
        """The testbench that drives camera ``c`` once its register file is configured."""
        raise NotImplementedError


class PythonSensors(AmaranthRoute):
    """Each camera's pins driven from its sensor model by a testbench, one await per PCLK edge."""

    name = "python"

    def design(self, run):
        return SystemTestbench(**run.setup.system_kwargs())

    def add_clocks(self, run, sim):
        sim.add_clock(1 / run.setup.sys_hz, domain="sync")
        if run.pix_running:
            sim.add_clock(run.pix_period, domain="pix")
        else:
            sim.add_testbench(run.pix_clock, background=True)

    async def start_pix(self, run, ctx):
        run.pix_running = True

    def camera(self, run, c, seed):
        async def testbench(ctx):
            model = run.models[f"cam_{c}"][0]
            sensor = run.setup.sensor(model, seed=seed)
            await run.until_configured(ctx, model)
            run.samples[c] = await drive_amaranth(
                ctx, sensor.frames([run.images[c]] * 1_000_000, tail=False, max_idle=10),
                clk=run.domains[f"cam_{c}"].clk, pins=getattr(run.top, f"cam_{c}"),
                pclk_hz=run.setup.camera_pclk_hz(c),
                start_delay=run.setup.cam_phase_s.get(c, 0.0))
        return testbench


class ReplayedSensors(AmaranthRoute):
    """Each camera's frame-period stream, made before the run for the spec's configuration
    (:func:`sim.models.mt9d112.config.expected_sensor_config`), replayed from a ROM in the design; gated simulator clocks.
    A :class:`~sim.testbench.system.result.SystemTimeout` is raised if the I2C init configures a register-file model to
    anything else."""

    name = "replay"

    def design(self, run):
        run.expected_config = expected_sensor_config(run.setup.geometry)
        words = {c: pack_stream(run.setup.sensor(run.expected_config, seed=seed).frame(run.images[c])).tolist()
                 for seed, c in enumerate(CAMERAS)}
        return RomReplayTestbench(replay_words=words, **run.setup.system_kwargs())

    def add_clocks(self, run, sim):
        sim.add_clock(1 / run.setup.sys_hz, domain="sync")
        periods = {"pix": run.pix_period, **{f"cam_{c}": 1 / run.setup.pclk_hz for c in CAMERAS}}
        for name in GATED_DOMAINS:
            sim.add_clock(periods[name], domain=run.top.free_domains[name])
        if run.pix_running:                     # the pixel clock runs from time 0
            async def start(ctx):
                await enable_clock(ctx, run.top, "pix")
            sim.add_testbench(start)

    async def start_pix(self, run, ctx):
        await enable_clock(ctx, run.top, "pix")
        run.pix_running = True

    def camera(self, run, c, seed):
        async def testbench(ctx):
            model = run.models[f"cam_{c}"][0]
            await run.until_configured(ctx, model)
            if model.sensor_config() != run.expected_config:
                raise SystemTimeout(f"camera {c}: the I2C init configured {model.sensor_config()}; the replay ROM "
                                    f"holds the sensor model's stream for {run.expected_config}")
            await ctx.delay(run.setup.cam_phase_s.get(c, 0.0) or 0.0)
            run.replay_started[c] = ctx.get(run.top.cycles) / run.setup.sys_hz
            ctx.set(getattr(run.top.replay_run, f"cam_{c}"), 1)
            await enable_clock(ctx, run.top, f"cam_{c}")
        return testbench


#: The Amaranth routes by name.
ROUTES = {route.name: route for route in (PythonSensors(), ReplayedSensors())}


class _Run:
    """One run in progress: the models, the sink, the status, and the phases (see the module docstring)."""

    def __init__(self, setup, route, left, right, progress, deadline_s):
        self.setup, self.route = setup, route
        self.images = {"a": left, "b": right}
        self.report = progress or (lambda stage, fraction: None)
        self.deadline = deadline_s if deadline_s is not None else setup.deadline_s()
        self.pix_period = 1 / setup.timing.pixel_hz
        self.pix_running = not setup.pix_after_init
        self.models = setup.i2c_models()
        self.monitors = {bus: I2CBusMonitor() for bus in I2C_BUSES}
        self.sink = HdmiSink(setup.timing)
        self.status, self.samples, self.replay_started = {}, {c: 0 for c in CAMERAS}, {}
        self.elapsed = 0.0                      # simulated time the controller has waited for
        self.top = route.design(self)
        self.domains = {cd.name: cd for cd in self.top.domains}

    # --- helpers ------------------------------------------------------------------------------------------------

    async def wait_for(self, ctx, what, cond, step=1e-6):
        while not cond():
            if self.elapsed > self.deadline:
                raise SystemTimeout(f"{what} did not happen within {self.deadline * 1e3:.3f} ms of simulated time")
            await ctx.delay(step)
            self.elapsed += step

    @staticmethod
    async def until_configured(ctx, model):
        while not model.sensor_config().rgb565:
            await ctx.delay(1e-6)

    async def pix_clock(self, ctx):
        """The pixel clock toggled by a testbench, from the moment the init phase starts it."""
        clk, half = self.domains["pix"].clk, self.pix_period / 2
        while not self.pix_running:
            await ctx.delay(100e-9)
        while True:
            ctx.set(clk, 1)
            await ctx.delay(half)
            ctx.set(clk, 0)
            await ctx.delay(half)

    # --- the phases -----------------------------------------------------------------------------------------

    async def controller(self, ctx):
        await self.reset(ctx)
        if await self.init(ctx):
            await self.capture(ctx)
            await self.display(ctx)

    async def reset(self, ctx):
        ctx.set(self.top.button, 1)
        await ctx.delay(50e-9)
        ctx.set(self.top.button, 0)
        self.elapsed = 50e-9
        await self.wait_for(ctx, "clock lock", lambda: ctx.get(self.top.locked), step=50e-9)

    async def init(self, ctx):
        """The I2C init; then the pixel clock and the switches. False if a bus failed (the caller reports it)."""
        self.report("i2c", 0.0)
        init = self.top.init
        buses = {b: getattr(init, b) for b in I2C_BUSES}
        await self.wait_for(ctx, "I2C initialisation",
                            lambda: all(ctx.get(s.done) or ctx.get(s.error) for s in buses.values()), step=2e-6)
        for b, s in buses.items():
            self.status[f"{b}_init_done"] = bool(ctx.get(s.done))
            self.status[f"{b}_init_error"] = bool(ctx.get(s.error))
        self.status["t_init_s"] = self.elapsed
        if not all(self.status[f"{b}_init_done"] for b in I2C_BUSES):
            return False
        if not self.pix_running:
            await self.route.start_pix(self, ctx)
        # The switches: disparity (SW7 = 1) then rectification (SW7 = 0), each held for 30 pixel clocks (more
        # than the synchroniser and the pending register need); the next frame_start loads both.
        await self.wait_for(ctx, "pixel-domain reset release", lambda: not ctx.get(self.domains["pix"].rst),
                            step=20e-9)
        for word in self.setup.switch_words():
            ctx.set(self.top.panel.sw, word)
            await ctx.delay(30 * self.pix_period)
        return True

    async def capture(self, ctx):
        self.report("capture", 0.0)
        status = {c: getattr(self.top.capture, f"cam_{c}") for c in CAMERAS}
        counts0 = {c: ctx.get(s.frame_count) for c, s in status.items()}
        await self.wait_for(ctx, "a complete camera frame from both sensors",
                            lambda: all(ctx.get(s.frame_count) != counts0[c] for c, s in status.items()))
        for c, s in status.items():
            self.status[f"cam_{c}_frame_ok"] = bool(ctx.get(s.frame_ok))
        self.status["t_captured_s"] = self.elapsed

    async def display(self, ctx):
        self.report("display", 0.0)
        top = self.top
        await ctx.tick("pix").until(top.frame_start)
        # Start sampling outside an hsync pulse (the pins lag the raster by DISPLAY_LATENCY clocks, which can put
        # them inside the previous line's pulse): the sink must see whole pulses.
        h_idle = 0 if self.setup.timing.hsync_positive else 1
        while ctx.get(top.ch7301c.hsync) != h_idle:
            await ctx.tick("pix")
        self.status["disparity"] = ctx.get(top.settings.disparity)
        self.status["rectification"] = ctx.get(top.settings.rectification)
        self.status["auto_rectification"] = {n: ctx.get(getattr(top.rectification, n))
                                             for n in ("auto", "confident", "held", "locked")}
        clocks = self.setup.timing.clocks_per_frame + DISPLAY_LATENCY + 2
        await amaranth_sink_testbench(self.sink, top.ch7301c, clocks)(ctx)
        self.status["leds"] = ctx.get(top.panel.leds)
        self.status["drive_high"] = {b: bool(ctx.get(getattr(top.bus, b).drive_high)) for b in I2C_BUSES}
        self.status["t_end_s"] = ctx.get(top.cycles) / self.setup.sys_hz    # sync clocks counted since time 0
        for c, start in self.replay_started.items():     # samples replayed: the PCLK periods since the start
            self.samples[c] = round((self.status["t_end_s"] - start) * self.setup.pclk_hz)
        self.report("done", 1.0)

    # --- the simulation -------------------------------------------------------------------------------------

    def simulate(self, vcd, gtkw, traces):
        sim = Simulator(self.top)                # elaborates the design (and builds the replay ROMs)
        self.route.add_clocks(self, sim)
        for bus in I2C_BUSES:
            sim.add_process(amaranth_target_process(getattr(self.top.bus, bus), self.models[bus],
                                                    self.setup.sys_hz, self.top.cycles, self.monitors[bus]))
        for seed, c in enumerate(CAMERAS):
            sim.add_testbench(self.route.camera(self, c, seed), background=True)
        sim.add_testbench(self.controller)
        if vcd is None:
            sim.run()
            return
        with recording(sim, vcd, gtkw, traces(self.top) if callable(traces) else traces):
            sim.run()


def run_amaranth(left, right, setup, *, route=ROUTES["python"], vcd=None, gtkw=None, traces=(), progress=None,
                 deadline_s=None):
    """Simulate the pair ``left``/``right`` (RGB arrays, any size: fitted to the sensor) through the whole system
    along ``route`` (an :class:`AmaranthRoute`); see the module docstring. Returns a
    :class:`~sim.testbench.system.result.SystemResult` (with ``sink``, ``models``, ``monitors``).

    ``progress(stage, fraction)`` is called at each phase. Raises :class:`~sim.testbench.system.result.SystemTimeout` when a
    phase does not complete within ``deadline_s`` of simulated time (default: ``setup.deadline_s()``). With
    ``vcd``, a VCD of the whole run and a GTKWave save file (``gtkw``) showing ``traces`` (a
    :class:`sim.waves.gtkw.Waves` or a dict of groups, or a function of the simulated design returning one, e.g.
    :func:`sim.testbench.system.waves.system_waves`) are written."""
    t_setup = time.perf_counter()
    left, right = setup.fit(left), setup.fit(right)
    run = _Run(setup, route, left, right, progress, deadline_s)
    t_sim = time.perf_counter()
    run.simulate(vcd, gtkw, traces)
    wall = time.perf_counter() - t_sim
    frame, golden = check_run(run.status, setup, left, right, run.sink, run.models, run.monitors)
    figures = {
        "wall_s": wall,                          # the simulation
        "setup_s": t_sim - t_setup,              # fitting the images, streams, design
        "cam_samples": dict(run.samples),
        "display_clocks_sampled": run.sink.clock,
        "t_init_s": run.status.get("t_init_s"),
        "t_captured_s": run.status.get("t_captured_s"),
    }
    return SystemResult(frame=frame, golden=golden, status=run.status, figures=figures, sink=run.sink,
                        models=run.models, monitors=run.monitors)
