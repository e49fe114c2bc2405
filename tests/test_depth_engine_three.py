"""The depth engine with three paths (left to right, top to bottom, right to left: docs/depth.md, "The third path in
the RTL", scheme a') against golden.depth.depth_map with ``THREE_PATHS``, bit for bit, on Amaranth's simulator at
the small size (16 x 12 buffers, D = 8, 4 lanes). Each map is also checked to differ from the two-path map, so a
three-path engine that dropped its third path would fail. One map in the default run; the others slow."""

import dataclasses

import numpy as np
import pytest

from golden.depth import depth_map
from golden.depth_display import engine_left
from hdl.depth import schedule
from spec.depth import THREE_PATHS, TWO_PATHS
from tests.test_depth_engine import (CFG, G, SHAPE, assert_same, engine_tags, random_pair, run_cocotb_depth,
                                     run_engine, steps)

CFG3 = dataclasses.replace(CFG, paths=THREE_PATHS, max_cost=CFG.max_cost * 3 // 2)


def check(left, right, *, config=CFG3, row_offset=0, tables=None, **kwargs):
    """One map of the three-path engine: equal to the golden three-path map (of the rectified left image, with the
    tags the engine sees) and unlike the two-path one; every pixel read once."""
    tags = None
    if tables is not None:
        tags = (engine_tags(tables[0], None, row_offset), engine_tags(tables[1]))
    codes, clocks, reads, _ = run_engine(left, right, config=config, row_offset=row_offset, tag_tables=tables,
                                         **kwargs)
    shifted = engine_left(left, row_offset)
    expected = depth_map(shifted, right, config, row_tags=tags)
    assert_same(codes, expected)
    assert (codes != depth_map(shifted, right, dataclasses.replace(config, paths=TWO_PATHS), row_tags=tags)).any()
    assert reads == (G.buf_depth, G.buf_depth)
    return codes, expected, clocks


def test_three_paths_bit_exact():
    """A random pair with 1 in 4 reads granted and a tag change at row 8 in both images (rows invalid around it,
    the vertical path restarted below: the third path along the row needs no restart)."""
    left, right = random_pair(21)
    h = SHAPE[0]
    _, expected, _ = check(left, right, grant_mask=0b11, tables=(steps(h, 8), steps(h, 8)))
    assert (expected == CFG3.invalid).any() and (expected != CFG3.invalid).any()


@pytest.mark.slow
@pytest.mark.parametrize("seed, grant_mask", [(1, 0), (2, 0b101)])
def test_three_paths_random_pairs(seed, grant_mask):
    """Random pairs; with every read granted the map takes (H + 1) x ``reverse_clocks`` more than the two-path
    map of the same pair (``hdl.depth.schedule``: the backward steps, their drain and the replay into the
    median)."""
    left, right = random_pair(seed)
    _, _, clocks = check(left, right, grant_mask=grant_mask)
    if grant_mask == 0:
        two_path_clocks = run_engine(left, right)[1]
        extra = schedule(G, CFG3).pass_clocks - schedule(G, CFG).pass_clocks
        assert schedule(G, CFG3).reverse_clocks > 0
        assert clocks - two_path_clocks == (SHAPE[0] + 1) * extra


@pytest.mark.slow
def test_three_paths_rectified_restarted_and_other_parameters():
    """The left image moved up 3 rows; a start again in the middle of a map; D = 6 with 2 lanes and other
    penalties (three groups: the backward candidate select across groups)."""
    left, right = random_pair(11)
    check(left, right, row_offset=3, grant_mask=0b1)
    check(left, right, restart_after=1500)
    config = dataclasses.replace(CFG3, disparities=6, lanes=2, p1=7, p2=60)
    check(*random_pair(12), config=config)


@pytest.mark.slow
def test_three_paths_edges():
    """Texture only in the border columns where x + d leaves the image (the backward pass's first pixels, whose
    candidates lie beyond the last column)."""
    rng = np.random.default_rng(7)
    border = np.zeros(SHAPE, dtype=np.int64)
    border[:, -CFG.disparities:] = rng.integers(0, 32, (SHAPE[0], CFG.disparities))
    border[:, :3] = rng.integers(0, 32, (SHAPE[0], 3))
    check(border, border[:, ::-1].copy())


@pytest.mark.slow
def test_three_paths_with_formal_invariants():
    """A 3-row buffer with the engine's formal invariants elaborated and checked by the simulator on every clock
    (the backward phase, its drain and the replay included): they hold, and the map is exact."""
    from spec.sensor import SensorGeometry
    geometry = SensorGeometry(width=G.width, height=3 * G.scale)
    left, right = random_pair(5, (geometry.buf_height, geometry.buf_width))
    codes, *_ = run_engine(left, right, geometry=geometry, config=CFG3, grant_mask=0b1, platform="formal")
    assert_same(codes, depth_map(left, right, CFG3))


@pytest.mark.slow
def test_three_paths_cocotb_small(simulator, tmp_path):
    """The three-path engine's Verilog on Verilator and Icarus (cocotb): a random pair with 1 in 4 reads granted
    and a tag change at rows 3 (left) and 4 (right), equal to the golden three-path map."""
    left, right = random_pair(5)
    h = SHAPE[0]
    outcome = run_cocotb_depth(left, right, G, CFG3, simulator, tmp_path, grant_mask=0b101,
                               tag_tables=(steps(h, 3), steps(h, 4)))
    assert outcome["mismatches"] == 0
