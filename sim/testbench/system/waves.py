"""What the whole system's GTKWave save file shows (``system.gtkw``, written by ``stereodepth demo`` and
``stereodepth run --vcd`` through :func:`sim.testbench.system.run_amaranth.run_amaranth`), and what a cocotb run's save
file marks (:func:`cocotb_system_waves`; ``STEREO_WAVES=1``).

Groups, in the order of the run: reset and clocking; each I2C bus (its lines decoded into bytes and
transactions, the state of its init sequencer and I2C master by name, its init status); each camera's pins, its
capture's line counter and frame status; the switches; the depth engine (start, busy, its read requests and the
arbiters' grants, the result rows ready and released); the video stream; the CH7301C pins; the LEDs.
:mod:`sim.waves.gtkw` adds any other state machine in a group of its own.

Named markers, in the order of the run: each bus's I2C init done, each camera's first captured frame, the first
display frame start after both, and that frame's vsync pulse. The file opens on the end of the camera
configuration (the last transactions readable) through the captured frames to the vsync pulse of the first
display frame after them; GTKWave's Zoom Full (Ctrl+Alt+F) shows the whole run.
"""

from hdl.system import CAMERAS, I2C_BUSES, I2C_SEQUENCER
from sim.waves.gtkw import Event, I2CBus, Show, Waves

__all__ = ["system_waves", "system_events", "cocotb_system_waves"]


def system_waves(top):
    """The :class:`sim.waves.gtkw.Waves` of a whole-system run (``top``: the design ``run_amaranth`` simulates, with
    :class:`sim.testbench.system.testbench.SystemTestbench`'s members and its ``video_timing``; the signals of the
    system's blocks by their names in the dump)."""
    # A top-level input is shown as the block that reads it names it (in the top's own module, its copy there has
    # the plain name): the clocking model's button, the system's switches.
    groups = {"reset_and_clocking": [Show("clocking.button"), top.locked]}
    groups["i2c_init"] = [Show(f"{I2C_SEQUENCER}.fsm_state", alias="init sequencer"),
                          Show(f"{I2C_SEQUENCER}.master.fsm_state", alias="I2C master")]
    for b in I2C_BUSES:
        bus, init = getattr(top.bus, b), getattr(top.init, b)
        groups[f"i2c_{b}"] = [I2CBus(f"{b}_i2c", bus.scl, bus.sda), init.done, init.error]
    for c in CAMERAS:
        status = getattr(top.capture, f"cam_{c}")
        pins = {name: f"system.cam_{c}__{name}" for name in ("fv", "lv", "data")}    # the system's own (by name)
        groups[f"camera_{c}"] = [Show(pins["fv"]), Show(pins["lv"]), Show(pins["data"]),
                                 Show(f"capture_{c}.row", fmt="dec", alias=f"cam_{c} lines in frame"),
                                 status.frame_done, status.frame_ok, Show(status.frame_count, fmt="dec")]
    groups["switches"] = [Show("system.panel__sw"), Show(top.settings.disparity, fmt="dec"),
                          Show(top.settings.rectification, fmt="dec")]
    engine = "display.engine."          # the depth engine's own signals, by their names in the dump
    groups["depth_engine"] = [Show(engine + "start"), Show(engine + "busy"),
                              Show(engine + "left_row_offset", fmt="dec"),
                              *(Show(f"{engine}{side}__{name}") for side in ("left", "right")
                                for name in ("request", "grant")),
                              Show(engine + "result__rows_ready", fmt="dec"),
                              Show(engine + "result__rows_released", fmt="dec")]
    video, pins = top.video, top.ch7301c
    groups["video_stream"] = [video.rgb, video.de, video.hsync, video.vsync, top.frame_start]
    groups["ch7301c_pins"] = [pins.xclk_p, pins.xclk_n, pins.data, pins.de, pins.hsync, pins.vsync]
    groups["leds"] = [Show(top.panel.leds, fmt="bin")]
    events = system_events(lambda path: _member(top, path), top.video_timing)
    return Waves(groups=groups, events=events, view=VIEW, before_s=BEFORE_S, after_s=AFTER_S)


#: The window both save files open on: the camera configuration's end to the vsync pulse, widened (seconds).
VIEW, BEFORE_S, AFTER_S = ("cam_a I2C done", "vsync"), 60e-6, 5e-6


def system_events(signal, timing):
    """The named markers of a whole-system run, in the order of the run: each bus's I2C init done, each camera's
    first captured frame after its bus's init, the first display frame start after both, that frame's vsync
    pulse. ``signal(path)`` gives what an :class:`~sim.waves.gtkw.Event` takes for the member at ``path`` of the
    system's signature (``("init", "cam_a", "done")``); ``timing``: the display's video timing."""
    events = [Event(f"{b} I2C done", signal(("init", b, "done"))) for b in I2C_BUSES]
    events += [Event(f"camera {c.upper()} frame", signal(("capture", f"cam_{c}", "frame_done")),
                     after=f"cam_{c} I2C done") for c in CAMERAS]
    events.append(Event("display frame", signal(("frame_start",)),
                        after=tuple(f"camera {c.upper()} frame" for c in CAMERAS)))
    events.append(Event("vsync", signal(("ch7301c", "vsync")), value=int(timing.vsync_positive),
                        after="display frame"))
    return events


def _member(top, path):
    for name in path:
        top = getattr(top, name)
    return top


def cocotb_system_waves(route, setup):
    """The :class:`sim.waves.cocotb.RunWaves` of a cocotb run of the system along ``route``: the same markers
    and window as :func:`system_waves`, on the exported top's flat port names, and the route's design for the
    state machines' names."""
    from board.export import flat_name
    from sim.waves.cocotb import RunWaves
    return RunWaves(design=lambda: route.design(setup), events=system_events(flat_name, setup.timing),
                    view=VIEW, before_s=BEFORE_S, after_s=AFTER_S)
