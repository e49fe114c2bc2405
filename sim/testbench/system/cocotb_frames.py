"""The multi-frame scenario inside a cocotb simulation (Verilator or Icarus), small size, Python models route.

:func:`frames_end_to_end` runs the reset and init phases of ``sim/testbench/system/cocotb_scenario.py``; then each
camera is driven by its sensor model (``drive_cocotb``) with the sequence's images, one per frame period, then FV
low for four display frame periods; the CH7301C pins are sampled by one :class:`CocotbSink` from the first display
frame start on, every frame the HDMI sink completes kept, up to the settled frame (the first display frame that
starts after both captures finished), as on the other simulators (``sim/testbench/system/frames_verilator.py``).
Each camera's driver notes, once per PCLK, its capture's ``in_frame`` rises and ``frame_count`` changes, and camera
A's the design's skew meter.

Parameters (``sim.runners.cocotb.test_params()``): ``setup``, ``route`` (``python``), ``sequence`` (an ``.npz`` of
``left`` and ``right``, N x H x W x 3), ``out_dir`` (``frames.npz``: the display frames and their start times;
``result.json``: the status).
"""

import json
import time
from pathlib import Path

import cocotb
import numpy as np
from cocotb.triggers import RisingEdge, Timer

from hdl.system import CAMERAS, I2C_BUSES
from sim.models.ch7301c.hdmi_sink import CocotbSink, HdmiSink
from sim.models.i2c.monitor import I2CBusMonitor
from sim.models.mt9d112.sensor import drive_cocotb
from sim.runners.cocotb import TopPorts
from sim.testbench.system.cocotb_routes import period_ps, route_from_spec
from sim.testbench.system.cocotb_scenario import _now_s, _Run
from sim.testbench.system.setup import SystemSetup

__all__ = ["frames_end_to_end"]


class _FramesRun(_Run):

    def __init__(self, dut, params):              # the one-pair run's members, with a sequence of pairs
        self.ports = TopPorts(dut)
        self.setup = SystemSetup.from_spec(params["setup"])
        self.route = route_from_spec(params["route"])
        self.out_dir = Path(params["out_dir"])
        self.progress_file = None
        with np.load(params["sequence"]) as npz:
            self.sequence = {"a": list(npz["left"]), "b": list(npz["right"])}
        self.deadline = self.setup.deadline_s()
        self.status = {"route": self.route.spec()}
        self.phase_wall, self.wall0 = {}, time.perf_counter()
        self.stage, self.running = "I2C-init", True
        self.models = self.setup.i2c_models()
        self.monitors = {bus: I2CBusMonitor() for bus in I2C_BUSES}
        self.replay_checks = {}
        self.events = {c: {"frame_start": [], "frame_done": []} for c in CAMERAS}
        self.hardware_skew = []

    async def camera(self, c, seed):
        model = self.models[f"cam_{c}"][0]
        while not model.sensor_config().rgb565:
            await Timer(1000, unit="ns")
        sensor = self.setup.sensor(model, seed=seed)
        status, meter = getattr(self.ports.capture, f"cam_{c}"), self.ports.skew
        last, events = [0, 0, 0], self.events[c]

        def on_sample():
            in_frame, count = int(status.in_frame.value), int(status.frame_count.value)
            if in_frame and not last[0]:
                events["frame_start"].append(_now_s())
            if count != last[1]:
                events["frame_done"].append(_now_s())
            last[0], last[1] = in_frame, count
            if c == "a" and int(meter.count.value) != last[2]:
                last[2] = int(meter.count.value)
                self.hardware_skew.append({"t_s": _now_s(), "skew_sync_clocks": meter.skew.value.to_signed(),
                                           "aligned": bool(int(meter.aligned.value))})

        def chunks():
            yield from sensor.frames(self.sequence[c], tail=False, max_idle=10)
            tail_s = 4 * self.setup.timing.clocks_per_frame / self.setup.timing.pixel_hz
            line = sensor.timing.line_time(self.setup.geometry.width)
            yield sensor.blank(max(1, round(tail_s * self.setup.pclk_hz / line)))
        await drive_cocotb(chunks(), clk=getattr(self.ports.clocks, f"cam_{c}"), pins=getattr(self.ports, f"cam_{c}"),
                           pclk_hz=self.setup.camera_pclk_hz(c), start_delay=self.setup.cam_phase_s.get(c, 0.0),
                           on_sample=on_sample)

    async def frames(self):
        ports, setup, n = self.ports, self.setup, len(self.sequence["a"])
        await RisingEdge(ports.frame_start)
        h_idle = 0 if setup.timing.hsync_positive else 1
        while int(ports.ch7301c.hsync.value) != h_idle:
            await RisingEdge(ports.clocks.pix)
        t0 = _now_s()
        period_s = setup.timing.clocks_per_frame / setup.timing.pixel_hz
        shown = []
        sink = HdmiSink(setup.timing, keep_frames=1, on_frame=lambda index, frame: shown.append(frame.copy()))
        cocotb.start_soon(CocotbSink(ports.ch7301c, sink, period_ps=period_ps(setup.timing.pixel_hz, 4))
                          .run(10 ** 9))
        settled = None
        for _ in range(3 * n + 12):
            await Timer(round(period_s * 1e12), unit="ps")
            if settled is None and all(len(self.events[c]["frame_done"]) >= n for c in CAMERAS):
                end = max(self.events[c]["frame_done"][n - 1] for c in CAMERAS)
                settled = -int(-(end - t0) // period_s)
            if settled is not None and len(shown) > settled:
                break
        else:
            raise AssertionError(f"the captures did not complete {n} frames in time")
        self.status.update(display_frames=len(shown), settled_frame=settled, t_display_start_s=t0,
                           violations=[str(v) for v in sink.violations], capture_events_s=self.events,
                           hardware_skew=self.hardware_skew, t_end_s=_now_s(),
                           wall_s=time.perf_counter() - self.wall0)
        self.out_dir.mkdir(parents=True, exist_ok=True)
        np.savez(self.out_dir / "frames.npz", frames=np.stack(shown),
                 t_start_s=t0 + period_s * np.arange(len(shown)))
        (self.out_dir / "result.json").write_text(json.dumps(self.status, indent=1, default=str))


async def frames_end_to_end(dut, params):
    """Reset, init, then the frames (see the module docstring)."""
    run = _FramesRun(dut, params)
    await run.reset()
    await run.init()
    await run.frames()
