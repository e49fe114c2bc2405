"""The depth engine with the diagonal as its second path (``DIAGONAL_PATHS``: left to right, top right to bottom
left, p' = (x + 1, y - 1): docs/depth.md, "Paths") against golden.depth.depth_map, bit for bit, on Amaranth's
simulator at the small size (16 x 12 buffers, D = 8, 4 lanes).

Each map is also checked to differ from the maps of wrong diagonals, computed here from the golden model's steps:
the line buffer read at word x (top to bottom but for the start at x = W - 1), the read at x = W - 1 not zeroed
(word 0: where the address x + 1 = W wraps on this 16-word buffer) and the restart rule not applied. The map with
torn rows tells the first and the third apart, the map whose right edge decides the second and the first, so an
engine with one of those faults fails. Two maps in the default run; the Verilog on Verilator and Icarus slow."""

import dataclasses

import numpy as np
import pytest
from amaranth.hdl import Fragment

from golden.depth import depth_map, matching_cost, median3x3, path_cost, path_step, row_flags, winner
from hdl.depth import DepthEngine, schedule
from hdl.depth.engine import check_parameters
from spec.depth import DIAGONAL_PATHS, PATH_STEPS, TWO_PATHS
from tests.test_depth_engine import (BUSY, CFG, G, SHAPE, assert_same, engine_tags, random_pair, run_cocotb_depth,
                                     run_engine, steps)

CFG_DIAGONAL = dataclasses.replace(CFG, paths=DIAGONAL_PATHS)


def diagonal_map(left, right, config, row_tags, fault=None):
    """The map with the diagonal computed here row by row, as the engine does, with ``fault``: None, "word_x" (row
    y - 1's word x read, 0 at x = W - 1), "no_zero" (word 0 read at x = W - 1) or "no_restart" (the tag restarts
    ignored; row 0 starts the path)."""
    cost = matching_cost(left, right, config).astype(np.int32)
    invalid_rows, restart_rows = row_flags(row_tags, cost.shape[1], config)
    above = np.zeros(cost[:, 0, :].shape, dtype=np.int32)
    diagonal = np.empty_like(cost)
    for y in range(cost.shape[1]):
        if y == 0 or (restart_rows[y] and fault != "no_restart"):
            above = np.zeros_like(above)
        prev = np.zeros_like(above)
        if fault == "word_x":
            prev[:, :-1] = above[:, :-1]
        else:
            prev[:, :-1] = above[:, 1:]
            if fault == "no_zero":
                prev[:, -1] = above[:, 0]
        above = diagonal[:, y, :] = path_step(cost[:, y, :], prev, config.p1, config.p2)
    raw, _ = winner(path_cost(cost, "left_to_right", config) + diagonal, config)
    raw[invalid_rows] = config.invalid
    return median3x3(raw)


def check(left, right, *, faults, tables=None, **kwargs):
    """One map of the diagonal engine: equal to the golden map (with the tags the engine sees), unlike the two-path
    map and unlike the map of each wrong diagonal in ``faults``; every pixel read once."""
    tags = None if tables is None else (engine_tags(tables[0]), engine_tags(tables[1]))
    codes, _, reads, _ = run_engine(left, right, config=CFG_DIAGONAL, tag_tables=tables, **kwargs)
    expected = depth_map(left, right, CFG_DIAGONAL, row_tags=tags)
    assert_same(codes, expected)
    assert reads == (G.buf_depth, G.buf_depth)
    assert (expected != depth_map(left, right, CFG, row_tags=tags)).any()
    for fault in faults:
        assert (expected != diagonal_map(left, right, CFG_DIAGONAL, tags, fault)).any(), fault
    return expected


def test_the_model_of_the_faults():
    """Without a fault the diagonal here is the golden model's (with and without tags)."""
    assert PATH_STEPS[DIAGONAL_PATHS[1]] == (1, -1) and DIAGONAL_PATHS[0] == TWO_PATHS[0]
    left, right = random_pair(41)
    h = SHAPE[0]
    tags = (engine_tags(steps(h, 5)), engine_tags(steps(h, 7)))
    for row_tags in (None, tags):
        assert (diagonal_map(left, right, CFG_DIAGONAL, row_tags) == depth_map(left, right, CFG_DIAGONAL,
                                                                                row_tags=row_tags)).all()


def test_the_rtl_takes_the_pair():
    """``DIAGONAL_PATHS`` elaborates, with the two-path schedule; the pair in the other order, or the other diagonal,
    is refused by name (``check_parameters``: DepthEngine's check)."""
    Fragment.get(DepthEngine(G, CFG_DIAGONAL), None)
    assert schedule(G, CFG_DIAGONAL) == schedule(G, CFG)
    for paths in (DIAGONAL_PATHS[::-1], ("left_to_right", "top_left_to_bottom_right")):
        with pytest.raises(ValueError, match="or left_to_right, top_right_to_bottom_left only"):
            check_parameters(G, dataclasses.replace(CFG, paths=paths))


def test_diagonal_bit_exact_with_torn_rows():
    """A random pair with 1 in 4 reads granted, the next frame pair from row 6 in both images and right row 2
    busy (torn): rows invalid around them, the diagonal restarted below them (a fault at x = W - 1 hides here,
    under the invalid right border and the median: :func:`test_diagonal_right_edge`)."""
    left, right = random_pair(21)
    h = SHAPE[0]
    left_table, right_table = steps(h, 6), steps(h, 6)
    right_table[2] |= BUSY
    expected = check(left, right, tables=(left_table, right_table), grant_mask=0b11, faults=("word_x", "no_restart"))
    assert (expected == CFG.invalid).any() and (expected != CFG.invalid).any()


def test_diagonal_right_edge():
    """A textured scene at disparity 5, every read granted: the right image's last 5 columns match beyond the left
    image's edge (cost N there from d = W - x on), so their codes come from the paths, the diagonal's start at x =
    W - 1 among them; a read of row y - 1 there instead of 0 changes 44 codes (the lower right corner)."""
    h, w = SHAPE
    scene = np.random.default_rng(5).integers(0, 32, (h, w + 5))
    left, right = scene[:, :w], scene[:, 5:]              # right(x) = left(x + 5)
    expected = check(left, right, faults=("word_x", "no_zero"))
    assert (np.abs(expected[:, :w - 5].astype(int) - 5 * CFG.fraction) <= CFG.fraction // 2).all()
    assert (expected[:, w - 5:] != CFG.invalid).all()


@pytest.mark.slow
def test_diagonal_cocotb_small(simulator, tmp_path):
    """The diagonal engine's Verilog on Verilator and Icarus (cocotb): a random pair with 1 in 4 reads granted
    and a tag change at rows 3 (left) and 4 (right), equal to the golden map (which a diagonal read at word x or
    without the restart would not give)."""
    left, right = random_pair(5)
    h = SHAPE[0]
    tables = (steps(h, 3), steps(h, 4))
    tags = (engine_tags(tables[0]), engine_tags(tables[1]))
    expected = depth_map(left, right, CFG_DIAGONAL, row_tags=tags)
    for fault in ("word_x", "no_restart"):
        assert (expected != diagonal_map(left, right, CFG_DIAGONAL, tags, fault)).any(), fault
    outcome = run_cocotb_depth(left, right, G, CFG_DIAGONAL, simulator, tmp_path, grant_mask=0b101,
                               tag_tables=tables)
    assert outcome["mismatches"] == 0
