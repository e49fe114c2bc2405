"""The capture path (:class:`hdl.capture_path.CapturePath`) driven from the sensor models and read back.

* :func:`run_capture_amaranth`: in Amaranth's simulator, each camera driven by :func:`sim.models.mt9d112.sensor.drive_amaranth`,
  every write recorded (:class:`CaptureRecord`), then each buffer read back through its read port.
* :func:`run_capture_cocotb`: the same in cocotb on an exported capture path (:func:`sim.models.mt9d112.sensor.drive_cocotb`).
* :func:`playback_design` / :func:`run_playback_cocotb`: the exported path with a ``sensor_replay`` module
  (``sim/replay/sensor.py``) beside each camera, so a whole frame runs without Python per PCLK; the same design
  (one build) also takes the Python drivers through its pins.

The cocotb functions reach the exported top's ports through ``sim.runners.cocotb.TopPorts``; the clocks are the
ports Amaranth makes for the domains the path uses (``cam_<c>_clk``, ``cam_<c>_rst``, ``pix_clk``, ``pix_rst``).
"""

import hashlib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from amaranth import ClockDomain, ClockSignal, Elaboratable, Instance, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.capture_path import CapturePath, CapturePortSignature
from board.export import export_verilog
from spec.board import CLOCKS
from sim.runners import build_dir
from sim.runners.cocotb import TopPorts
from sim.waves.gtkw import recording
from sim.models.mt9d112.sensor import drive_amaranth, drive_cocotb
from sim.replay.sensor import REPLAY_VERILOG, pack_stream, write_hex

__all__ = ["CaptureRecord", "run_capture_amaranth", "run_capture_cocotb", "playback_design", "run_playback_cocotb"]


@dataclass
class CaptureRecord:
    """What one camera's capture did: every committed write ``(address, grey)`` in order, ``frame_ok`` at
    every ``frame_done`` strobe, the number of PCLK samples sent, and when (the index of the sample whose rising
    edge ends the clock, :meth:`observe`'s call count) each write and each ``row_start`` / ``row_end`` strobe
    was: ``write_cycles``, ``rows`` (``("start" | "end", cycle)``)."""
    writes: list = field(default_factory=list)
    frames: list = field(default_factory=list)
    samples: int = 0
    write_cycles: list = field(default_factory=list)
    rows: list = field(default_factory=list)
    cycle: int = 0

    def observe(self, read, write, status):
        """Record one PCLK period's ``write`` port and capture ``status``, each value read with ``read(signal)``
        (and only when it counts: per-sample reads are what a simulation pays for)."""
        if read(write.en):
            self.writes.append((read(write.addr), read(write.data)))
            self.write_cycles.append(self.cycle)
        if read(status.frame_done):
            self.frames.append(bool(read(status.frame_ok)))
        if read(status.row_start):
            self.rows.append(("start", self.cycle))
        if read(status.row_end):
            self.rows.append(("end", self.cycle))
        self.cycle += 1


def _cocotb_value(handle):
    return int(handle.value)


def _per_camera(value, cameras, default):
    if isinstance(value, dict):
        return {c: value.get(c, default) for c in cameras}
    return {c: (default if value is None else value) for c in cameras}


class _CaptureTestbench(Elaboratable):
    """The capture path with its domains defined (Amaranth's simulator)."""

    def __init__(self, path):
        self.path = path
        self.cam = {c: ClockDomain(f"cam_{c}") for c in path.cameras}
        self.pix = ClockDomain(path.read_domain)

    def elaborate(self, platform):
        m = Module()
        m.domains += [*self.cam.values(), self.pix]
        m.submodules.path = self.path
        return m


def run_capture_amaranth(path, streams, *, pclk_hz=CLOCKS.CAM_MCLK_HZ, start_delay=0.0, read=True,
                         pix_hz=CLOCKS.PIXEL_HZ, vcd=None):
    """Simulate ``path`` (a :class:`hdl.capture_path.CapturePath`) in Amaranth's simulator.

    ``streams``: ``{camera: SensorStream or iterable of chunks}``; the cameras run concurrently, each on its
    own PCLK (``pclk_hz`` and ``start_delay``: a value, or a dict per camera). Every write port is recorded
    (:class:`CaptureRecord`). With ``read``, once every stream has been sent, each camera's buffer is read back
    through its ``pix`` read port at ``pix_hz`` (the pix clock runs only then: the read port is idle before).
    Returns ``(records, buffers)``: dicts per camera; buffers are uint8 ``(buf_height, buf_width)``.
    """
    from amaranth.sim import Simulator

    cameras = list(streams)
    pclk = _per_camera(pclk_hz, cameras, CLOCKS.CAM_MCLK_HZ)
    delay = _per_camera(start_delay, cameras, 0.0)
    testbench = _CaptureTestbench(path)
    records = {c: CaptureRecord() for c in cameras}
    done = {c: Signal(name=f"stream_{c}_done") for c in cameras}
    buffers = {}
    sim = Simulator(testbench)
    for c in cameras:
        port = getattr(path, f"cam_{c}")

        async def camera(ctx, c=c, port=port):
            def on_sample(ctx):
                records[c].observe(ctx.get, port.write, port.status)
            records[c].samples = await drive_amaranth(
                ctx, streams[c], clk=testbench.cam[c].clk, pins=port.pins, pclk_hz=pclk[c], start_delay=delay[c],
                on_sample=on_sample)
            ctx.set(done[c], 1)
        sim.add_testbench(camera)

    if read:
        async def reader(ctx):
            for c in cameras:
                if not ctx.get(done[c]):
                    await ctx.posedge(done[c])
            for c in path.cameras:
                buffers[c] = await _read_buffer_amaranth(ctx, getattr(path, f"cam_{c}").read, testbench.pix.clk,
                                                         path.geometry, pix_hz)
        sim.add_testbench(reader)

    if vcd is None:
        sim.run()
    else:
        traces = {}
        for c in cameras:
            port = getattr(path, f"cam_{c}")
            traces[f"camera_{c}"] = [testbench.cam[c].clk, port.pins.fv, port.pins.lv, port.pins.data,
                                     port.status.in_frame, port.write.en, port.write.addr, port.write.data,
                                     port.status.frame_done, port.status.frame_ok, port.status.frame_count]
        with recording(sim, vcd, Path(vcd).with_suffix(".gtkw"), traces):
            sim.run()
    return records, buffers


async def _read_buffer_amaranth(ctx, read, clk, geometry, pix_hz):
    """Every word of a buffer through its read port, the read clock toggled here."""
    half = 0.5 / pix_hz
    values = []
    for addr in range(geometry.buf_depth):
        ctx.set(read.addr, addr)
        ctx.set(clk, 0)
        await ctx.delay(half)
        ctx.set(clk, 1)           # read.data <= memory[addr]
        await ctx.delay(half)
        values.append(ctx.get(read.data))
    return np.array(values, dtype=np.uint8).reshape(geometry.buf_height, geometry.buf_width)


async def run_capture_cocotb(dut, geometry, streams, *, pclk_hz=CLOCKS.CAM_MCLK_HZ, start_delay=0.0,
                             read=True, pix_hz=CLOCKS.PIXEL_HZ, cameras=None):
    """The cocotb counterpart of :func:`run_capture_amaranth` for an exported capture path (``dut``).

    Each camera's PCLK is a GPI clock driven by :func:`sim.models.mt9d112.sensor.drive_cocotb` (which also holds
    ``cam_<c>_rst`` for a few cycles first). ``cameras`` lists all the design's cameras (default: those in
    ``streams``), whose buffers are read back when ``read``, through the pix ports with the pix clock at ``pix_hz``
    (it runs only then, as in :func:`run_capture_amaranth`: the read ports are idle during the capture and every
    pix edge costs simulation time). Returns ``(records, buffers)`` like :func:`run_capture_amaranth`.
    """
    import cocotb

    ports = TopPorts(dut)
    cameras_read = list(cameras or streams)
    cameras = list(streams)
    pclk = _per_camera(pclk_hz, cameras, CLOCKS.CAM_MCLK_HZ)
    delay = _per_camera(start_delay, cameras, 0.0)
    records = {c: CaptureRecord() for c in cameras}
    dut.pix_rst.value = 0
    dut.pix_clk.value = 0
    for c in cameras_read:
        port = getattr(ports, f"cam_{c}")
        for pin in ("data", "lv", "fv"):        # cameras without a stream stay idle, not undriven
            getattr(port.pins, pin).value = 0
        if hasattr(dut, "playback__cam_a__select"):   # a playback_design: the pins, not the replays, drive
            control = getattr(ports.playback, f"cam_{c}")
            control.select.value = 0
            control.run.value = 0

    async def camera(c):
        port = getattr(ports, f"cam_{c}")
        write, status, observe = port.write, port.status, records[c].observe

        def on_sample():
            observe(_cocotb_value, write, status)
        records[c].samples = await drive_cocotb(
            streams[c], clk=getattr(dut, f"cam_{c}_clk"), pins=port.pins, pclk_hz=pclk[c], start_delay=delay[c],
            on_sample=on_sample, reset=getattr(dut, f"cam_{c}_rst"))

    tasks = [cocotb.start_soon(camera(c)) for c in cameras]
    for task in tasks:
        await task
    buffers = await read_buffers_cocotb(dut, cameras_read, geometry, pix_hz) if read else {}
    return records, buffers


async def read_buffers_cocotb(dut, cameras, geometry, pix_hz):
    """Read every camera's frame buffer back through its read port (one clock of latency), with the pixel clock
    running only for the read-back. Returns ``{camera: uint8 (buf_height, buf_width)}``."""
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge
    ports = TopPorts(dut)
    pix_clock = Clock(dut.pix_clk, 2 * round(0.5e12 / pix_hz), unit="ps", impl="gpi")
    pix_clock.start(start_high=False)
    falling = FallingEdge(dut.pix_clk)
    buffers = {}
    for c in cameras:
        read = getattr(ports, f"cam_{c}").read
        values = []
        for addr in range(geometry.buf_depth + 1):
            await falling
            if addr:
                values.append(int(read.data.value))
            if addr < geometry.buf_depth:
                read.addr.value = addr
        buffers[c] = np.array(values, dtype=np.uint8).reshape(geometry.buf_height, geometry.buf_width)
    pix_clock.stop()
    return buffers


# --- Replay (cocotb on Verilator / Icarus: no Python per PCLK cycle) -------------------------------------------

#: How a test controls one camera's replay in a :func:`playback_design`: ``select`` (1: the replay drives the
#: capture's pins, 0: the top-level pins do), ``load`` (rising edge: read the file), ``run`` (play it once),
#: ``done`` (all played).
PlaybackSignature = wiring.Signature({"select": In(1), "load": In(1), "run": In(1), "done": Out(1)})


def _stream_file(stream, directory=None):
    """``stream`` packed into a ``$readmemh`` file named by its content hash (under build/cocotb/playback by
    default); returns ``(path, words)``."""
    words = pack_stream(stream)
    directory = Path(directory) if directory else build_dir("cocotb", "playback")
    path = directory / f"stream-{hashlib.sha256(words.tobytes()).hexdigest()[:16]}.hex"
    if not path.exists():
        write_hex(words, path)
    return path, len(words)


class _CapturePlayback(wiring.Component):
    """A capture path whose cameras are fed by the top-level pins or by a ``sensor_replay`` module each."""

    def __init__(self, geometry, files, r_byte_first):
        self.geometry = geometry
        self.files = files
        self.r_byte_first = r_byte_first
        super().__init__({
            **{f"cam_{c}": Out(CapturePortSignature(geometry)) for c in files},
            "playback": Out(wiring.Signature({f"cam_{c}": Out(PlaybackSignature) for c in files})),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.path = path = CapturePath(self.geometry, cameras=tuple(self.files), r_byte_first=self.r_byte_first)
        for c, (hex_path, depth) in self.files.items():
            for name in ("write", "status", "read"):
                wiring.connect(m, wiring.flipped(getattr(getattr(self, f"cam_{c}"), name)),
                               getattr(path.port(c), name))
            control, outer = getattr(self.playback, f"cam_{c}"), getattr(self, f"cam_{c}").pins
            inner = path.port(c).pins
            data, lv, fv = Signal(8, name=f"replay_{c}_data"), Signal(name=f"replay_{c}_lv"), \
                Signal(name=f"replay_{c}_fv")
            m.submodules[f"replay_{c}"] = Instance(
                "sensor_replay", p_DEPTH=depth, p_FILE=str(hex_path), p_LOOP=0,
                i_pclk=ClockSignal(f"cam_{c}"), i_load=control.load, i_run=control.run, i_length=depth,
                o_d=data, o_lv=lv, o_fv=fv, o_done=control.done, o_index=Signal(32, name=f"replay_{c}_index"))
            m.d.comb += [inner.data.eq(Mux(control.select, data, outer.data)),
                         inner.lv.eq(Mux(control.select, lv, outer.lv)),
                         inner.fv.eq(Mux(control.select, fv, outer.fv))]
        return m


def playback_design(geometry, streams, *, name="capture_path", r_byte_first=True):
    """Verilog text of a capture path whose cameras can be fed either by the Python drivers through the top-level
    pins or by ``sensor_replay`` modules replaying ``streams`` (``{camera: SensorStream}``, pauses not replayed),
    for cocotb on Verilator or Icarus. One design (one build) serves both.

    Top-level ports: every port of the :class:`~hdl.capture_path.CapturePath` plus, per camera ``c``,
    ``playback.cam_<c>`` (:data:`PlaybackSignature`). The frame-buffer memories get the compact initialisation of
    ``board.export``."""
    files = {c: _stream_file(s) for c, s in streams.items()}
    return export_verilog(_CapturePlayback(geometry, files, r_byte_first), name) + REPLAY_VERILOG


async def run_playback_cocotb(dut, geometry, cameras, *, pclk_hz=CLOCKS.CAM_MCLK_HZ, start_delay=0.0,
                              pix_hz=CLOCKS.PIXEL_HZ, poll=10e-6):
    """Run a :func:`playback_design`: start each camera's PCLK (GPI clock, phase ``start_delay``), hold its
    reset for 4 cycles, start the replay, wait (polling every ``poll`` seconds of simulated time) until every
    camera is done, then read the buffers back through pix. Returns ``(status, buffers)``: per camera
    ``{"frame_count", "frame_ok"}`` and the uint8 buffers."""
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, Timer

    ports = TopPorts(dut)
    pclk = _per_camera(pclk_hz, cameras, CLOCKS.CAM_MCLK_HZ)
    delay = _per_camera(start_delay, cameras, 0.0)
    control = {c: getattr(ports.playback, f"cam_{c}") for c in cameras}
    dut.pix_rst.value = 0
    dut.pix_clk.value = 0
    clocks = {}
    for c in cameras:
        getattr(dut, f"cam_{c}_rst").value = 1
        getattr(dut, f"cam_{c}_clk").value = 0
        control[c].run.value = 0
        control[c].select.value = 1
        control[c].load.value = 0
    elapsed = 0.0
    for c in sorted(cameras, key=lambda c: delay[c]):
        if delay[c] > elapsed:
            await Timer(round((delay[c] - elapsed) * 1e12), unit="ps")
            elapsed = delay[c]
        clocks[c] = Clock(getattr(dut, f"cam_{c}_clk"), 2 * round(0.5e12 / pclk[c]), unit="ps", impl="gpi")
        clocks[c].start(start_high=False)
    for c in cameras:
        control[c].load.value = 1               # rising edge: the replay reads its file
        falling = FallingEdge(getattr(dut, f"cam_{c}_clk"))
        for _ in range(4):
            await falling
        getattr(dut, f"cam_{c}_rst").value = 0
        control[c].run.value = 1
    while not all(int(control[c].done.value) for c in cameras):
        await Timer(round(poll * 1e12), unit="ps")
    for c in cameras:                               # let the capture pipelines drain
        falling = FallingEdge(getattr(dut, f"cam_{c}_clk"))
        for _ in range(8):
            await falling
    status = {c: {"frame_count": int(getattr(ports, f"cam_{c}").status.frame_count.value),
                  "frame_ok": bool(getattr(ports, f"cam_{c}").status.frame_ok.value)} for c in cameras}
    for clock in clocks.values():
        clock.stop()
    return status, await read_buffers_cocotb(dut, cameras, geometry, pix_hz)
