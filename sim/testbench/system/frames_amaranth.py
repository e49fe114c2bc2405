"""Many camera frames through the whole system in Amaranth's simulator (small size): :func:`run_amaranth_frames`.

The one-frame Python-sensor route (``sim/testbench/system/run_amaranth.py``, :class:`PythonSensors`) with a
:class:`~sim.testbed.sequence.FrameSequence`: each camera's testbench sends the sequence's images, one per
frame period (the sensor model reads its register file at every frame start), then FV low for four display frame
periods, and stops its PCLK. The display is sampled from the first display frame start after the init, one display
frame period at a time, every frame the sink completes handed to ``on_frame`` at once, up to the settled frame
(the first display frame that starts after both captures finished the sequence), as the Verilator route does
(``sim/testbench/system/frames_verilator.py``). Each camera testbench notes the times its capture's ``in_frame``
rises (the frame-start skew) and its ``frame_count`` changes, read once per PCLK.
"""

import time

from amaranth.sim import Simulator

from hdl.system import CAMERAS, I2C_BUSES
from sim.models.ch7301c.hdmi_sink import HdmiSink, amaranth_sink_testbench
from sim.models.i2c.bus import amaranth_target_process
from sim.models.mt9d112.sensor import drive_amaranth
from sim.testbench.system.frames_verilator import DisplayFrame
from sim.testbench.system.result import SystemTimeout
from sim.testbench.system.run_amaranth import ROUTES, _Run

__all__ = ["run_amaranth_frames"]


class _FramesRun(_Run):

    def __init__(self, setup, sequence, on_frame, progress, deadline_s):
        left, right = sequence.pairs[0]
        super().__init__(setup, ROUTES["python"], left, right, progress, deadline_s)
        self.sequence = sequence
        self.on_frame = on_frame or (lambda frame: None)
        self.events = {c: {"frame_start": [], "frame_done": []} for c in CAMERAS}
        self.frames_shown = 0
        self.skew_count, self.hardware_skew = 0, []

    def _note_skew(self, ctx):
        """A new measurement of the design's skew meter (read once per camera A PCLK)."""
        meter = self.top.skew
        count = ctx.get(meter.count)
        if count != self.skew_count:
            self.skew_count = count
            self.hardware_skew.append({"t_s": ctx.get(self.top.cycles) / self.setup.sys_hz,
                                       "skew_sync_clocks": ctx.get(meter.skew), "aligned": bool(ctx.get(meter.aligned))})

    def camera(self, c, seed):
        async def testbench(ctx):
            model = self.models[f"cam_{c}"][0]
            sensor = self.setup.sensor(model, seed=seed)
            status = getattr(self.top.capture, f"cam_{c}")
            await self.until_configured(ctx, model)
            last = [0, 0]
            events = self.events[c]
            cycles, sys_hz = self.top.cycles, self.setup.sys_hz

            def on_sample(ctx):
                if c == "a":
                    self._note_skew(ctx)
                in_frame, count = ctx.get(status.in_frame), ctx.get(status.frame_count)
                if in_frame != last[0] or count != last[1]:
                    now = ctx.get(cycles) / sys_hz
                    if in_frame and not last[0]:
                        events["frame_start"].append(now)
                    if count != last[1]:
                        events["frame_done"].append(now)
                    last[:] = in_frame, count

            def chunks():
                yield from sensor.frames(self.sequence.images(c), tail=False, max_idle=10)
                tail_s = 4 * self.setup.timing.clocks_per_frame / self.setup.timing.pixel_hz
                line = sensor.timing.line_time(self.setup.geometry.width)
                yield sensor.blank(max(1, round(tail_s * self.setup.pclk_hz / line)))
            self.samples[c] = await drive_amaranth(
                ctx, chunks(), clk=self.domains[f"cam_{c}"].clk, pins=getattr(self.top, f"cam_{c}"),
                pclk_hz=self.setup.camera_pclk_hz(c), start_delay=self.setup.cam_phase_s.get(c, 0.0),
                on_sample=on_sample)
        return testbench

    async def controller(self, ctx):
        await self.reset(ctx)
        if await self.init(ctx):
            await self.frames(ctx)

    async def frames(self, ctx):
        self.report("frames", 0.0)
        top, n = self.top, len(self.sequence)
        await ctx.tick("pix").until(top.frame_start)
        h_idle = 0 if self.setup.timing.hsync_positive else 1
        while ctx.get(top.ch7301c.hsync) != h_idle:
            await ctx.tick("pix")
        self.status["disparity"] = ctx.get(top.settings.disparity)
        self.status["rectification"] = ctx.get(top.settings.rectification)
        t0 = ctx.get(top.cycles) / self.setup.sys_hz
        self.status["t_display_start_s"] = t0
        clocks = self.setup.timing.clocks_per_frame
        period_s = clocks / self.setup.timing.pixel_hz
        shown = []
        self.sink = HdmiSink(self.setup.timing, keep_frames=1,
                             on_frame=lambda index, frame: shown.append((index, frame.copy())))
        limit = 3 * n + 12
        settled = None
        for chunk in range(limit):
            await amaranth_sink_testbench(self.sink, top.ch7301c, clocks)(ctx)
            for k, frame in shown:
                start = t0 + k * period_s
                captured = {c: sum(1 for t in self.events[c]["frame_done"] if t <= start) for c in CAMERAS}
                self.on_frame(DisplayFrame(k, frame, start, captured))
                self.frames_shown += 1
            shown.clear()
            self.report("frames", min(0.99, self.frames_shown / (2 * n + 2)))
            if settled is None and all(len(self.events[c]["frame_done"]) >= n for c in CAMERAS):
                end = max(self.events[c]["frame_done"][n - 1] for c in CAMERAS)
                settled = -int(-(end - t0) // period_s)
            if settled is not None and self.frames_shown > settled:
                break
        else:
            raise SystemTimeout(f"the captures did not complete {n} frames within {limit} display frames")
        self.status["display_frames"] = self.frames_shown
        self.status["settled_frame"] = settled
        self.status["violations"] = [str(v) for v in self.sink.violations]
        self.status["t_end_s"] = ctx.get(top.cycles) / self.setup.sys_hz
        self.status["capture_events_s"] = self.events
        self.status["hardware_skew"] = self.hardware_skew
        self.report("done", 1.0)

    def simulate(self):
        sim = Simulator(self.top)
        self.route.add_clocks(self, sim)
        for bus in I2C_BUSES:
            sim.add_process(amaranth_target_process(getattr(self.top.bus, bus), self.models[bus],
                                                    self.setup.sys_hz, self.top.cycles, self.monitors[bus]))
        for seed, c in enumerate(CAMERAS):
            sim.add_testbench(self.camera(c, seed), background=True)
        sim.add_testbench(self.controller)
        sim.run()


def run_amaranth_frames(sequence, setup, *, on_frame=None, progress=None, deadline_s=None):
    """Simulate ``sequence`` through the whole system in Amaranth's simulator (small size; see the module
    docstring); ``on_frame(DisplayFrame)`` for each display frame. Returns the status (as
    :func:`sim.testbench.system.frames_verilator.run_verilator_frames`)."""
    if setup.preset != "small":
        raise ValueError("the Amaranth multi-frame route runs the small preset")
    run = _FramesRun(setup, sequence, on_frame, progress, deadline_s)
    wall = time.perf_counter()
    run.simulate()
    run.status["wall_s"] = time.perf_counter() - wall
    run.status["frames_in"] = len(sequence)
    return run.status
