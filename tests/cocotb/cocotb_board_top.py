"""cocotb test of the board's Verilog as built (``top.v`` of ``stereodepth verilog``) with the Virtex-5 primitive
models, on Icarus and Verilator (run by tests/test_board_top.py's ``run_board_cocotb``).

The bench (``sim.board.top.TESTBENCH``) drives only the 100 MHz oscillator pin and the reset button; everything
else comes from the design and the models:

* the DCM/PLL models make MCLK, the pixel clock and the 90-degree XCLK clock: the test measures MCLK on both
  camera pins and XCLK_P / XCLK_N against the clock plan (``board.clocking.PLAN``);
* the I2C register-file models answer on the three buses (``sim.models``); at the end each part's state is
  compared field by field with ``golden.part_config``;
* the sensor models (``sim.models.mt9d112.sensor``) drive PCLK, D, LV, FV of each camera once their register file says RGB565
  and streaming;
* the HDMI sink (``sim.models.ch7301c.hdmi_sink.HdmiSink``) reads the CH7301C pins the way the CH7301C latches them: the
  syncs, DE and the first 12-bit word on each rising edge of XCLK_P, the second word on each falling edge. With
  ``measure_eye`` every change of the data pins is timed against the XCLK edges (the setup / hold margins the
  CH7301C sees). The first complete display frame after both cameras have sent a whole frame must equal the
  golden model's frame bit for bit.

Parameters (``sim.runners.cocotb.test_params``): ``setup`` (a ``SystemSetup`` spec), ``left``, ``right``,
``out_dir``; optional ``dvi_version_id`` (what the CH7301C model's version register reads: another value than
0x95 must leave the bring-up running and LED5 blinking with LED6), ``measure_eye``, ``check_heartbeat`` (LD6 must
toggle within the few frames sampled: the small build's rate), ``timeout_ms``, ``init_timeout_ms``,
``capture_timeout_ms``.
"""

import bisect
import json
from pathlib import Path

import cocotb
import numpy as np
from cocotb.clock import Clock
from cocotb.simtime import get_sim_time
from cocotb.triggers import FallingEdge, RisingEdge, Timer

from golden.part_config import ch7301c_expected, mt9d112_expected
from golden.stereo_pair import load_pair
from board.clocking import PLAN
from hdl.system import CAMERAS, I2C_BUSES
from sim.board.top import board_setup
from sim.runners.cocotb import TopPorts, test_params
from sim.models.ch7301c.hdmi_sink import HdmiSink, SinkError
from sim.models.i2c.bus import start_cocotb_targets
from sim.models.ch7301c.target import CH7301CModel
from sim.models.i2c.monitor import I2CBusMonitor
from sim.models.mt9d112.sensor import drive_cocotb
from sim.testbench.system.result import check_run

PARAMS = test_params()
OSC_PS = 10_000


def now_ps():
    return get_sim_time("ps")


def _reader(handle):
    gpi = getattr(handle, "_handle", None)
    if gpi is not None and hasattr(gpi, "get_signal_val_binstr"):
        return gpi.get_signal_val_binstr
    return lambda: str(handle.value)


async def _wait(cond, what, timeout_s, step_ns=1000):
    start = now_ps()
    while not cond():
        if (now_ps() - start) * 1e-12 > timeout_s:
            raise AssertionError(f"{what} did not happen within {timeout_s * 1e3:.3f} ms of simulated time")
        await Timer(step_ns, unit="ns")


async def _edges(signal, count):
    """Times (ps) of the next ``count`` rising and falling edges of ``signal``: ``(rises, falls)``."""
    rises, falls = [], []
    rise, fall = RisingEdge(signal), FallingEdge(signal)
    while len(rises) < count:
        await rise
        rises.append(now_ps())
        await fall
        falls.append(now_ps())
    return rises, falls


def _period_stats(rises, falls, ideal_ps):
    periods = np.diff(rises)
    highs = np.array(falls[:len(rises)]) - np.array(rises)
    return {"ideal_ps": ideal_ps, "mean_ps": float(periods.mean()), "min_ps": int(periods.min()),
            "max_ps": int(periods.max()), "high_min_ps": int(highs.min()), "high_max_ps": int(highs.max())}


class EyeMeter:
    """Times every change of the data pins, to compare with the XCLK edges."""

    def __init__(self, data):
        self.data, self.changes, self.running = data, [], True
        cocotb.start_soon(self._run())

    async def _run(self):
        while self.running:
            await self.data.value_change
            self.changes.append(now_ps())

    def margins(self, clock_edges):
        """Smallest (data change -> clock edge, clock edge -> next data change) over ``clock_edges``."""
        before = after = None
        for t in clock_edges:
            i = bisect.bisect_left(self.changes, t)
            if i < len(self.changes) and self.changes[i] == t:
                return 0, 0                          # a data change on a clock edge
            if i > 0:
                before = min(before or 1e18, t - self.changes[i - 1])
            if i < len(self.changes):
                after = min(after or 1e18, self.changes[i] - t)
        return before, after


async def sample_ch7301c(ports, sink, *, max_clocks, leds_at_vsync=None):
    """Feed ``sink`` from the CH7301C pins on both XCLK_P edges, from a rising edge with DE low, until it has
    rebuilt one frame (or ``max_clocks``). Returns the XCLK_P edge times."""
    ch = ports.ch7301c
    data, hs, vs, de = (_reader(getattr(ch, n)) for n in ("data", "hsync", "vsync", "de"))
    leds = _reader(ports.panel.leds)
    rise, fall = RisingEdge(ch.xclk_p), FallingEdge(ch.xclk_p)
    await rise
    while de() != "0":
        await rise
    edges, prev_vs = [], "0"
    for _ in range(max_clocks):
        h, v, d, first = hs(), vs(), de(), data()
        t_rise = now_ps()
        await fall
        second = data()
        edges += [t_rise, now_ps()]
        try:
            sink.sample(h == "1", v == "1", d == "1", int(first, 2), int(second, 2))
        except ValueError:
            raise SinkError(f"X/Z on the CH7301C pins at clock {sink.clock}: {h}{v}{d} {first} {second}") from None
        if leds_at_vsync is not None and v == "1" and prev_vs == "0":
            leds_at_vsync.append(int(leds(), 2))
        prev_vs = v
        if sink.frames_completed:
            break
        await rise
    return edges


def _counted(chunks, sent):
    """Yield ``chunks``, counting in ``sent[0]`` the chunks (frame periods) completely sent before the next."""
    for chunk in chunks:
        yield chunk
        sent[0] += 1


@cocotb.test(timeout_time=PARAMS.get("timeout_ms", 200), timeout_unit="ms")
async def board(dut):
    setup = board_setup(PARAMS["setup"])
    out_dir = Path(PARAMS["out_dir"])
    g, t = setup.geometry, setup.timing
    left, right = load_pair(PARAMS["left"], PARAMS["right"], g.width, g.height)
    images = {"a": left, "b": right}
    status = {}
    ports = TopPorts(dut)

    ports.btn_rst_n.value = 0                   # the reset button (active low) pressed
    ports.panel.sw.value = 0
    for c in CAMERAS:
        for pin in ("pclk", "data", "lv", "fv"):
            getattr(getattr(ports, f"cam_{c}"), pin).value = 0
    Clock(ports.clk100, OSC_PS, unit="ps").start()

    models = setup.i2c_models()
    models["dvi"] = [CH7301CModel(version_id=PARAMS.get("dvi_version_id", 0x95))]
    monitors = {bus: I2CBusMonitor() for bus in I2C_BUSES}
    for bus in I2C_BUSES:
        start_cocotb_targets(getattr(ports.bus, bus), models[bus], monitors[bus])

    frames_sent = {c: [0] for c in CAMERAS}

    async def camera(c, seed):
        model = models[f"cam_{c}"][0]
        sensor = setup.sensor(model, seed=seed)
        while not model.sensor_config().rgb565:
            await Timer(1000, unit="ns")
        pins = getattr(ports, f"cam_{c}")
        await drive_cocotb(_counted(sensor.frames([images[c]] * 1_000_000, tail=False, max_idle=10),
                                    frames_sent[c]),
                           clk=pins.pclk, pins=pins, pclk_hz=setup.pclk_hz,
                           start_delay=setup.cam_phase_s.get(c, 0.0))

    for seed, c in enumerate(CAMERAS):
        cocotb.start_soon(camera(c, seed))

    await Timer(200, unit="ns")
    ports.btn_rst_n.value = 1
    await _wait(lambda: str(ports.ch7301c.reset_n.value) == "1", "the clocks locking (reset pins released)", 1e-3, 50)
    status["t_locked_us"] = now_ps() * 1e-6
    status["mclk"] = {c: _period_stats(*await _edges(getattr(ports, f"cam_{c}").mclk, 20), 1e12 / PLAN.mclk_hz)
                      for c in CAMERAS}
    xp, xn = await _xclk_pair(ports.ch7301c, 64)
    status["xclk"] = _period_stats(*xp, 1e12 / PLAN.pix_hz)
    status["xclk_n_is_complement"] = _complement(xp, xn)

    def bus_finished():                         # LD0, LD2, LD4: the three buses done; LD1 / LD3: an error
        led = int(ports.panel.leds.value)
        return led & 0b10101 == 0b10101 or led & 0b1010
    await _wait(bus_finished, "the I2C bring-up of the three buses", PARAMS.get("init_timeout_ms", 50) * 1e-3,
                2000)
    status["t_init_us"] = now_ps() * 1e-6
    status["leds_after_init"] = int(ports.panel.leds.value)

    for word in setup.switch_words():
        ports.panel.sw.value = word
        await Timer(round(30e12 / PLAN.pix_hz), unit="ps")

    await _wait(lambda: all(frames_sent[c][0] >= 1 for c in CAMERAS), "a whole frame sent by both cameras",
                PARAMS.get("capture_timeout_ms", 100) * 1e-3, 1000 if g.width < 100 else 20_000)
    status["t_captured_us"] = now_ps() * 1e-6
    await Timer(2, unit="us")                   # the capture pipelines drain

    sink = HdmiSink(t, starts_at_frame=False)
    eye = EyeMeter(ports.ch7301c.data) if PARAMS.get("measure_eye", True) else None
    leds_at_vsync = []
    edges = await sample_ch7301c(ports, sink, max_clocks=3 * t.clocks_per_frame, leds_at_vsync=leds_at_vsync)
    if eye is not None:
        eye.running = False
        status["eye_ps"] = dict(zip(("setup", "hold"), eye.margins(edges)))
    for _ in range(6):                          # LEDs over a few more display frames (heartbeat, ID LED)
        await Timer(round(t.clocks_per_frame * 1e12 / PLAN.pix_hz / 2), unit="ps")
        leds_at_vsync.append(int(ports.panel.leds.value))
    status["leds"] = leds_at_vsync
    pins = {"cam_vdden": ports.cam_vdden, "cam_a_rst_n": ports.cam_a.rst_n, "cam_b_rst_n": ports.cam_b.rst_n,
            "cam_a_pwdn": ports.cam_a.pwdn, "cam_b_pwdn": ports.cam_b.pwdn, "dvi_reset_n": ports.ch7301c.reset_n}
    status["pins"] = {n: str(h.value) for n, h in pins.items()}
    _finish(status, setup, models, monitors, sink, images, out_dir)


def _complement(xp, xn):
    """XCLK_N rises exactly when XCLK_P falls and falls when it rises (inside the window both recorded)."""
    lo, hi = xp[0][0], xp[1][-1]
    rises = [t for t in xn[0] if lo <= t <= hi]
    falls = [t for t in xn[1] if lo <= t <= hi]
    return bool(rises) and set(rises) <= set(xp[1]) and set(falls) <= set(xp[0]) and len(rises) >= len(xp[1]) - 2


async def _xclk_pair(ch, count):
    xp = cocotb.start_soon(_edges(ch.xclk_p, count))
    xn = cocotb.start_soon(_edges(ch.xclk_n, count - 1))
    return await xp, await xn


def _state_diff(model, expected):
    state = model.state()
    return {k: [repr(state.get(k)), repr(e.value)] for k, e in expected.items() if state.get(k) != e.value}


def _finish(status, setup, models, monitors, sink, images, out_dir):
    frame, golden = check_run(status, setup, images["a"], images["b"], sink, models, monitors, after_s=0.0)
    np.save(out_dir / "golden.npy", golden)
    if frame is not None:
        np.save(out_dir / "frame.npy", frame)
    status["state_diff"] = {b: _state_diff(models[b][0], mt9d112_expected(setup.geometry))
                            for b in ("cam_a", "cam_b")}
    status["state_diff"]["dvi"] = _state_diff(models["dvi"][0], ch7301c_expected(setup.timing))
    status["problems"] = {b: models[b][0].problems() for b in I2C_BUSES}
    status["i2c_violations"] = {b: [str(v) for v in monitors[b].violations(require_all=False)] for b in I2C_BUSES}
    (out_dir / "result.json").write_text(json.dumps(status, indent=1, default=str))
    _check(status, setup)


def _check(status, setup):
    expect_mismatch = PARAMS.get("dvi_version_id", 0x95) != 0x95
    for c in CAMERAS:
        m = status["mclk"][c]
        assert abs(m["mean_ps"] - m["ideal_ps"]) < 1 and m["max_ps"] - m["min_ps"] <= 1, f"MCLK {c}: {m}"
    x = status["xclk"]
    assert abs(x["mean_ps"] - x["ideal_ps"]) < 1 and x["max_ps"] - x["min_ps"] <= 1, f"XCLK: {x}"
    assert abs(x["high_min_ps"] - x["ideal_ps"] / 2) <= 1, f"XCLK duty: {x}"
    assert status["xclk_n_is_complement"], "XCLK_N does not switch opposite XCLK_P on the same instants"
    quarter = status["xclk"]["ideal_ps"] / 4
    if "eye_ps" in status:
        eye = status["eye_ps"]
        assert eye["setup"] >= quarter - 2 and eye["hold"] >= quarter - 2, \
            f"data changes {eye} ps from an XCLK edge, expected a quarter pixel period ({quarter:.0f} ps)"
    assert status["leds_after_init"] & 0b10101 == 0b10101 and not status["leds_after_init"] & 0b1010, \
        f"LEDs after the bring-up: {status['leds_after_init']:08b} (want LD0, LD2, LD4 on, LD1, LD3 off)"
    led5 = [(v >> 5) & 1 for v in status["leds"]]
    led6 = [(v >> 6) & 1 for v in status["leds"]]
    if PARAMS.get("check_heartbeat", True):          # the board's rate (32 frames) needs a longer window
        assert len(set(led6)) == 2, f"LD6 (display heartbeat) did not toggle: {led6}"
    if expect_mismatch:
        assert led5 == led6, f"LD5 does not blink with LD6 for a CH7301C ID mismatch: {led5} vs {led6}"
    else:
        assert not any(led5), f"LD5 lit without an error or ID mismatch: {led5}"
    assert status["pins"] == {"cam_vdden": "1", "cam_a_rst_n": "1", "cam_b_rst_n": "1", "cam_a_pwdn": "0",
                              "cam_b_pwdn": "0", "dvi_reset_n": "1"}, status["pins"]
    for bus in I2C_BUSES:
        assert not status["problems"][bus], f"{bus}: {status['problems'][bus]}"
        assert not status["i2c_protocol_errors"][bus], f"{bus}: {status['i2c_protocol_errors'][bus]}"
        assert not status["state_diff"][bus], f"{bus}: part state differs from golden: {status['state_diff'][bus]}"
    assert not status["violations"], f"HDMI sink: {status['violations'][:5]}"
    assert status["mismatched_pixels"] == 0, f"{status['mismatched_pixels']} pixels differ from the golden frame"
