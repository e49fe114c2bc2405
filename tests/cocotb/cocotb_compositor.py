"""cocotb test of the display path: SwitchControl + Compositor + two FrameBuffers (tests/test_compositor.py
builds the testbench ``DisplayTestbench`` and runs this module on Verilator and Icarus).

The test loads the two buffers through their write ports, drives the raster (``timing__*``) from the reference
raster below (not from the RTL sync generator) and moves the switches in the middle of frames as the schedule
says; it records every output clock and checks the whole stream against the golden frames (computed by
``golden.disparity.composite_frame`` in the pytest process and handed over in an ``.npz`` file).

The helpers (:func:`reference_raster`, :func:`switch_events`, :func:`check_stream`) are also used by the
Amaranth-simulator test, so both simulators are held to the same checks.
"""

import numpy as np

SW7 = 0x80


def reference_raster(timing):
    """One frame of the raster, clock by clock, straight from the timing numbers: dict of int arrays
    ``x``, ``y``, ``de``, ``hsync``, ``vsync``, ``frame_start`` (length ``timing.clocks_per_frame``).

    ``x`` runs 0..h_total-1 along a line, ``y`` 0..v_total-1 down the frame; active pixels first on both;
    sync pulses after the front porches (vsync whole lines here: the compositor only delays it)."""
    x = np.tile(np.arange(timing.h_total), timing.v_total)
    y = np.repeat(np.arange(timing.v_total), timing.h_total)
    de = (x < timing.h_active) & (y < timing.v_active)
    hs = (x >= timing.h_sync_start) & (x < timing.h_sync_start + timing.h_sync)
    vs = (y >= timing.v_sync_start) & (y < timing.v_sync_start + timing.v_sync)
    if not timing.hsync_positive:
        hs = ~hs
    if not timing.vsync_positive:
        vs = ~vs
    fs = (x == 0) & (y == 0)
    return {k: v.astype(np.int64) for k, v in
            dict(x=x, y=y, de=de, hsync=hs, vsync=vs, frame_start=fs).items()}


def switch_events(schedule, timing, hold=8):
    """``{clock: sw value}`` and the settings in force for each frame.

    ``schedule`` lists, for frames 1, 2, ..., a dict with ``line`` (and optionally ``column``, default 1) of the
    *previous* frame where the user moves the switches, and ``disparity`` and/or ``rectification`` (either may
    be missing: that register must keep its value; the rectification is signed). The disparity is set first (SW7 = 1), the rectification
    ``hold`` clocks later (SW7 = 0). Frame 0 shows the reset values (0, 0).
    """
    events = {}
    settings = [(0, 0)]
    cpf = timing.clocks_per_frame
    for k, entry in enumerate(schedule, start=1):
        t = (k - 1) * cpf + entry["line"] * timing.h_total + entry.get("column", 1)
        d, r = settings[-1]
        if entry.get("disparity") is not None:
            d = entry["disparity"]
            events[t] = SW7 | d
            t += hold
        if entry.get("rectification") is not None:
            r = entry["rectification"]
            events[t] = r & (SW7 - 1)            # SW6..SW0: two's complement (hdl/switches.py)
        if t >= k * cpf - 4:
            raise ValueError("switch change too close to the next frame_start for a deterministic test")
        settings.append((d, r))
    return events, settings


def check_stream(timing, latency, n_frames, out, expected_frames):
    """Check the recorded outputs ``out`` (dict of int arrays ``rgb``, ``de``, ``hsync``, ``vsync``: the values
    *during* clock ``c``; frame 0 of the raster starts at clock 0, before which the raster sat at its last
    position for at least ``latency`` clocks) against the reference raster delayed by ``latency`` and the
    golden frames (n_frames, v_active, h_active, 3)."""
    raster = reference_raster(timing)
    total = n_frames * timing.clocks_per_frame
    assert len(out["de"]) >= total + latency
    for name in ("de", "hsync", "vsync"):
        got = np.asarray(out[name][:total + latency])
        # Before clock 0 the raster sat at its last position (the end of a previous frame's blanking).
        want = np.concatenate([np.full(latency, raster[name][-1]), np.tile(raster[name], n_frames)])
        bad = np.flatnonzero(got != want)
        assert bad.size == 0, f"{name} differs from the raster delayed by {latency} at clocks {bad[:8]}"
    rgb = np.asarray(out["rgb"][:total + latency])
    de = np.asarray(out["de"][:total + latency]).astype(bool)
    assert not rgb[~de].any(), f"rgb not 0 outside the active area at clocks {np.flatnonzero(rgb * ~de)[:8]}"
    pixels = rgb[de]
    frame_pixels = timing.h_active * timing.v_active
    assert pixels.size == n_frames * frame_pixels
    got = np.stack([(pixels >> 16) & 0xFF, (pixels >> 8) & 0xFF, pixels & 0xFF], axis=-1).astype(np.uint8)
    got = got.reshape(n_frames, timing.v_active, timing.h_active, 3)
    for k in range(n_frames):
        diff = np.argwhere((got[k] != expected_frames[k]).any(axis=-1))
        assert diff.size == 0, (f"frame {k}: {len(diff)} pixels differ from the golden frame, first (y, x) "
                                f"{diff[:5].tolist()}: got {got[k][tuple(diff[0])]} want "
                                f"{expected_frames[k][tuple(diff[0])]}")


try:
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge
except ImportError:          # imported outside a cocotb run (the Amaranth test uses the helpers only)
    cocotb = None


if cocotb is not None:
    @cocotb.test()
    async def composited_frames_match_golden(dut):
        """Load the pair, run the raster with mid-frame switch changes, compare every frame bit for bit."""
        from spec.video import VideoTiming
        from sim.runners.cocotb import test_params

        p = test_params()
        timing = VideoTiming(**p["timing"])
        latency = p["latency"]
        data = np.load(p["data"])
        left, right, expected = data["left"], data["right"], data["expected"]
        n_frames = expected.shape[0]
        events, _ = switch_events(p["schedule"], timing)

        Clock(dut.clk, p["clock_ps"], unit="ps").start()
        clk = dut.clk
        dut.rst.value = 1
        dut.sw.value = 0
        dut.segment.value = int(p.get("segment", False))
        dut.load_en.value = 0
        # During reset and loading the raster sits at its last position (the end of a frame's blanking).
        raster = reference_raster(timing)
        for name in ("x", "y", "de", "hsync", "vsync", "frame_start"):
            getattr(dut, f"timing__{name}").value = int(raster[name][-1])
        for _ in range(3):
            await FallingEdge(clk)
        dut.rst.value = 0

        # Load both buffers through their write ports, one word per clock.
        dut.load_en.value = 1
        for a, (lv, rv) in enumerate(zip(left.ravel().tolist(), right.ravel().tolist())):
            await FallingEdge(clk)
            dut.load_addr.value = a
            dut.load_left.value = lv
            dut.load_right.value = rv
        await FallingEdge(clk)
        dut.load_en.value = 0

        cpf = timing.clocks_per_frame
        total = n_frames * cpf + latency
        handles = [getattr(dut, f"timing__{n}") for n in ("x", "y", "de", "hsync", "vsync", "frame_start")]
        columns = [raster[n].tolist() for n in ("x", "y", "de", "hsync", "vsync", "frame_start")]
        word_h = dut.video_word       # Cat(vsync, hsync, de, rgb): one read per clock
        port_h = (dut.video__rgb, dut.video__de, dut.video__hsync, dut.video__vsync)
        sw_h = dut.sw
        words = np.zeros(total, dtype=np.int64)
        previous = [None] * 6
        for c in range(total):
            await FallingEdge(clk)
            # Outputs during clock c (the registers after the rising edge that began it).
            w = words[c] = int(word_h.value)
            if c % 997 == 0:          # the packed word is the video ports themselves
                ports = [int(h.value) for h in port_h]
                assert ports == [w >> 3, (w >> 2) & 1, (w >> 1) & 1, w & 1], f"video_word at clock {c}"
            # Inputs for clock c (sampled by the rising edge that ends it); the raster repeats every frame.
            i = c % cpf
            for j in range(6):
                v = columns[j][i]
                if v != previous[j]:
                    handles[j].value = v
                    previous[j] = v
            if c in events:
                sw_h.value = events[c]
        out = {"rgb": words >> 3, "de": (words >> 2) & 1, "hsync": (words >> 1) & 1, "vsync": words & 1}
        check_stream(timing, latency, n_frames, out, expected)
