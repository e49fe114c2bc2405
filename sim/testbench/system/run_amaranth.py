"""The whole system in Amaranth's simulator: :class:`AmaranthRun`, the Amaranth backend's driver.

It simulates a :class:`sim.testbench.system.setup.SystemSetup` through a *route* (how the cameras and the clocks
are driven), every clock at its real frequency (``sync`` 100 MHz, ``pix`` from the video timing, each camera's
PCLK from its sensor model). Its controller testbench runs the phases
(:func:`sim.testbench.system.phases.phases`: reset, I2C init, capture, display frames) with the driver's primitives
in Amaranth's terms: ``ctx.delay`` and ``ctx.tick``, a wait polling every :data:`POLL_S` step of what it waits for.
Each sensor streams its image once its register file says RGB565 and streaming (see
``sim/testbench/system/setup.py`` for this shortcut), the same image every frame; a sequence's sensors send its
images, one per frame period, then FV low for four display frame periods. The HDMI sink model
(``sim.models.ch7301c.hdmi_sink``) samples the CH7301C pins one display frame period at a time; a background
testbench notes each capture's frame starts and ends and the design's skew meter as they change. The check phase
(after the simulation): :func:`sim.testbench.system.result.record_parts`; the display frames' verdict is the run's
(:mod:`sim.system.verdict`).

Routes (:data:`ROUTES`): :class:`PythonSensors` drives each camera's pins from the sensor model in a testbench, per
PCLK (:class:`sim.testbench.system.testbench.SystemTestbench`); :class:`ReplayedSensors` replays each camera's
frame-period stream of a still pair from a ROM inside the simulated design and gates free-running simulator clocks
(:class:`sim.testbench.system.rom_testbench.RomReplayTestbench`): the full-resolution route.
"""

import time

from amaranth.sim import Simulator

from hdl.system import CAMERAS, I2C_BUSES
from sim.waves.gtkw import recording
from sim.models.mig import READ_LATENCY_RANGE, draw_latency, watch_violations
from spec.memory import MIG
from sim.models.ch7301c.hdmi_sink import amaranth_sink_testbench
from sim.models.i2c.bus import amaranth_target_process
from sim.models.i2c.monitor import I2CBusMonitor
from sim.models.mt9d112.sensor import drive_amaranth
from sim.models.mt9d112.config import expected_sensor_config
from sim.replay.sensor import pack_stream
from sim.testbench.system.phases import CAPTURE, INIT, LOCK, display_limit, phases
from sim.testbench.system.testbench import SystemTestbench
from sim.testbench.system.result import DisplayFrames, sent_frames, SystemTimeout, record_parts
from sim.testbench.system.rom_testbench import GATED_DOMAINS, RomReplayTestbench, enable_clock

__all__ = ["AmaranthRoute", "PythonSensors", "ReplayedSensors", "ROUTES", "AmaranthRun"]

#: The controller's polling step while it waits (``until``), by what it waits for; 1 us otherwise.
POLL_S = {LOCK: 50e-9, INIT: 2e-6, CAPTURE: 1e-6, "pixel-domain reset release": 20e-9}


class AmaranthRoute:
    """How a route builds the design and drives its cameras and clocks. A route is stateless; ``run`` is the
    :class:`AmaranthRun` in progress."""

    name = None
    #: Whether the route sends a sequence of images (not only a still pair's, for ever).
    sequences = False

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
    sequences = True

    def design(self, run):
        return SystemTestbench(**run.setup.system_kwargs())

    def add_clocks(self, run, sim):
        sim.add_clock(1 / run.setup.sys_hz, domain="sync")
        if run.pix_running:
            sim.add_clock(run.pix_period, domain="pix")
        else:
            sim.add_testbench(run.pix_clock, background=True)
        if "mem" in run.domains:
            sim.add_clock(1 / MIG.CLK0_HZ, domain="mem")

    async def start_pix(self, run, ctx):
        run.pix_running = True

    def camera(self, run, c, seed):
        async def testbench(ctx):
            model = run.models[f"cam_{c}"][0]
            sensor = run.setup.sensor(model, seed=seed)
            await run.until_configured(ctx, model)
            run.samples[c] = await drive_amaranth(
                ctx, run.camera_chunks(sensor, c), clk=run.domains[f"cam_{c}"].clk,
                pins=getattr(run.top, f"cam_{c}"), pclk_hz=run.setup.camera_pclk_hz(c),
                start_delay=run.setup.cam_phase_s.get(c, 0.0))
        return testbench


class ReplayedSensors(AmaranthRoute):
    """Each camera's frame-period stream of a still pair, made before the run for the spec's configuration
    (:func:`sim.models.mt9d112.config.expected_sensor_config`), replayed from a ROM in the design; gated simulator
    clocks. A :class:`~sim.testbench.system.result.SystemTimeout` is raised if the I2C init configures a
    register-file model to anything else."""

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


class AmaranthRun:
    """One run of ``sequence`` along ``route`` in progress: the models, the sink, the status, and the primitives of the
    phases (see the module docstring). ``on_frame(DisplayFrame)`` receives each display frame (a still pair's run
    ends when it returns True, or after ``max_frames``); ``progress(stage, fraction)``."""

    def __init__(self, setup, sequence, *, route=ROUTES["python"], on_frame=None, progress=None, deadline_s=None,
                 max_frames=1):
        self.still = bool(getattr(sequence, "still", False))
        if not (self.still or route.sequences):
            raise ValueError(f"the Amaranth {route.name} route replays a still pair only")
        self.setup, self.route, self.sequence = setup, route, sequence
        self.images = {c: setup.fit(sequence.images(c)[0]) for c in CAMERAS}
        self.on_frame = on_frame or (lambda frame: None)
        self.max_frames = max_frames
        self.report = progress or (lambda stage, fraction: None)
        self.deadline = deadline_s if deadline_s is not None else setup.deadline_s()
        self.pix_period = 1 / setup.timing.pixel_hz
        self.pix_running = not setup.pix_after_init
        self.models = setup.i2c_models()
        self.monitors = {bus: I2CBusMonitor() for bus in I2C_BUSES}
        self.sink, self.ctx = None, None       # the display phase's sink; the controller's context
        self.frames = DisplayFrames(setup, CAMERAS, sent_frames(sequence, CAMERAS))
        self.status, self.samples, self.replay_started = {}, {c: 0 for c in CAMERAS}, {}
        self.top = route.design(self)
        self.domains = {cd.name: cd for cd in self.top.domains}

    # --- helpers ------------------------------------------------------------------------------------------------

    def camera_chunks(self, sensor, c):
        """What camera ``c``'s sensor sends: a still pair's image every frame period for ever, or the sequence's
        images one per frame period, then FV low for four display frame periods."""
        if self.still:
            yield from sensor.frames([self.images[c]] * 1_000_000, tail=False, max_idle=10)
            return
        images = [self.setup.fit(image) for image in self.sequence.images(c)]
        yield from sensor.frames(images, tail=False, max_idle=10)
        tail_s = 4 * self.setup.timing.clocks_per_frame / self.setup.timing.pixel_hz
        line = sensor.timing.line_time(self.setup.geometry.width)
        yield sensor.blank(max(1, round(tail_s * self.setup.pclk_hz / line)))

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

    async def watch_captures(self, ctx):
        """Note each capture's frame starts and ends and the skew meter's measurements as they change."""
        captures = [getattr(self.top.capture, f"cam_{c}") for c in CAMERAS]
        signals = [s for status in captures for s in (status.in_frame, status.frame_count)] + [self.top.skew.count]
        last = [0] * len(signals)
        async for values in ctx.changed(*signals):
            now = ctx.get(self.top.cycles) / self.setup.sys_hz
            for i, c in enumerate(CAMERAS):
                in_frame, count = values[2 * i], values[2 * i + 1]
                self.frames.note_capture(c, now, in_frame and not last[2 * i], count != last[2 * i + 1])
            if values[-1] != last[-1]:
                meter = self.top.skew
                self.frames.note_skew(now, ctx.get(meter.skew), bool(ctx.get(meter.aligned)))
            last = list(values)

    # --- the primitives of the phases (sim.testbench.system.phases), the controller's ------------------------------

    async def controller(self, ctx):
        self.ctx = ctx
        self.sink = await phases(self, self.setup, still=self.still, frames=self.frames, on_frame=self.on_frame,
                                 max_frames=self.max_frames, deadline_s=self.deadline,
                                 limit_frames=display_limit(self.setup, self.sequence, self.max_frames, self.deadline),
                                 status=self.status)

    def button(self, pressed):
        self.ctx.set(self.top.button, int(pressed))

    async def start_pix(self):
        if not self.pix_running:
            await self.route.start_pix(self, self.ctx)

    async def pix_out_of_reset(self):
        await self.until("pixel-domain reset release", lambda: not self.ctx.get(self.domains["pix"].rst),
                         self.deadline)

    async def advance(self, seconds):
        await self.ctx.delay(seconds)

    async def advance_pix(self, clocks):
        await self.ctx.delay(clocks * self.pix_period)

    async def until(self, what, condition, timeout_s):
        """Poll ``condition`` every :data:`POLL_S` step of ``what``."""
        step, waited = POLL_S.get(what, 1e-6), 0.0
        while not condition():
            if waited > timeout_s:
                raise SystemTimeout(f"{what} did not happen within {timeout_s * 1e3:.3f} ms of simulated time")
            await self.ctx.delay(step)
            waited += step

    def set_switches(self, word):
        self.ctx.set(self.top.panel.sw, word)

    def now(self):
        return self.ctx.get(self.top.cycles) / self.setup.sys_hz    # sync clocks counted since time 0

    def locked(self):
        return bool(self.ctx.get(self.top.locked))

    def init_flags(self):
        return {b: (self.ctx.get(getattr(self.top.init, b).done), self.ctx.get(getattr(self.top.init, b).error))
                for b in I2C_BUSES}

    def frame_counts(self):
        return {c: self.ctx.get(getattr(self.top.capture, f"cam_{c}").frame_count) for c in CAMERAS}

    def frames_ok(self):
        return {c: self.ctx.get(getattr(self.top.capture, f"cam_{c}").frame_ok) for c in CAMERAS}

    def settings(self):
        """The switch settings and the automatic rectification's state the design shows now."""
        ctx, top = self.ctx, self.top
        return {"disparity": ctx.get(top.settings.disparity), "rectification": ctx.get(top.settings.rectification),
                "auto_rectification": {n: ctx.get(getattr(top.rectification, n))
                                       for n in ("auto", "confident", "held", "locked")}}

    def panel(self):
        ctx, top = self.ctx, self.top
        out = {"leds": ctx.get(top.panel.leds),
               "drive_high": {b: bool(ctx.get(getattr(top.bus, b).drive_high)) for b in I2C_BUSES}}
        if "display_missed" in top.signature.members:     # the DDR2 build: display reads the frame store refused
            out["display_missed"] = ctx.get(top.display_missed)
        return out

    def progress(self, stage):
        self.report(stage, 1.0 if stage == "done" else min(0.999, self.now() / self.setup.expected_sim_time_s()))

    async def display_frame_start(self):
        ctx, top = self.ctx, self.top
        await ctx.tick("pix").until(top.frame_start)
        h_idle = 0 if self.setup.timing.hsync_positive else 1
        while ctx.get(top.ch7301c.hsync) != h_idle:
            await ctx.tick("pix")

    async def display_frame(self, sink, clocks):
        await amaranth_sink_testbench(sink, self.top.ch7301c, clocks)(self.ctx)

    # --- the simulation -------------------------------------------------------------------------------------

    def run(self, vcd=None, gtkw=None, traces=()):
        """Simulate (with ``vcd``, a VCD of the whole run and a GTKWave save file ``gtkw`` showing ``traces``: a
        :class:`sim.waves.gtkw.Waves`, a dict of groups, or a function of the simulated design returning one);
        returns the status."""
        wall = time.perf_counter()
        sim = Simulator(self.top)                # elaborates the design (and builds the replay ROMs)
        self.route.add_clocks(self, sim)
        for bus in I2C_BUSES:
            sim.add_process(amaranth_target_process(getattr(self.top.bus, bus), self.models[bus],
                                                    self.setup.sys_hz, self.top.cycles, self.monitors[bus]))
        for seed, c in enumerate(CAMERAS):
            sim.add_testbench(self.route.camera(self, c, seed), background=True)
        sim.add_testbench(self.watch_captures, background=True)
        if "memory" in self.top.signature.members:        # the DDR2 build: the MIG model's latency and checker
            latency = draw_latency(0, READ_LATENCY_RANGE)
            self.status["mig_latency"] = latency

            async def set_latency(ctx):
                ctx.set(self.top.memory.latency, latency)
            sim.add_testbench(set_latency)
            sim.add_testbench(watch_violations(self.top.memory), background=True)
        sim.add_testbench(self.controller)
        if vcd is None:
            sim.run()
        else:
            with recording(sim, vcd, gtkw, traces(self.top) if callable(traces) else traces):
                sim.run()
        for c, start in self.replay_started.items():     # samples replayed: the PCLK periods since the start
            self.samples[c] = round((self.status.get("t_end_s", start) - start) * self.setup.pclk_hz)
        self.status["wall_s"] = time.perf_counter() - wall
        return self.status

    def check(self):
        """The driver's check phase (:func:`record_parts`); returns the status."""
        record_parts(self.status, self.models, self.monitors)
        return self.status
