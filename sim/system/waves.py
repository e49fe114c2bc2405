"""What the whole system's GTKWave save file shows (``system.gtkw``, written by ``stereodepth demo`` and
``stereodepth run --vcd`` through :func:`sim.system.run_amaranth.run_amaranth`).

Groups, in the order of the run: reset and clocking; each I2C bus (its lines decoded into bytes and
transactions, the state of its init sequencer and I2C master by name, its init status); each camera's pins, its
capture's line counter and frame status; the switches; the video stream; the CH7301C pins; the LEDs.
:mod:`sim.gtkw` adds any other state machine in a group of its own.

Named markers, in the order of the run: each bus's I2C init done, each camera's first captured frame, the first
display frame start after both, and that frame's vsync pulse. The file opens on the end of the camera
configuration (the last transactions readable) through the captured frames to the vsync pulse of the first
display frame after them; GTKWave's Zoom Full (Ctrl+Alt+F) shows the whole run.
"""

from hdl.system import CAMERAS, I2C_BUSES
from sim.gtkw import Event, I2CBus, Show, Waves

__all__ = ["system_waves"]


def system_waves(top):
    """The :class:`sim.gtkw.Waves` of a whole-system run (``top``: the design ``run_amaranth`` simulates, with
    :class:`sim.system.bench.SystemBench`'s members and its ``system``)."""
    groups = {"reset_and_clocking": [top.button, top.locked]}
    for b in I2C_BUSES:
        bus, init = getattr(top.bus, b), getattr(top.init, b)
        groups[f"i2c_{b}"] = [I2CBus(f"{b}_i2c", bus.scl, bus.sda),
                              Show(f"init_{b}.fsm_state", alias=f"{b} init sequencer"),
                              Show(f"init_{b}.master.fsm_state", alias=f"{b} I2C master"),
                              init.done, init.error]
    for c in CAMERAS:
        pins, status = getattr(top.system, f"cam_{c}"), getattr(top.capture, f"cam_{c}")
        groups[f"camera_{c}"] = [pins.fv, pins.lv, pins.data,
                                 Show(f"capture_{c}.row", fmt="dec", alias=f"cam_{c} lines in frame"),
                                 status.frame_done, status.frame_ok, Show(status.frame_count, fmt="dec")]
    groups["switches"] = [top.panel.sw, Show(top.settings.disparity, fmt="dec"),
                          Show(top.settings.rectification, fmt="dec")]
    video, pins = top.video, top.ch7301c
    groups["video_stream"] = [video.rgb, video.de, video.hsync, video.vsync, top.frame_start]
    groups["ch7301c_pins"] = [pins.xclk_p, pins.xclk_n, pins.data, pins.de, pins.hsync, pins.vsync]
    groups["leds"] = [Show(top.panel.leds, fmt="bin")]
    events = [Event(f"{b} I2C done", getattr(top.init, b).done) for b in I2C_BUSES]
    events += [Event(f"camera {c.upper()} frame", getattr(top.capture, f"cam_{c}").frame_done,
                     after=f"cam_{c} I2C done") for c in CAMERAS]
    events.append(Event("display frame", top.frame_start,
                        after=tuple(f"camera {c.upper()} frame" for c in CAMERAS)))
    events.append(Event("vsync", pins.vsync, value=int(top.system.video_timing.vsync_positive),
                        after="display frame"))
    return Waves(groups=groups, events=events, view=("cam_a I2C done", "vsync"), before_s=60e-6, after_s=5e-6)
