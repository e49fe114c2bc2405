"""Model of an Aptina MT9D112's parallel video output (one camera of the VmodCAM): image in, PCLK/FV/LV/D[7:0] out.

Pure-Python core
----------------
:class:`MT9D112` turns an image into :class:`SensorStream` chunks: one sample per PCLK rising edge
(``fv``, ``lv``, ``data`` as uint8 NumPy arrays) plus ``pauses`` (PCLK held low for a while before some
samples). A chunk is one frame period: the vertical blanking (FV low), then the frame::

    FV  __|‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾‾|____
    LV  ______|‾‾‾‾2W bytes‾‾‾|__h_blank__|‾‾‾‾2W bytes‾‾‾|__|______
           frame_start                          ...    frame_end

* Two bytes per pixel, RGB565, in the configured byte order: the "R byte" R[4:0] G[5:3] and the "G byte"
  G[2:0] B[4:0] (``SensorConfig.r_byte_first``, default R byte first). An 8-bit RGB image is packed by
  truncation: R5 = R8 >> 3, G6 = G8 >> 2, B5 = B8 >> 3 (:func:`golden.capture.rgb888_to_rgb565`).
* During blanking the data bus carries pseudo-random bytes (seeded), so a capture that samples D outside
  LV shows up in the tests.
* The sensor is configured through ``config``: a :class:`sim.models.mt9d112.config.SensorConfig` or any object with
  a ``sensor_config()`` method returning one (the I2C register-file model, ``sim/models/{i2c,mt9d112,ch7301c}/``). It is
  read at the start of every frame period, like a real sensor applies new settings at a frame boundary.
  While ``rgb565`` is False the sensor outputs nothing: FV and LV stay low for the whole frame period.
* Resolution: the configured ``width`` x ``height`` (1600 x 1200 by default). An RGB image of another
  size is centre-cropped and resized to it (:func:`golden.stereo_pair.fit_to_sensor`), as the sensor's
  scaler would frame the scene; an RGB565 image must have the configured size.

Blanking (:class:`SensorTiming`, all in PCLK periods) is a parameter. The MT9D112's own figures depend on its
PLL and context registers, which the thesis does not give; the defaults follow the sibling Micron sensors'
datasheets (frame start/end blanking of 6 PCLKs, a few hundred PCLKs of horizontal blanking, several blank
rows between frames). See docs/capture.md "Sensor model" for the sources and the choice.

Fault injection (:class:`Faults`, per frame) for the robustness tests: lines with another byte count (short,
long, odd), extra lines, FV dropped mid-frame, LV pulses without FV in the blanking, PCLK pauses.

Drivers
-------
* :func:`drive_amaranth`: an Amaranth-simulator testbench coroutine that owns the camera's PCLK (it toggles
  the domain's clock signal, so PCLK can pause) and drives D/LV/FV on the falling edge.
* :func:`drive_cocotb`: the same for cocotb: a GPI clock on the PCLK pin (stopped and restarted for a pause)
  and D/LV/FV written on the falling edge.

Both take an iterable of chunks, which may be a generator (:meth:`MT9D112.frames`): the next chunk is built
when the previous one has been sent, so a configuration written over I2C during the simulation takes effect
at the next frame boundary. Both can call ``on_sample`` once per PCLK period, just before the rising edge
(all registered outputs of the design are stable then): the tests use it to record the write port.

For speed, a precomputed stream can be replayed inside the simulator instead (``sim/replay/sensor.py``); the
capture path's testbench (``sim/testbench/capture.py``) and the whole-system routes (``sim/testbench/system/``) use it.
"""

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from golden.capture import rgb565_to_bytes, to_rgb565
from golden.image_file import ImageFileError, read_image
from golden.stereo_pair import fit_to_sensor
from spec.board import CLOCKS
from sim import UserError
from sim.models.mt9d112.config import SensorConfig

__all__ = ["SensorTiming", "SENSOR_TIMING", "SMALL_SENSOR_TIMING", "Faults", "SensorStream", "MT9D112",
           "drive_amaranth", "drive_cocotb", "image_to_bytes", "fault_cases"]


@dataclass(frozen=True)
class SensorTiming:
    """Output blanking in PCLK periods (see docs/capture.md "Sensor model")."""
    h_blank: int = 256          # LV low between two lines (FV high)
    v_blank_lines: int = 8      # FV low between frames, in line times (2 * width + h_blank)
    frame_start: int = 6        # FV rising edge -> first LV rising edge
    frame_end: int = 6          # last LV falling edge -> FV falling edge

    def __post_init__(self):
        for name in ("h_blank", "v_blank_lines", "frame_start", "frame_end"):
            if getattr(self, name) < 0:
                raise ValueError(f"{name} must not be negative")

    def line_time(self, width):
        return 2 * width + self.h_blank


#: Default blanking (full-size sensor).
SENSOR_TIMING = SensorTiming()
#: Short blanking for fast tests with spec.sensor.SMALL_SENSOR (same structure).
SMALL_SENSOR_TIMING = SensorTiming(h_blank=12, v_blank_lines=1, frame_start=6, frame_end=6)


@dataclass(frozen=True)
class Faults:
    """Ways to break one frame (all optional; line and byte indices from 0).

    * ``line_bytes``: ``{line: n}``: that line carries ``n`` bytes instead of ``2 * width`` (fewer: the
      line is cut short; more: extra pseudo-random bytes; odd counts allowed).
    * ``extra_lines``: that many additional full lines of pseudo-random bytes after the configured height.
    * ``fv_drop``: ``(line, byte)``: FV (and LV) fall just before that byte of that line and the rest of the
      frame is not sent (the next frame period follows).
    * ``lv_without_fv``: that many line-long LV-high bursts of pseudo-random bytes in the vertical blanking
      before the frame, with FV low.
    * ``pauses``: ``((line, byte, seconds), ...)``: PCLK stops (held low) for ``seconds`` before that
      byte of that line (``byte`` may equal the line's byte count: a pause in the horizontal blanking).
    * ``cut_before``: ``(line, byte)``: the chunk starts at that byte of that line, FV already high: what a
      capture block sees when it comes out of reset in the middle of a frame.
    * ``silence_lines``: after the frame (or where ``fv_drop`` ends it), FV and LV stay low for that many more
      line times, PCLK running: with ``fv_drop``, a sensor restarted mid-frame (a reset or a standby and wake-up
      with its registers kept), whose later frames then start that much later against the other camera's.
    """
    line_bytes: dict = field(default_factory=dict)
    extra_lines: int = 0
    fv_drop: tuple = None
    lv_without_fv: int = 0
    pauses: tuple = ()
    cut_before: tuple = None
    silence_lines: int = 0


@dataclass
class SensorStream:
    """Per-PCLK samples: ``fv``, ``lv``, ``data`` (uint8 arrays of equal length) and ``pauses``
    ``{sample index: seconds PCLK is held low before that sample's rising edge}``."""
    fv: np.ndarray
    lv: np.ndarray
    data: np.ndarray
    pauses: dict = field(default_factory=dict)
    configured: bool = True           # False: produced while the sensor was not configured for RGB565

    def __len__(self):
        return len(self.fv)

    @classmethod
    def concat(cls, streams):
        streams = list(streams)
        pauses, offset = {}, 0
        for s in streams:
            pauses.update({offset + i: t for i, t in s.pauses.items()})
            offset += len(s)
        return cls(np.concatenate([s.fv for s in streams]), np.concatenate([s.lv for s in streams]),
                   np.concatenate([s.data for s in streams]), pauses, all(s.configured for s in streams))

    def duration(self, pclk_hz):
        """Seconds this stream takes at ``pclk_hz`` (pauses included)."""
        return len(self) / pclk_hz + sum(self.pauses.values())


def image_to_bytes(words, r_byte_first=True):
    """RGB565 words ``(H, W)`` -> the bus bytes ``(H, 2W)`` of each line in transmission order."""
    first, second = rgb565_to_bytes(np.asarray(words, dtype=np.uint16), r_byte_first)
    out = np.empty((words.shape[0], 2 * words.shape[1]), dtype=np.uint8)
    out[:, 0::2] = first
    out[:, 1::2] = second
    return out


class _Builder:
    """Accumulates runs of samples."""

    def __init__(self, rng):
        self.rng = rng
        self.parts = []
        self.n = 0
        self.pauses = {}

    def add(self, count, fv, lv, data=None):
        if count <= 0:
            return
        if data is None:
            data = self.rng.integers(0, 256, count, dtype=np.uint8)
        self.parts.append((np.full(count, fv, np.uint8), np.full(count, lv, np.uint8),
                           np.asarray(data, dtype=np.uint8)))
        self.n += count

    def pause(self, offset, seconds):
        self.pauses[self.n + offset] = self.pauses.get(self.n + offset, 0.0) + float(seconds)

    def stream(self, configured=True):
        if not self.parts:
            z = np.zeros(0, np.uint8)
            return SensorStream(z, z.copy(), z.copy(), dict(self.pauses), configured)
        fv, lv, data = (np.concatenate(p) for p in zip(*self.parts))
        return SensorStream(fv, lv, data, dict(self.pauses), configured)


class MT9D112:
    """The sensor model's core. ``config``: a ``SensorConfig`` or an object with ``sensor_config()``."""

    def __init__(self, config=None, *, timing=SENSOR_TIMING, pclk_hz=CLOCKS.CAM_MCLK_HZ, seed=0):
        if config is None:
            config = SensorConfig()
        if not (isinstance(config, SensorConfig) or callable(getattr(config, "sensor_config", None))):
            raise TypeError("config must be a SensorConfig or have a sensor_config() method")
        self._config = config
        self.timing = timing
        self.pclk_hz = float(pclk_hz)
        self.rng = np.random.default_rng(seed)

    def config(self):
        """The current output configuration."""
        cfg = self._config if isinstance(self._config, SensorConfig) else self._config.sensor_config()
        if not isinstance(cfg, SensorConfig):
            raise TypeError(f"sensor_config() returned {type(cfg).__name__}, expected SensorConfig")
        return cfg

    def words(self, image, cfg=None):
        """``image`` (RGB uint8 array, RGB565 uint16 array or PNG path) as RGB565 words at the configured size."""
        cfg = cfg or self.config()
        if isinstance(image, (str, Path)):
            try:
                image = read_image(image)
            except ImageFileError as exc:
                raise UserError(str(exc)) from None
        image = np.asarray(image)
        if image.ndim == 3 and image.shape[:2] != (cfg.height, cfg.width):
            image = fit_to_sensor(image, cfg.width, cfg.height)
        words = to_rgb565(image)
        if words.shape != (cfg.height, cfg.width):
            raise ValueError(f"RGB565 image is {words.shape[1]}x{words.shape[0]}, sensor outputs "
                             f"{cfg.width}x{cfg.height}")
        return words

    def frame(self, image, faults=None):
        """One frame period: vertical blanking then the frame (or, unconfigured, a frame period of FV low). A
        register-file model with ``start_frame()`` is told that a frame starts (a still capture counts it)."""
        start = getattr(self._config, "start_frame", None)
        cfg = start() if start is not None else self.config()
        t = self.timing
        faults = faults or Faults()
        line_len = 2 * cfg.width
        line_time = t.line_time(cfg.width)
        b = _Builder(self.rng)
        if not cfg.rgb565:
            b.add(t.v_blank_lines * line_time + t.frame_start + cfg.height * line_time + t.frame_end,
                  0, 0)
            return b.stream(configured=False)

        lines = image_to_bytes(self.words(image, cfg), cfg.r_byte_first)
        # Vertical blanking, with optional LV bursts while FV is low.
        v_blank = t.v_blank_lines * line_time
        bursts = faults.lv_without_fv
        if bursts:
            gap = max(1, (v_blank - bursts * line_len) // (bursts + 1))
            used = 0
            for _ in range(bursts):
                b.add(gap, 0, 0)
                b.add(line_len, 0, 1)
                used += gap + line_len
            b.add(max(1, v_blank - used), 0, 0)
        else:
            b.add(v_blank, 0, 0)

        drop = faults.fv_drop
        pauses = {}
        for line, byte, seconds in faults.pauses:
            pauses.setdefault(line, []).append((byte, seconds))

        b.add(t.frame_start, 1, 0)
        cut = None
        total_lines = cfg.height + faults.extra_lines
        for line in range(total_lines):
            nbytes = faults.line_bytes.get(line, line_len)
            if line < cfg.height:
                content = lines[line][:nbytes]
                if nbytes > line_len:
                    content = np.concatenate([content, self.rng.integers(0, 256, nbytes - line_len,
                                                                         dtype=np.uint8)])
            else:
                content = self.rng.integers(0, 256, nbytes, dtype=np.uint8)
            for byte, seconds in pauses.get(line, ()):
                b.pause(byte, seconds)
            if faults.cut_before is not None and faults.cut_before[0] == line:
                cut = b.n + faults.cut_before[1]
            if drop is not None and drop[0] == line:
                b.add(min(drop[1], nbytes), 1, 1, content[:drop[1]])
                break
            b.add(nbytes, 1, 1, content)
            b.add(t.h_blank if line < total_lines - 1 else t.frame_end, 1, 0)
        b.add(faults.silence_lines * line_time, 0, 0)
        return self._cut(b.stream(), cut)

    @staticmethod
    def _cut(stream, start):
        if start is None:
            return stream
        return SensorStream(stream.fv[start:], stream.lv[start:], stream.data[start:],
                            {i - start: t for i, t in stream.pauses.items() if i >= start}, stream.configured)

    def blank(self, lines=None):
        """FV low for ``lines`` line times (default: the vertical blanking)."""
        cfg = self.config()
        lines = self.timing.v_blank_lines if lines is None else lines
        b = _Builder(self.rng)
        b.add(max(1, lines * self.timing.line_time(cfg.width)), 0, 0)
        return b.stream()

    def frames(self, images, faults=None, *, tail=True, max_idle=None):
        """Chunks for ``images`` in order, built lazily. A frame period in which the sensor is not configured
        is sent blank and the same image is tried again in the next one (at most ``max_idle`` times, if
        given). ``faults`` is a sequence parallel to ``images`` (``None`` entries for good frames).
        Ends with a blank tail (``tail``) so the capture pipeline drains."""
        faults = list(faults) if faults is not None else [None] * len(images)
        if len(faults) != len(images):
            raise ValueError("faults must have one entry per image")
        for image, fault in zip(images, faults):
            idle = 0
            while True:
                chunk = self.frame(image, fault)
                yield chunk
                if chunk.configured:
                    break
                idle += 1
                if max_idle is not None and idle > max_idle:
                    raise RuntimeError("the sensor was never configured for RGB565 output")
        if tail:
            yield self.blank(1)

    def stream(self, images, faults=None, *, tail=True):
        """:meth:`frames` joined into one :class:`SensorStream` (configuration read now)."""
        return SensorStream.concat(self.frames(images, faults, tail=tail, max_idle=0))


def fault_cases(width, height):
    """The bad-stream cases of the robustness tests, for a ``width`` x ``height`` sensor (at least 8 x 8):
    name -> :class:`Faults`. Each is sent as a faulty frame followed by a good one."""
    if width < 8 or height < 8:
        raise ValueError("the fault cases need a sensor of at least 8 x 8")
    n = 2 * width
    return {
        "lv_without_fv": Faults(lv_without_fv=3),
        "short_lines": Faults(line_bytes={1: n - 8, 5: 6}),
        "long_line": Faults(line_bytes={2: n + 10}),
        "odd_byte_counts": Faults(line_bytes={3: n - 1, 4: n + 1, height - 1: 1}),
        "fv_drop_mid_frame": Faults(fv_drop=(height // 2, width + 1)),
        "extra_lines": Faults(extra_lines=3),
        "pclk_pause": Faults(pauses=((0, 0, 1e-6), (1, 5, 2.5e-6), (height - 1, n, 1e-6))),
        "reset_mid_frame": Faults(cut_before=(height // 3, 7)),
        "combined": Faults(lv_without_fv=1, line_bytes={0: n + 3, 2: n - 5}, extra_lines=2,
                           pauses=((3, 1, 0.5e-6),)),
    }


# --- Drivers -----------------------------------------------------------------------------------------------

def _as_chunks(stream_or_chunks):
    return [stream_or_chunks] if isinstance(stream_or_chunks, SensorStream) else stream_or_chunks


def _changed_only(current, fv, lv, data, write):
    """``put(f, l, d)``: ``write(pin, value)`` for the pins whose value changes from the last put (starting from
    ``current``): a write only on a change is the cheapest for both simulators."""
    current = list(current)
    pins = (fv, lv, data)

    def put(*values):
        for k, value in enumerate(values):
            if value != current[k]:
                write(pins[k], value)
                current[k] = value
    return put


async def drive_amaranth(ctx, chunks, *, clk, pins, pclk_hz, start_delay=0.0, on_sample=None):
    """Amaranth-simulator testbench body: send ``chunks`` (a :class:`SensorStream` or an iterable of them) on
    ``pins`` (an ``hdl.capture.CameraSignature`` interface of the design: ``data``, ``lv``, ``fv``).

    ``clk`` is the camera domain's clock signal (``ClockDomain.clk``; do not also ``add_clock`` it). Each
    sample: PCLK falls and D/LV/FV change, half a period (plus any pause) later ``on_sample(ctx)`` is called
    and PCLK rises. ``start_delay`` (seconds) shifts this camera's phase. Returns the number of samples sent.
    """
    half = 0.5 / pclk_hz
    if start_delay:
        await ctx.delay(start_delay)
    put = _changed_only((None, None, None), pins.fv, pins.lv, pins.data, ctx.set)
    sent = 0
    for chunk in _as_chunks(chunks):
        fvs, lvs, ds = chunk.fv.tolist(), chunk.lv.tolist(), chunk.data.tolist()
        pauses = chunk.pauses
        for i in range(len(fvs)):
            ctx.set(clk, 0)
            put(fvs[i], lvs[i], ds[i])
            await ctx.delay(half + pauses[i] if pauses and i in pauses else half)
            if on_sample is not None:
                on_sample(ctx)
            ctx.set(clk, 1)
            await ctx.delay(half)
        sent += len(fvs)
    ctx.set(clk, 0)
    return sent


async def drive_cocotb(chunks, *, clk, pins, pclk_hz, start_delay=0.0, on_sample=None, reset=None, reset_cycles=4):
    """cocotb coroutine: send ``chunks`` on PCLK ``clk`` and ``pins`` (DUT handles ``data``, ``lv``, ``fv``, e.g.
    ``sim.runners.cocotb.TopPorts(dut).cam_a``).

    PCLK is a GPI clock (its edges stay out of Python). Sample ``i`` is put on D/LV/FV at a falling edge
    (the first one before the clock starts) and captured by the next rising edge; ``on_sample()`` is called
    right after it is put there (mid-period: the design's registered outputs are stable and are what that
    rising edge commits). A pause stops the clock while it is low. The period is rounded to an even number
    of picoseconds. With ``reset`` (the domain's reset pin) the reset is held for ``reset_cycles`` PCLK
    periods first, the pins already showing the first sample. The clock is stopped (low) after the last
    sample's rising edge.
    Returns the number of samples sent.
    """
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, Timer

    period_ps = 2 * round(0.5e12 / pclk_hz)
    data, lv, fv = pins.data, pins.lv, pins.fv
    chunks = iter(_as_chunks(chunks))
    pending = next(chunks, None)
    first = (0, 0, 0) if pending is None or not len(pending) else (
        int(pending.fv[0]), int(pending.lv[0]), int(pending.data[0]))
    # Before the first sample (and during reset) the pins already show the first sample, as a sensor that
    # is running when the FPGA comes out of reset would.
    fv.value, lv.value, data.value = first
    clk.value = 0
    if start_delay:
        await Timer(round(start_delay * 1e12), unit="ps")
    clock = Clock(clk, period_ps, unit="ps", impl="gpi")
    falling = FallingEdge(clk)
    if reset is not None:
        reset.value = 1
        clock.start(start_high=False)
        for _ in range(reset_cycles):
            await falling
        reset.value = 0     # the first sample is captured by the next rising edge
    running = reset is not None
    wait = False                        # we are at a falling edge (or before the clock starts)
    put = _changed_only(first, fv, lv, data, lambda handle, value: setattr(handle, "value", value))
    sent = 0

    def all_chunks():
        if pending is not None:
            yield pending
        yield from chunks

    try:
        for chunk in all_chunks():
            fvs, lvs, ds = chunk.fv.tolist(), chunk.lv.tolist(), chunk.data.tolist()
            pauses = chunk.pauses
            for i in range(len(fvs)):
                if wait:
                    await falling
                wait = True
                put(fvs[i], lvs[i], ds[i])
                if on_sample is not None:
                    on_sample()
                pause = pauses.get(i)
                if pause:
                    if running:
                        clock.stop()
                        running = False
                    await Timer(round(pause * 1e12), unit="ps")
                if not running:
                    clock.start(start_high=False)
                    running = True
            sent += len(fvs)
        if running:
            await falling
    finally:
        if running:
            clock.stop()
    return sent
