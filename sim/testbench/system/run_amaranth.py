"""The whole system in Amaranth's simulator: :class:`AmaranthRun`, the Amaranth backend's driver.

It simulates a :class:`sim.testbench.system.setup.SystemSetup` through a *route* (how the cameras and the clocks
are driven), every clock at its real frequency (``sync`` 100 MHz, ``pix`` from the video timing, each camera's
PCLK from its sensor model), in the phases a reader can follow in :meth:`AmaranthRun.controller`:

1. **reset**: the reset button is pressed and released; the clocking model locks and releases the domain resets;
2. **init**: the RTL's three init sequencers configure the two MT9D112 register-file models and the CH7301C model
   over their I2C buses (``sim.models``, time from the ``cycles`` counter); then the pixel clock starts (with
   ``setup.pix_after_init``) and the switches are set: SW7 = 1 with the disparity, then SW7 = 0 with the
   rectification;
3. **capture** (a still pair): each sensor streams its image once its register file says RGB565 and streaming
   (see ``sim/testbench/system/setup.py`` for this shortcut), the same image every frame, until both captures
   complete a frame; a sequence's sensors send its images, one per frame period, then FV low for four display
   frame periods;
4. **display**: the HDMI sink model (``sim.models.ch7301c.hdmi_sink``) samples the CH7301C pins from the next
   display frame start, one display frame period at a time, each frame it completes handed on as a
   :class:`~sim.testbench.system.result.DisplayFrame` (the bookkeeping of
   :class:`~sim.testbench.system.result.DisplayFrames`: a sequence up to its settled frame, a still pair until
   ``on_frame`` returns True or ``max_frames``); a background testbench notes each capture's frame starts and ends
   and the design's skew meter as they change;
5. **check** (after the simulation): :func:`sim.testbench.system.result.record_parts`; the display frames' verdict
   is the run's (:mod:`sim.system.verdict`).

Routes (:data:`ROUTES`): :class:`PythonSensors` drives each camera's pins from the sensor model in a testbench, per
PCLK (:class:`sim.testbench.system.testbench.SystemTestbench`); :class:`ReplayedSensors` replays each camera's
frame-period stream of a still pair from a ROM inside the simulated design and gates free-running simulator clocks
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
from sim.testbench.system.result import DisplayFrames, sent_frames, SystemTimeout, record_parts
from sim.testbench.system.rom_testbench import GATED_DOMAINS, RomReplayTestbench, enable_clock

__all__ = ["AmaranthRoute", "PythonSensors", "ReplayedSensors", "ROUTES", "AmaranthRun"]


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
    """One run of ``sequence`` along ``route`` in progress: the models, the sink, the status, and the phases (see
    the module docstring). ``on_frame(DisplayFrame)`` receives each display frame (a still pair's run ends when it
    returns True, or after ``max_frames``); ``progress(stage, fraction)``."""

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
        self.sink = HdmiSink(setup.timing, keep_frames=1)
        self.frames = DisplayFrames(setup, CAMERAS, sent_frames(sequence, CAMERAS))
        self.status, self.samples, self.replay_started = {}, {c: 0 for c in CAMERAS}, {}
        self.elapsed = 0.0                      # simulated time the controller has waited for
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

    def settings(self, ctx):
        """The switch settings and the automatic rectification's state the design shows now."""
        top = self.top
        return {"disparity": ctx.get(top.settings.disparity), "rectification": ctx.get(top.settings.rectification),
                "auto_rectification": {n: ctx.get(getattr(top.rectification, n))
                                       for n in ("auto", "confident", "held", "locked")}}

    # --- the phases -----------------------------------------------------------------------------------------

    async def controller(self, ctx):
        await self.reset(ctx)
        if await self.init(ctx):
            if self.still:
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
        self.report("capture", 0.5)
        status = {c: getattr(self.top.capture, f"cam_{c}") for c in CAMERAS}
        counts0 = {c: ctx.get(s.frame_count) for c, s in status.items()}
        await self.wait_for(ctx, "a complete camera frame from both sensors",
                            lambda: all(ctx.get(s.frame_count) != counts0[c] for c, s in status.items()))
        for c, s in status.items():
            self.status[f"cam_{c}_frame_ok"] = bool(ctx.get(s.frame_ok))
        self.status["t_captured_s"] = self.elapsed

    async def display(self, ctx):
        self.report("display", 0.8 if self.still else 0.0)
        top, sink = self.top, self.sink
        await ctx.tick("pix").until(top.frame_start)
        # Start sampling outside an hsync pulse (the pins lag the raster by DISPLAY_LATENCY clocks, which can put
        # them inside the previous line's pulse): the sink must see whole pulses.
        h_idle = 0 if self.setup.timing.hsync_positive else 1
        while ctx.get(top.ch7301c.hsync) != h_idle:
            await ctx.tick("pix")
        self.status.update(self.settings(ctx))
        clocks = self.setup.timing.clocks_per_frame
        self.frames.start(ctx.get(top.cycles) / self.setup.sys_hz, clocks / self.setup.timing.pixel_hz)
        limit = self.max_frames + 1 if self.still else 3 * len(self.sequence) + 12
        recorded = 0
        for chunk in range(limit):
            settings, before = self.settings(ctx), sink.frames_completed
            # The first chunk holds a display frame and the pins' latency: the sink completes frame k in chunk k.
            sampled = clocks + (DISPLAY_LATENCY + 2 if not chunk else 0)
            await amaranth_sink_testbench(sink, top.ch7301c, sampled)(ctx)
            recorded += sampled
            enough = any([self.frames.completed(self.on_frame, sink.frames[-1].copy(), settings)
                          for _ in range(before, sink.frames_completed)])
            done = (chunk + 1) / limit
            self.report("display", min(0.99, 0.8 + 0.2 * done if self.still else done))
            if self.frames.finished(enough, self.max_frames):
                break
        else:
            raise SystemTimeout(self.frames.overdue())
        self.status["recorded_clocks"] = recorded
        self.status["violations"] = [str(v) for v in sink.violations]
        self.status["leds"] = ctx.get(top.panel.leds)
        self.status["drive_high"] = {b: bool(ctx.get(getattr(top.bus, b).drive_high)) for b in I2C_BUSES}
        self.status["t_end_s"] = ctx.get(top.cycles) / self.setup.sys_hz    # sync clocks counted since time 0
        self.status.update(self.frames.record())
        for c, start in self.replay_started.items():     # samples replayed: the PCLK periods since the start
            self.samples[c] = round((self.status["t_end_s"] - start) * self.setup.pclk_hz)
        self.report("done", 1.0)

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
        sim.add_testbench(self.controller)
        if vcd is None:
            sim.run()
        else:
            with recording(sim, vcd, gtkw, traces(self.top) if callable(traces) else traces):
                sim.run()
        self.status["wall_s"] = time.perf_counter() - wall
        return self.status

    def check(self):
        """The driver's check phase (:func:`record_parts`); returns the status."""
        record_parts(self.status, self.models, self.monitors)
        return self.status
