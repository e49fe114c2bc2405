"""Run the whole system end to end in Amaranth's simulator: stereo pair in, rebuilt HDMI frame out.

:func:`run_amaranth` builds a :class:`sim.system_bench.SystemBench` for a :class:`sim.system_setup.SystemSetup`
and simulates, with every clock at its real frequency (``sync`` 100 MHz, ``pix`` from the video timing, each
camera's PCLK from its sensor model):

1. the reset button is pressed and released; the clocking model locks and releases the domain resets;
2. the switches are set: SW7 = 1 with the disparity, then SW7 = 0 with the rectification;
3. the RTL's three init sequencers configure the two MT9D112 register-file models and the CH7301C model over
   their I2C buses (``sim.i2c_devices``, time from the ``cycles`` counter);
4. each sensor model (``sim.mt9d112``) starts streaming its image once its register file says RGB565 and
   streaming (see ``sim/system_setup.py`` for this shortcut), repeating the same image every frame: driven from
   a testbench per PCLK (``sensors="python"``), or its frame-period stream replayed from a ROM in the simulated
   design (``sensors="replay"``, :mod:`sim.system_amaranth_fast`: the full-resolution route);
5. once both captures have completed a frame with ``frame_ok``, the HDMI sink model (``sim.hdmi_sink``) samples
   the CH7301C pins from the next display frame start for one whole frame and rebuilds it.

The result carries the rebuilt frame, the golden frame (``golden.disparity.composite_frame`` of
``golden.capture.capture_frame`` of each image), the sink (timing violations), the device models (what was
written over I2C) and figures (simulated time, wall time, clocks per domain).
"""

import time
from dataclasses import dataclass, field

import numpy as np

from sim.hdmi_sink import HdmiSink, amaranth_sink_testbench
from sim.i2c_devices import I2CBusMonitor, amaranth_target_process
from sim.mt9d112 import drive_amaranth
from sim.system_bench import SystemBench
from hdl.system import CAMERAS, DISPLAY_LATENCY, I2C_BUSES

__all__ = ["SystemResult", "SystemTimeout", "run_amaranth"]


class SystemTimeout(AssertionError):
    """The simulation did not reach a stage in the allowed simulated time."""


@dataclass
class SystemResult:
    frame: np.ndarray
    golden: np.ndarray
    sink: object
    models: dict
    monitors: dict
    status: dict = field(default_factory=dict)
    figures: dict = field(default_factory=dict)

    @property
    def mismatched_pixels(self):
        if self.frame is None:
            return None
        return int(np.any(self.frame != self.golden, axis=-1).sum())


def _deadline_s(setup):
    """Simulated-time budget: the I2C init (table waits + bus time, generously) plus a few frames."""
    from hdl.init_tables import Poll, Wait
    table = setup.cam_table
    waits = sum(e.us for e in table.entries if isinstance(e, Wait)) * 1e-6
    polls = sum(e.interval_us * 4 for e in table.entries if isinstance(e, Poll)) * 1e-6
    bus = len(table.entries) * 12 * 9 / setup.i2c_hz
    cam_frame = (setup.geometry.height + 20) * (2 * setup.geometry.width + 400) / setup.pclk_hz
    display_frame = setup.timing.clocks_per_frame / setup.timing.pixel_hz
    return 2 * (waits + polls + bus) + 4 * cam_frame + 4 * display_frame + 1e-3


def run_amaranth(left, right, setup, *, sensors="python", vcd=None, gtkw=None, traces=(), progress=None,
                 deadline_s=None):
    """Simulate the pair ``left``/``right`` (RGB arrays, any size) through the whole system; see the module
    docstring. ``progress(stage, fraction)`` is called as the run advances. Raises :class:`SystemTimeout`
    when a stage does not complete within ``deadline_s`` of simulated time (default: an estimate).

    ``sensors``: ``"python"`` drives each camera's pins from the sensor model in a testbench, per PCLK;
    ``"replay"`` uses :class:`sim.system_amaranth_fast.AmaranthFastBench` (the model's frame-period stream
    replayed from a ROM, gated simulator clocks: the full-resolution route; the stream is made before the run for
    ``sim.i2c_expected.expected_sensor_config`` and a :class:`SystemTimeout` is raised if the I2C init
    configures a register-file model to anything else).

    ``setup.pix_after_init`` starts the pixel clock once the I2C init is done (see ``sim/system_setup.py``).
    With ``vcd``, a VCD of the whole run and a GTKWave save file (``gtkw``) showing ``traces`` (a
    :class:`sim.gtkw.Waves` or a dict of groups, or a function of the :class:`sim.system_bench.SystemBench`
    returning one) are written."""
    from amaranth.sim import Simulator

    if sensors not in ("python", "replay"):
        raise ValueError(f"sensors must be 'python' or 'replay', not {sensors!r}")
    t_setup = time.perf_counter()
    left, right = setup.fit(left), setup.fit(right)
    images = {"a": left, "b": right}
    replay = sensors == "replay"
    if replay:
        from sim.i2c_expected import expected_sensor_config
        from sim.sensor_replay import stream_words
        from sim.system_amaranth_fast import GATED_DOMAINS, AmaranthFastBench, enable_clock
        expected_cfg = expected_sensor_config(setup.geometry)
        words = {c: stream_words(setup.sensor(expected_cfg, seed=seed).frame(images[c]))
                 for seed, c in enumerate(CAMERAS)}
        top = AmaranthFastBench(replay_words=words, **setup.system_kwargs())
        bench = top.bench
    else:
        top = bench = SystemBench(**setup.system_kwargs())
    models = setup.i2c_models()
    monitors = {bus: I2CBusMonitor() for bus in I2C_BUSES}
    sink = HdmiSink(setup.timing)
    clk_domains = {cd.name: cd for cd in bench.sim_system.clocking.domains}
    deadline = deadline_s if deadline_s is not None else _deadline_s(setup)
    status = {}
    report = progress or (lambda stage, fraction: None)
    sim = Simulator(top)                        # elaborates the design (and builds the replay ROMs)
    t_wall = time.perf_counter()
    sim.add_clock(1 / setup.sys_hz, domain="sync")
    pix_period = 1 / setup.timing.pixel_hz
    pix_from_start = not setup.pix_after_init
    if replay:
        periods = {"pix": pix_period, **{f"cam_{c}": 1 / setup.pclk_hz for c in CAMERAS}}
        for name in GATED_DOMAINS:
            sim.add_clock(periods[name], domain=top.gated_clock(name))
    elif pix_from_start:
        sim.add_clock(pix_period, domain="pix")
    pix_run = [pix_from_start]

    async def start_pix(ctx):
        if replay:
            await enable_clock(ctx, top, "pix")
        pix_run[0] = True

    async def pix_clock(ctx):
        clk = clk_domains["pix"].clk
        half = pix_period / 2
        while not pix_run[0]:
            await ctx.delay(100e-9)
        while True:
            ctx.set(clk, 1)
            await ctx.delay(half)
            ctx.set(clk, 0)
            await ctx.delay(half)
    if not pix_from_start and not replay:
        sim.add_testbench(pix_clock, background=True)
    for bus in I2C_BUSES:
        sim.add_process(amaranth_target_process(bench, bus, models[bus], setup.sys_hz, monitors[bus]))

    samples = {c: 0 for c in CAMERAS}
    replay_started = {}

    for seed, c in enumerate(CAMERAS):
        async def replay_camera(ctx, c=c):
            model = models[f"cam_{c}"][0]
            while not model.sensor_config().rgb565:
                await ctx.delay(1e-6)
            if model.sensor_config() != expected_cfg:
                raise SystemTimeout(f"camera {c}: the I2C init configured {model.sensor_config()}; the replay ROM "
                                    f"holds the sensor model's stream for {expected_cfg}")
            await ctx.delay(setup.cam_phase_s.get(c, 0.0) or 0.0)
            replay_started[c] = ctx.get(bench.cycles) / setup.sys_hz
            ctx.set(getattr(top, f"cam_{c}_run"), 1)
            await enable_clock(ctx, top, f"cam_{c}")

        async def camera(ctx, c=c, seed=seed):
            model = models[f"cam_{c}"][0]
            sensor = setup.sensor(model, seed=seed)
            while not model.sensor_config().rgb565:
                await ctx.delay(1e-6)
            samples[c] = await drive_amaranth(
                ctx, sensor.frames([images[c]] * 1_000_000, tail=False, max_idle=10),
                clk=clk_domains[f"cam_{c}"].clk, data=getattr(bench, f"cam_{c}_data"),
                lv=getattr(bench, f"cam_{c}_lv"), fv=getattr(bench, f"cam_{c}_fv"),
                pclk_hz=setup.pclk_hz, start_delay=setup.cam_phase_s.get(c, 0.0))
        sim.add_testbench(replay_camera if replay else camera, background=True)

    async def wait_for(ctx, what, cond, step=1e-6):
        while not cond():
            if ctx_time[0] > deadline:
                raise SystemTimeout(f"{what} did not happen within {deadline * 1e3:.3f} ms of simulated time")
            await ctx.delay(step)
            ctx_time[0] += step

    ctx_time = [0.0]

    async def controller(ctx):
        get = ctx.get
        ctx.set(bench.button, 1)
        await ctx.delay(50e-9)
        ctx.set(bench.button, 0)
        ctx_time[0] = 50e-9
        await wait_for(ctx, "clock lock", lambda: get(bench.locked), step=50e-9)
        report("i2c", 0.0)

        def init_finished():
            return all(get(getattr(bench, f"{b}_init_done")) or get(getattr(bench, f"{b}_init_error"))
                       for b in I2C_BUSES)
        await wait_for(ctx, "I2C initialisation", init_finished, step=2e-6)
        for b in I2C_BUSES:
            status[f"{b}_init_done"] = bool(get(getattr(bench, f"{b}_init_done")))
            status[f"{b}_init_error"] = bool(get(getattr(bench, f"{b}_init_error")))
        status["t_init_s"] = ctx_time[0]
        if not all(status[f"{b}_init_done"] for b in I2C_BUSES):
            return                                  # the caller reports which bus failed
        await start_pix(ctx)
        # The switches: disparity (SW7 = 1) then rectification (SW7 = 0), each held for 30 pixel clocks (more
        # than the synchroniser and the pending register need); the next frame_start loads both.
        await wait_for(ctx, "pixel-domain reset release", lambda: not get(clk_domains["pix"].rst), step=20e-9)
        for word in setup.switch_words():
            ctx.set(bench.sw, word)
            await ctx.delay(30 * pix_period)
        report("capture", 0.0)

        counts0 = {c: get(getattr(bench, f"cam_{c}_frame_count")) for c in CAMERAS}

        def captured():
            return all(get(getattr(bench, f"cam_{c}_frame_count")) != counts0[c] for c in CAMERAS)
        await wait_for(ctx, "a complete camera frame from both sensors", captured, step=1e-6)
        for c in CAMERAS:
            status[f"cam_{c}_frame_ok"] = bool(get(getattr(bench, f"cam_{c}_frame_ok")))
        status["t_captured_s"] = ctx_time[0]
        report("display", 0.0)

        await ctx.tick("pix").until(bench.frame_start)
        # Start sampling outside an hsync pulse (the pins lag the raster by DISPLAY_LATENCY clocks, which can
        # put them inside the previous line's pulse): the sink must see whole pulses.
        h_idle = 0 if setup.timing.hsync_positive else 1
        while get(bench.hsync) != h_idle:
            await ctx.tick("pix")
        status["disparity"] = get(bench.disparity)
        status["rectification"] = get(bench.rectification)
        clocks = setup.timing.clocks_per_frame + DISPLAY_LATENCY + 2
        await amaranth_sink_testbench(sink, bench, clocks)(ctx)
        status["leds"] = get(bench.leds)
        status["drive_high"] = {b: bool(get(getattr(bench, f"{b}_drive_high"))) for b in I2C_BUSES}
        status["t_end_s"] = get(bench.cycles) / setup.sys_hz      # the sync clocks counted since time 0
        for c in replay_started:                 # samples replayed: the PCLK periods since the replay started
            samples[c] = round((status["t_end_s"] - replay_started[c]) * setup.pclk_hz)
        report("done", 1.0)

    sim.add_testbench(controller)
    if callable(traces):
        traces = traces(bench)
    if vcd is not None:
        from sim.gtkw import recording
        with recording(sim, vcd, gtkw, traces):
            sim.run()
    else:
        sim.run()
    wall = time.perf_counter() - t_wall

    frame = sink.frames[0] if sink.frames else None
    sim_time = sink_time = None
    figures = {
        "wall_s": wall,                          # the simulation
        "setup_s": t_wall - t_setup,             # fitting the images, streams, elaboration
        "cam_samples": dict(samples),
        "display_clocks_sampled": sink.clock if hasattr(sink, "clock") else None,
        "t_init_s": status.get("t_init_s"),
        "t_captured_s": status.get("t_captured_s"),
    }
    del sim_time, sink_time
    return SystemResult(frame=frame, golden=setup.golden_frame(left, right), sink=sink, models=models,
                        monitors=monitors, status=status, figures=figures)
