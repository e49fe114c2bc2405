"""The depth engine (hdl/depth/) against the golden model (golden/depth.py), bit for bit.

Amaranth simulator, small preset (16 x 12 buffers, D = 8, 4 lanes): random pairs under several read-grant
patterns, a synthetic scene with known disparities (sim/testbed/scene.py), uniform images, a shift beyond D, texture
only in the border columns, a restart in the middle of a map, a reader that falls behind. cocotb on Verilator
and Icarus: a small random pair in the default run; at full size (400 x 300, D = 64) the bundled motorcycle
buffers and a random pair (slow).
"""

import dataclasses
import json

import numpy as np
import pytest
from amaranth.hdl import Fragment

from golden.depth import depth_map
from golden.depth_display import engine_left
import hdl.depth.engine as engine_module
from hdl.depth import DepthEngine, schedule
from hdl.depth.engine import line_buffer_pieces
from spec.depth import DEPTH, DIAGONAL_PATHS, SMALL_DEPTH, THREE_PATHS, TWO_PATHS, DepthConfig
from spec.sensor import ROW_TAG_BITS, SENSOR, SMALL_SENSOR, SensorGeometry
from sim.runners.amaranth import simulate
from board.export import export_verilog
from sim.runners.cocotb import run_cocotb
from sim.waves.cocotb import RunWaves
from sim.testbench.depth import DepthTestbench

G, CFG = SMALL_SENSOR, SMALL_DEPTH
SHAPE = (G.buf_height, G.buf_width)
CLOCK_PS = 6734                 # 148.5 MHz
VERILATOR_ARGS = ("-Wno-CASEINCOMPLETE",)      # Amaranth's Verilog style (FSM and switch cases)


def random_pair(seed, shape=SHAPE, top=32):
    rng = np.random.default_rng(seed)
    return rng.integers(0, top, shape), rng.integers(0, top, shape)


def run_engine(left, right, *, geometry=G, config=CFG, grant_mask=0, restart_after=None, hold_clocks=0,
               row_offset=0, timeout=200_000, tag_tables=None, flips=None, platform=None):
    """One map from the testbench in Amaranth's simulator: returns (codes, clocks, reads, rows_ready seen while
    the reader held back). ``tag_tables``: (left, right) per buffer row, tag | busy << ROW_TAG_BITS; ``flips``:
    (left row, right row) whose tag flips at the first ask (None: none). ``platform="formal"`` elaborates the
    blocks' formal invariants too: the simulator raises ``AssertionError`` on the clock one fails."""
    dut = DepthTestbench(geometry, config)
    out = {}

    async def bench(ctx):
        if tag_tables is not None:
            ctx.set(dut.tag_load_en, 1)
            for r in range(geometry.buf_height):
                ctx.set(dut.tag_load_row, r)
                ctx.set(dut.tag_load_left, int(tag_tables[0][r]))
                ctx.set(dut.tag_load_right, int(tag_tables[1][r]))
                await ctx.tick()
            ctx.set(dut.tag_load_en, 0)
        for port, row in zip((dut.flip_left, dut.flip_right), flips or (None, None)):
            ctx.set(port, geometry.buf_height if row is None else row)
        ctx.set(dut.load_en, 1)
        for a in range(geometry.buf_depth):
            ctx.set(dut.load_addr, a)
            ctx.set(dut.load_left, int(left.flat[a]))
            ctx.set(dut.load_right, int(right.flat[a]))
            await ctx.tick()
        ctx.set(dut.load_en, 0)
        ctx.set(dut.grant_mask, grant_mask)
        ctx.set(dut.hold, 1 if hold_clocks else 0)
        ctx.set(dut.row_offset, row_offset)
        await ctx.tick().repeat(2)
        ctx.set(dut.start, 1)
        await ctx.tick()
        ctx.set(dut.start, 0)
        if restart_after is not None:
            await ctx.tick().repeat(restart_after)
            ctx.set(dut.start, 1)
            await ctx.tick()
            ctx.set(dut.start, 0)
        if hold_clocks:
            await ctx.tick().repeat(hold_clocks)
            out["held"] = ctx.get(dut.rows_ready)
            ctx.set(dut.hold, 0)
        for _ in range(timeout):
            if ctx.get(dut.done):
                break
            await ctx.tick()
        else:
            raise AssertionError("no map within the timeout")
        out["clocks"], out["reads"] = ctx.get(dut.clocks), (ctx.get(dut.reads_left), ctx.get(dut.reads_right))
        codes = np.zeros(geometry.buf_depth, dtype=np.int64)
        for a in range(geometry.buf_depth):
            ctx.set(dut.read_addr, a)
            await ctx.tick()
            codes[a] = ctx.get(dut.read_data)
        out["codes"] = codes.reshape(geometry.buf_height, geometry.buf_width)

    simulate(dut if platform is None else Fragment.get(dut, platform), clocks={"sync": 148.5e6}, testbenches=[bench])
    return out["codes"], out["clocks"], out["reads"], out.get("held")


def assert_same(codes, expected):
    bad = np.argwhere(codes != expected)
    assert bad.size == 0, (f"{len(bad)} pixels differ; first (y, x) {bad[:4].tolist()}: RTL "
                           f"{[int(codes[tuple(b)]) for b in bad[:4]]}, golden "
                           f"{[int(expected[tuple(b)]) for b in bad[:4]]}")


@pytest.mark.parametrize("seed, grant_mask", [(1, 0), (2, 0b101), (3, 0b111)])
def test_random_pair_bit_exact(seed, grant_mask):
    """Random pairs; every read granted, 1 in 4 and 1 in 8 clocks granted. Each pixel read once."""
    left, right = random_pair(seed)
    codes, clocks, reads, _ = run_engine(left, right, grant_mask=grant_mask)
    assert_same(codes, depth_map(left, right, CFG))
    assert reads == (G.buf_depth, G.buf_depth)


def test_line_buffer_pieces():
    """The vertical line buffer's pieces of columns: powers of two, in order, covering the width, none smaller than
    a block's words."""
    assert line_buffer_pieces(800, 8) == [(0, 512), (512, 256), (768, 64)]
    assert line_buffer_pieces(400, 4) == [(0, 512)]
    for width, groups, block in [(28, 2, 8), (799, 8, 512), (400, 16, 512), (33, 3, 16)]:
        pieces = line_buffer_pieces(width, groups, block)
        assert [base for base, _ in pieces] == [sum(size for _, size in pieces[:i]) for i in range(len(pieces))]
        assert sum(size for _, size in pieces) >= width
        assert all(size & (size - 1) == 0 and 2 * size * groups > block for _, size in pieces)


@pytest.mark.parametrize("paths", [TWO_PATHS, DIAGONAL_PATHS])
def test_line_buffer_in_pieces(paths, monkeypatch):
    """The vertical line buffer in three pieces (blocks of 8 words: 16 + 8 + 4 of 28 columns), read across their
    edges (the diagonal at x + 1): bit for bit."""
    monkeypatch.setattr(engine_module, "LINE_BLOCK_WORDS", 8)
    assert line_buffer_pieces(28, CFG.disparities // CFG.lanes, 8) == [(0, 16), (16, 8), (24, 4)]
    geometry = SensorGeometry(width=28 * G.scale, height=G.height)
    config = dataclasses.replace(CFG, paths=paths)
    left, right = random_pair(12, (geometry.buf_height, geometry.buf_width))
    codes, *_ = run_engine(left, right, geometry=geometry, config=config, grant_mask=0b1)
    assert_same(codes, depth_map(left, right, config))


@pytest.mark.parametrize("offset", [3, SHAPE[0] - 1, -1, -3, -(SHAPE[0] - 1)])
def test_left_row_offset_bit_exact(offset):
    """The signed rectification moves the left image up (or down) for the engine: row y of the map is matched
    against left row min(max(y + offset, 0), H - 1) (golden.depth_display.engine_left); the boundary values
    +-(H - 1) included (every row the last or the first); H reads per map as without an offset."""
    left, right = random_pair(11)
    h = SHAPE[0]
    if offset >= 0:
        left[offset:] = right[:h - offset]               # a vertical misalignment the offset undoes
    else:
        left[:h + offset] = right[-offset:]
    codes, _, reads, _ = run_engine(left, right, grant_mask=0b11, row_offset=offset)
    assert_same(codes, depth_map(engine_left(left, offset), right, CFG))
    assert reads == (G.buf_depth, G.buf_depth)


def test_edge_cases_bit_exact():
    """Uniform images (every cost 0: disparity 0 everywhere), a shift beyond D, texture only in the border
    columns where x + d leaves the image; one simulation each."""
    rng = np.random.default_rng(7)
    flat = np.full(SHAPE, 11)
    texture = rng.integers(0, 32, (SHAPE[0], SHAPE[1] + CFG.disparities + 3))
    beyond_left = texture[:, :SHAPE[1]]
    beyond_right = texture[:, CFG.disparities + 3:]       # right(x) = left(x + D + 3)
    border = np.zeros(SHAPE, dtype=np.int64)
    border[:, -CFG.disparities:] = rng.integers(0, 32, (SHAPE[0], CFG.disparities))
    for left, right in ((flat, flat), (beyond_left, beyond_right), (border, border[:, ::-1].copy())):
        expected = depth_map(left, right, CFG)
        codes, *_ = run_engine(left, right)
        assert_same(codes, expected)
    assert (depth_map(flat, flat, CFG) == 0).all()


def test_synthetic_scene_bit_exact():
    """A textured card before a textured wall (sim/testbed/scene.py), at buffer disparities 5 and 2: the RTL equals the
    golden map, and the golden map finds the card's disparity."""
    from golden.capture import capture_frame
    from sim.testbed.scene import PlanarObject, StereoRig, object_footprint, render_pair

    rig = StereoRig(width=G.width, height=G.height)
    z = [rig.focal_px * rig.baseline_m / (G.scale * d) for d in (2, 5)]
    scene = (PlanarObject("rectangle", (3.0, 3.0), z[0], finish="textured", texel_m=0.05),
             PlanarObject("rectangle", (0.12, 0.1), z[1], finish="textured", texel_m=0.025))
    left_rgb, right_rgb = render_pair(scene, rig)
    left, right = capture_frame(left_rgb, G), capture_frame(right_rgb, G)
    expected = depth_map(left, right, CFG)
    codes, *_ = run_engine(left, right, grant_mask=0b11)
    assert_same(codes, expected)
    card = object_footprint(scene, rig, index=1)
    assert card.sum() >= 12 and abs(np.median(expected[card]) / CFG.fraction - 5) <= 1 / 8


def test_three_row_buffer_with_formal_invariants():
    """A 3-row buffer: H + 1 = 4 is a power of two, and the pass counter counts to H + 1 once the map is done
    (then it must not wrap to 0). The map equals the golden one, and the engine's formal invariants, elaborated for
    the formal platform and checked by the simulator on every clock, hold through the map and the reads after it
    (``rows_ready_trails_pass``: rows_ready = y - 1)."""
    geometry = SensorGeometry(width=G.width, height=3 * G.scale)
    left, right = random_pair(5, (geometry.buf_height, geometry.buf_width))
    codes, *_ = run_engine(left, right, geometry=geometry, grant_mask=0b1, platform="formal")
    assert_same(codes, depth_map(left, right, CFG))


@pytest.mark.parametrize("rows", [6, pytest.param(14, marks=pytest.mark.slow)])
def test_census_rows_below_the_last_row_clamped(rows):
    """Heights where the last rows' census rows (y + 3 at the last pass) pass the pass counter's own range (6 rows:
    y counts 0..7, three bits, and row 5's window reaches row 8): the rows are clamped to the last, not wrapped
    to the top; the map equals the golden one."""
    geometry = SensorGeometry(width=G.width, height=rows * G.scale)
    left, right = random_pair(5, (geometry.buf_height, geometry.buf_width))
    codes, *_ = run_engine(left, right, geometry=geometry)
    assert_same(codes, depth_map(left, right, CFG))


def test_restart_and_slow_reader():
    """``start`` again in the middle of a map gives the map of a fresh start; a reader that holds back stops
    the engine after ``out_rows`` rows, and the map is still exact."""
    left, right = random_pair(11)
    expected = depth_map(left, right, CFG)
    codes, *_ = run_engine(left, right, restart_after=700)
    assert_same(codes, expected)
    codes, _, _, held = run_engine(left, right, hold_clocks=6000)
    assert held == 4
    assert_same(codes, expected)


# --- row tags (docs/depth.md, "Rows from different camera frames") --------------------------------------------

BUSY = 1 << ROW_TAG_BITS


def engine_tags(table, flip=None, row_offset=0):
    """The tags the engine sees per engine row: the table's (None where busy), the flip row None at its first
    fetch and flipped after it; the left rows through the rectification."""
    h = len(table)
    tags, flipped = [], False
    for r in range(h):
        b = min(max(r + row_offset, 0), h - 1)
        value = int(table[b])
        if b == flip:
            tags.append(None if not flipped else (value & (BUSY - 1)) ^ 1)
            flipped = True
        else:
            tags.append(None if value & BUSY else value)
    return tags


def tag_case(tables, flips=(None, None), row_offset=0, grant_mask=0, seed=31, some_valid=True):
    left, right = random_pair(seed)
    tags = (engine_tags(tables[0], flips[0], row_offset), engine_tags(tables[1], flips[1]))
    expected = depth_map(engine_left(left, row_offset), right, CFG, row_tags=tags)
    codes, _, reads, _ = run_engine(left, right, grant_mask=grant_mask, row_offset=row_offset,
                                    tag_tables=tables, flips=flips)
    assert_same(codes, expected)
    assert reads == (G.buf_depth, G.buf_depth)
    assert (expected != CFG.invalid).any() == some_valid
    return codes, expected, tags


def steps(h, k, before=3, after=4):
    return np.array([before] * k + [after] * (h - k))


@pytest.mark.parametrize("left_k, right_k, grant_mask", [(5, 5, 0), (8, 8, 0b101), (3, 7, 0b11), (11, None, 0)])
def test_tag_changes(left_k, right_k, grant_mask):
    """The next camera frame pair's tag from row left_k in the left image and right_k in the right one (None:
    none): rows whose census window holds two pairs' rows, or a left row of one pair beside a right row of the
    other, are invalid, the vertical path restarted below them, bit for bit with the golden map (which differs
    from the map without tags)."""
    h = SHAPE[0]
    tables = tuple(np.full(h, 3) if k is None else steps(h, k) for k in (left_k, right_k))
    codes, expected, tags = tag_case(tables, grant_mask=grant_mask)
    left, right = random_pair(31)
    assert (expected != depth_map(left, right, CFG)).any()
    if left_k != right_k:            # rows between the two changes pair different frames: invalid, though in
        between = range(min(left_k, right_k or h), max(left_k, right_k or h))    # each image alone untorn
        assert all(tags[0][r] != tags[1][r] for r in between)
        assert (expected[list(between)] == CFG.invalid).all()


@pytest.mark.parametrize("right_k", [None, 10])
def test_images_of_different_pairs_are_invalid(right_k):
    """Left rows all of pair 4 (left from row 2 on, above it 3); the right rows all of pair 3 (from row 10 on: 4):
    no row's census window holds one pair's rows only in both images, so every code is invalid, as the golden
    map says (row 6 only through the comparison of the two images' tags)."""
    h = SHAPE[0]
    left_table = np.full(h, 4) if right_k is None else steps(h, 2)
    tag_case((left_table, np.full(h, 3) if right_k is None else steps(h, right_k)), grant_mask=0b10,
             some_valid=False)


def test_torn_by_a_flip_between_the_samples():
    """Left row 6 and right row 2 (tag 3 among 2s) change their tags to their neighbours' after the engine's first
    ask: each is torn (its start and end samples differ), although its end sample alone agrees with every other
    row (so a missing start or end sample shows)."""
    h = SHAPE[0]
    left_table, right_table = np.full(h, 2), np.full(h, 2)
    left_table[6], right_table[2] = 3, 3
    _, _, tags = tag_case((left_table, right_table), flips=(6, 2), grant_mask=0b1)
    assert tags[0][6] is None and tags[1][2] is None


def test_busy_rows_and_a_rectified_left_image():
    """Busy rows are torn: left buffer row 0 with the left image moved down 2 rows (engine rows 0 .. 2 read it:
    three torn rows, rows 0 .. 5 invalid), right row 11 (rows 8 .. 11 invalid)."""
    h = SHAPE[0]
    left_table = np.full(h, 1)
    left_table[0] |= BUSY
    right_table = np.full(h, 1)
    right_table[11] |= BUSY
    _, _, tags = tag_case((left_table, right_table), row_offset=-2, grant_mask=0b11)
    assert tags[0][:4] == [None, None, None, 1] and tags[1][11] is None


def test_constructor_checks_and_d128_elaborates():
    with pytest.raises(ValueError, match="lanes"):
        DepthEngine(G, DepthConfig(disparities=8, lanes=3))
    with pytest.raises(ValueError, match="D = 32"):
        DepthEngine(G, DepthConfig(disparities=32, lanes=4))
    with pytest.raises(ValueError, match="census"):
        DepthEngine(G, DepthConfig(disparities=8, lanes=4, census_width=6))
    with pytest.raises(ValueError, match="tag_margin"):
        DepthEngine(G, CFG, tag_margin=1)
    with pytest.raises(ValueError, match="RTL aggregates"):
        DepthEngine(G, DepthConfig(disparities=8, lanes=4, paths=TWO_PATHS + ("top_left_to_bottom_right",)))
    DepthEngine(G, DepthConfig(disparities=8, lanes=4, paths=THREE_PATHS))     # tests/test_depth_engine_three.py
    Fragment.get(DepthEngine(SENSOR, DepthConfig(disparities=128)), None)
    assert schedule(SENSOR, DepthConfig(disparities=128)).step_clocks == 8 + 4


def test_schedule_fits_a_display_row():
    """The board engine's pass fits the two 1080p lines that show a buffer row at 2x (2 x 2200 clocks)."""
    plan = schedule(SENSOR, DEPTH)
    assert plan.step_clocks == 8
    assert plan.pass_clocks + 3 < 2 * 2200


# --- cocotb ----------------------------------------------------------------------------------------------

def run_cocotb_depth(left, right, geometry, config, simulator, tmp_path, grant_mask=0, tag_tables=None,
                     flips=(None, None)):
    data = tmp_path / "depth.npz"
    h = geometry.buf_height
    if tag_tables is None:
        np.savez(data, left=left, right=right, expected=depth_map(left, right, config))
    else:
        tags = (engine_tags(tag_tables[0], flips[0]), engine_tags(tag_tables[1], flips[1]))
        np.savez(data, left=left, right=right, expected=depth_map(left, right, config, row_tags=tags),
                 left_tags=tag_tables[0], right_tags=tag_tables[1],
                 flips=[h if f is None else f for f in flips])
    result = tmp_path / "result.json"
    name = f"depth_testbench_{geometry.buf_width}x{geometry.buf_height}_d{config.disparities}"
    if config.paths != TWO_PATHS:
        name += f"_p{len(config.paths)}"
    if config.left_right:
        name += "_lr"
    verilog = export_verilog(DepthTestbench(geometry, config), name)
    run_cocotb(verilog, name=name, test_module="cocotb_depth", simulator=simulator,
               build_args=VERILATOR_ARGS if simulator == "verilator" else (),
               run_waves=RunWaves(design=lambda: DepthTestbench(geometry, config)),   # STEREO_WAVES=1: FSM names
               params=dict(data=str(data), result=str(result), clock_ps=CLOCK_PS, grant_mask=grant_mask,
                           timeout_clocks=3_000_000))
    return json.loads(result.read_text())


def test_depth_cocotb_small(simulator, tmp_path):
    left, right = random_pair(5)
    outcome = run_cocotb_depth(left, right, G, CFG, simulator, tmp_path, grant_mask=0b101)
    assert outcome["mismatches"] == 0


def test_depth_cocotb_row_tags(simulator, tmp_path):
    """Row tags through the Verilog: a tag change at row 3 in the left image and at row 4 in the right (rows 0 .. 6
    invalid, the vertical path restarted at row 7), left row 11 torn by a flip between its two samples, right row
    11 busy (rows 8 .. 11 invalid)."""
    left, right = random_pair(6)
    h = SHAPE[0]
    right_table = steps(h, 4)
    right_table[11] |= BUSY
    outcome = run_cocotb_depth(left, right, G, CFG, simulator, tmp_path, grant_mask=0b11,
                               tag_tables=(steps(h, 3), right_table), flips=(11, None))
    assert outcome["mismatches"] == 0


@pytest.mark.slow
@pytest.mark.parametrize("pair", ["motorcycle", "random"])
def test_depth_cocotb_full_size(simulator, pair, tmp_path):
    """400 x 300, D = 64: the bundled motorcycle buffers (as the system captures them) and a random pair."""
    if pair == "motorcycle":
        from golden.capture import capture_frame
        from golden.stereo_pair import load_default_pair
        left_rgb, right_rgb = load_default_pair(SENSOR.width, SENSOR.height)
        left, right = capture_frame(left_rgb, SENSOR), capture_frame(right_rgb, SENSOR)
    else:
        left, right = random_pair(9, (SENSOR.buf_height, SENSOR.buf_width))
    outcome = run_cocotb_depth(left, right, SENSOR, DEPTH, simulator, tmp_path, grant_mask=0b1)
    assert outcome["mismatches"] == 0
    print(f"{simulator} {pair}: {outcome['clocks']} clocks from start to the last row")
