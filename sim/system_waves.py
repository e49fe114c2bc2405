"""What the whole system's GTKWave save file shows (``system.gtkw``, written by ``stereodepth demo`` and
``stereodepth run --vcd`` through :func:`sim.system_amaranth.run_amaranth`).

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


def system_waves(bench):
    """The :class:`sim.gtkw.Waves` of a :class:`sim.system_bench.SystemBench` run (see the module docstring)."""
    sys_ = bench.system
    groups = {"reset_and_clocking": [bench.button, bench.locked]}
    for b in I2C_BUSES:
        groups[f"i2c_{b}"] = [I2CBus(f"{b}_i2c", getattr(bench, f"{b}_scl"), getattr(bench, f"{b}_sda")),
                              Show(f"init_{b}.fsm_state", alias=f"{b} init sequencer"),
                              Show(f"init_{b}.master.fsm_state", alias=f"{b} I2C master"),
                              getattr(bench, f"{b}_init_done"), getattr(bench, f"{b}_init_error")]
    for c in CAMERAS:
        groups[f"camera_{c}"] = [
            getattr(bench, f"cam_{c}_fv"), getattr(bench, f"cam_{c}_lv"), getattr(bench, f"cam_{c}_data"),
            Show(f"capture_{c}.row", fmt="dec", alias=f"cam_{c} lines in frame"),
            getattr(bench, f"cam_{c}_frame_done"), getattr(bench, f"cam_{c}_frame_ok"),
            Show(getattr(bench, f"cam_{c}_frame_count"), fmt="dec")]
    groups["switches"] = [bench.sw, Show(bench.disparity, fmt="dec"), Show(bench.rectification, fmt="dec")]
    groups["video_stream"] = [sys_.video_rgb, sys_.video_de, sys_.video_hsync, sys_.video_vsync,
                              bench.frame_start]
    groups["ch7301c_pins"] = [bench.xclk_p, bench.xclk_n, bench.data, bench.de, bench.hsync, bench.vsync]
    groups["leds"] = [Show(bench.leds, fmt="bin")]
    events = [Event(f"{b} I2C done", getattr(bench, f"{b}_init_done")) for b in I2C_BUSES]
    events += [Event(f"camera {c.upper()} frame", getattr(bench, f"cam_{c}_frame_done"), after=f"cam_{c} I2C done")
               for c in CAMERAS]
    events.append(Event("display frame", bench.frame_start,
                        after=tuple(f"camera {c.upper()} frame" for c in CAMERAS)))
    events.append(Event("vsync", bench.vsync, value=int(sys_.video_timing.vsync_positive), after="display frame"))
    return Waves(groups=groups, events=events, view=("cam_a I2C done", "vsync"), before_s=60e-6, after_s=5e-6)
