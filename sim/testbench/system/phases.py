"""The phases of a whole-system run, written once: :func:`phases`, a coroutine every driver runs.

1. **reset**: the reset button is pressed for 50 ns (the pixel clock already running without
   ``setup.pix_after_init``) and released; the clocking model locks and releases the domain resets;
2. **init**: the RTL's three init sequencers configure the register-file models over their I2C buses; a bus that
   reports an error ends the run here (the verdict reports it); then the pixel clock starts (with
   ``setup.pix_after_init``) and, once the pixel domain is out of reset, the switches are set
   (:meth:`~sim.testbench.system.setup.SystemSetup.switch_words`, each held for 30 pixel clocks: SW7 = 1 with the
   disparity, then SW7 = 0 with the rectification; the next frame start loads both);
3. **capture** (a still pair): until both captures complete a frame;
4. **display**: from the next display frame start (in the DDR2 build, one that starts at least
   :data:`PUBLISH_S` after the capture phase: a display frame shows the pair the frame store holds at its start),
   outside an hsync pulse, the CH7301C pins one display frame
   period at a time into the HDMI sink model, each frame it completes handed to ``on_frame`` as a
   :class:`~sim.testbench.system.result.DisplayFrame` (:class:`~sim.testbench.system.result.DisplayFrames`: a
   sequence up to its settled frame, a still pair until ``on_frame`` returns True or ``max_frames``);
5. **check**: the driver's, after the simulation (:func:`sim.testbench.system.result.record_parts`).

A driver is the primitives the phases are written against, each in its simulator's way of advancing time:

* ``button(pressed)``: the reset button (the switches are at 0 while it is first pressed);
* ``await start_pix()``: start the pixel clock; ``await pix_out_of_reset()``: until the pixel domain left reset;
* ``await advance(seconds)``, ``await advance_pix(clocks)``: let simulated time pass;
* ``await until(what, condition, timeout_s)``: until ``condition()`` holds (a
  :class:`~sim.testbench.system.result.SystemTimeout` naming ``what`` after ``timeout_s`` of simulated time);
* ``await display_frame_start()``: until the next display frame start, then until the CH7301C's hsync is idle (the
  pins lag the raster by ``DISPLAY_LATENCY`` clocks, which can put them inside the previous line's pulse: the
  sink must see whole pulses);
* ``await display_frame(sink, clocks)``: ``clocks`` pixel clocks of the CH7301C pins into ``sink``;
* ``set_switches(word)``; what the design shows: ``now()`` (simulated seconds), ``locked()``, ``init_flags()``
  (``{bus: (done, error)}``), ``frame_counts()``, ``frames_ok()`` (``{camera: ...}``), ``settings()`` (the
  switch settings and the automatic rectification's state), ``panel()`` (``leds``, ``drive_high``);
* ``progress(stage)``: the run entered ``stage`` (``i2c``, ``capture``, ``display``, ``done``); the driver
  reports it with its fraction done.

A driver whose primitives never suspend (Verilator: plain calls) runs the coroutine with :func:`run_to_end`. A
driver that cannot record the display one display frame period at a time (the cocotb scenario's in-simulator
recorder writes one stretch) runs :func:`before_display` and its own display phase.
"""

import math
import time

from hdl.system import DISPLAY_LATENCY, I2C_BUSES
from sim.models.ch7301c.hdmi_sink import HdmiSink
from sim.testbench.system.result import SystemTimeout

__all__ = ["phases", "before_display", "display", "mark", "display_limit", "run_to_end", "RESET_PRESS_S",
           "PIX_RESET_S", "PUBLISH_S", "SWITCH_HOLD_CLOCKS", "LOCK", "INIT", "CAPTURE"]

#: How long the reset button is held.
RESET_PRESS_S = 50e-9
#: The pixel domain's reset release after its clock starts (two synchroniser stages, generously): for drivers that
#: cannot see the domain's reset.
PIX_RESET_S = 200e-9
#: The DDR2 build: time from a capture's last pixel to its frame published in the frame store, at most (the
#: camera writer's 8 bursts in flight, each a few ``mem`` clocks, and the FIFO crossings: well under a microsecond).
PUBLISH_S = 2e-6
#: Pixel clocks each switch word is held (more than the synchroniser and the pending register need).
SWITCH_HOLD_CLOCKS = 30
#: What the phases wait for (``until``'s ``what``: a polling driver chooses its step by it).
LOCK, INIT, CAPTURE = "clock lock", "I2C initialisation", "a complete frame from both cameras"


def run_to_end(coroutine):
    """Run a coroutine whose awaits never suspend (every primitive a plain call); returns its value."""
    try:
        while True:
            coroutine.send(None)
    except StopIteration as stop:
        return stop.value


async def phases(sim, setup, *, still, frames, on_frame, max_frames, deadline_s, limit_frames, status):
    """The phases (see the module docstring) on driver ``sim``; ``frames``: the run's
    :class:`~sim.testbench.system.result.DisplayFrames`; ``limit_frames``: display frame periods the display phase
    may take (:func:`display_limit`; a :class:`~sim.testbench.system.result.SystemTimeout` after them); fills
    ``status``. Returns the HDMI sink of the display phase (a sink that saw nothing when the init failed)."""
    wall0 = time.perf_counter()
    sink = HdmiSink(setup.timing, keep_frames=1)
    if await before_display(sim, setup, still=still, deadline_s=deadline_s, status=status, wall0=wall0):
        await display(sim, setup, sink, frames, on_frame, max_frames, limit_frames, status)
        mark(status, "display", wall0)
    return sink


async def before_display(sim, setup, *, still, deadline_s, status, wall0):
    """The phases up to the display frames: reset, I2C init and (``still``) capture, each marked in
    ``status["phase_wall_s"]`` with the wall time since ``wall0``. False if the init failed (nothing more was
    done)."""
    status["phase_wall_s"] = {}
    await reset(sim, setup, deadline_s)
    if not await init(sim, setup, deadline_s, status):
        return False
    mark(status, "init", wall0)
    if still:
        await capture(sim, deadline_s, status)
        mark(status, "capture", wall0)
    return True


def mark(status, phase, wall0):
    """Note in ``status["phase_wall_s"]`` that ``phase`` ended (wall seconds since ``wall0``)."""
    status["phase_wall_s"][phase] = time.perf_counter() - wall0


def display_limit(setup, sequence, max_frames, deadline_s):
    """Display frame periods a run's display phase may take: a still pair's ``max_frames`` and one more; a
    sequence's deadline and twice its stream (one sensor frame period per pair, then four display frames)."""
    if getattr(sequence, "still", False):
        return max_frames + 1
    display = setup.timing.clocks_per_frame / setup.timing.pixel_hz
    stream = len(sequence) * setup.frame_period_samples() / setup.pclk_hz + 4 * display
    return math.ceil((deadline_s + 2 * stream) / display)


async def reset(sim, setup, deadline_s):
    sim.button(True)
    if not setup.pix_after_init:
        await sim.start_pix()
    await sim.advance(RESET_PRESS_S)
    sim.button(False)
    await sim.until(LOCK, sim.locked, deadline_s)
    if not setup.pix_after_init:
        await set_switches(sim, setup)


async def set_switches(sim, setup):
    await sim.pix_out_of_reset()
    for word in setup.switch_words():
        sim.set_switches(word)
        await sim.advance_pix(SWITCH_HOLD_CLOCKS)


async def init(sim, setup, deadline_s, status):
    """The I2C init; then the pixel clock and the switches. False if a bus failed."""
    sim.progress("i2c")
    await sim.until(INIT, lambda: all(done or error for done, error in sim.init_flags().values()), deadline_s)
    for b, (done, error) in sim.init_flags().items():
        status[f"{b}_init_done"], status[f"{b}_init_error"] = bool(done), bool(error)
    status["t_init_s"] = sim.now()
    if not all(status[f"{b}_init_done"] for b in I2C_BUSES):
        return False
    if setup.pix_after_init:
        await sim.start_pix()
        await set_switches(sim, setup)
    return True


async def capture(sim, deadline_s, status):
    """Until both captures completed a frame (a still pair's run)."""
    sim.progress("capture")
    counts0 = sim.frame_counts()
    await sim.until(CAPTURE, lambda: all(n != counts0[c] for c, n in sim.frame_counts().items()), deadline_s)
    for c, ok in sim.frames_ok().items():
        status[f"cam_{c}_frame_ok"] = bool(ok)
    status["t_captured_s"] = sim.now()


async def display(sim, setup, sink, frames, on_frame, max_frames, limit, status):
    """The display frames, one display frame period at a time from the next display frame start."""
    sim.progress("display")
    if setup.memory == "ddr2":
        await sim.advance(PUBLISH_S)
    await sim.display_frame_start()
    status.update(sim.settings())
    clocks = setup.timing.clocks_per_frame
    frames.start(sim.now(), clocks / setup.timing.pixel_hz)
    recorded = 0
    for chunk in range(limit):
        settings, before = sim.settings(), sink.frames_completed
        # The first chunk holds a display frame and the pins' latency: the sink completes frame k in chunk k.
        sampled = clocks + (DISPLAY_LATENCY + 2 if not chunk else 0)
        await sim.display_frame(sink, sampled)
        recorded += sampled
        enough = any([frames.completed(on_frame, sink.frames[-1].copy(), settings)
                      for _ in range(before, sink.frames_completed)])
        sim.progress("display")
        if frames.finished(enough, max_frames):
            break
        if not frames.shown and chunk >= 3:
            raise SystemTimeout("the HDMI sink rebuilt no frame from three display frame periods of pins")
    else:
        raise SystemTimeout(frames.overdue())
    status["recorded_clocks"] = recorded
    status["violations"] = [str(v) for v in sink.violations]
    status.update(sim.panel())
    status["t_end_s"] = sim.now()
    status.update(frames.record())
    sim.progress("done")
