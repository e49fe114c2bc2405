"""The depth engine with the left-right check and the background fill (``DepthConfig.left_right``: docs/depth.md,
"left-right check") against golden.depth.depth_map, bit for bit, on Amaranth's simulator at the small size (16 x
12 buffers, D = 8, 4 lanes): two paths and the diagonal pair, the 3 x 3 and the separable 5 x 5 median, torn rows
and a new frame pair in the middle, a restart in the middle of a map. Each map also differs from the map without
the check. One map in the default run, the others slow."""

import dataclasses

import numpy as np
import pytest
from amaranth.hdl import Fragment

from golden.depth import depth_map
from hdl.depth import DepthEngine, schedule
from hdl.depth.engine import check_parameters, row_lag
from hdl.depth.left_right_fill import LeftRightFill
from hdl.depth.median import Median3x3
from hdl.stereo_display import check_map_rate
from spec.depth import DEPTH_800_BASE, DIAGONAL_PATHS, THREE_PATHS, TWO_PATHS
from spec.sensor import SENSOR_800
from spec.video import CEA_1080P60
from tests.test_depth_engine import (BUSY, CFG, G, SHAPE, assert_same, engine_tags, random_pair, run_cocotb_depth,
                                     run_engine, steps)


def config(paths=TWO_PATHS, median=3):
    return dataclasses.replace(CFG, left_right=True, paths=paths, median=median)


def occlusion_pair(seed=7, wall=2, card=5):
    """A textured card at disparity ``card`` before a textured wall at disparity ``wall``: a strip of the wall
    beside the card hidden from the left camera (where the check rejects codes and the fill takes the wall's)."""
    h, w = SHAPE
    rng = np.random.default_rng(seed)
    texture, face = rng.integers(0, 32, (h, w + 8)), rng.integers(0, 32, (h, w + 8))
    right, left = texture[:, wall:w + wall].copy(), texture[:, :w].copy()      # right(x) = left(x + wall)
    right[3:9, 5:10] = face[3:9, 5:10]                  # the card in the right image at x 5..9
    left[3:9, 5 + card:10 + card] = face[3:9, 5:10]     # and in the left at x + card
    return left, right


def check(left, right, cfg, tables=None, **kwargs):
    """One map: equal to the golden one (with the tags the engine sees), unlike the map without the check; every
    pixel read once. Returns the golden map."""
    tags = None if tables is None else (engine_tags(tables[0]), engine_tags(tables[1]))
    codes, _, reads, _ = run_engine(left, right, config=cfg, tag_tables=tables, **kwargs)
    expected = depth_map(left, right, cfg, row_tags=tags)
    assert_same(codes, expected)
    assert reads == (G.buf_depth, G.buf_depth)
    assert (expected != depth_map(left, right, dataclasses.replace(cfg, left_right=False), row_tags=tags)).any()
    return expected


def torn_tables():
    """The next frame pair from row 6 in both images, right row 2 busy (torn)."""
    h = SHAPE[0]
    left_table, right_table = steps(h, 6), steps(h, 6)
    right_table[2] |= BUSY
    return left_table, right_table


def test_two_paths_torn_rows():
    """Two paths, the 3 x 3 median: a card before a wall with 1 in 4 reads granted, a new frame pair from row 6
    and a torn row: invalid rows stay invalid (no kept code: the fill leaves them invalid). The engine's formal
    invariants (pass control with the row lag of 2, fetch, tag samples) are checked on every clock. On this pair
    a check that wraps x + d* at W instead of clamping it changes 5 codes of the map (found with the golden
    model)."""
    left, right = occlusion_pair(5, wall=3, card=6)
    expected = check(left, right, config(), tables=torn_tables(), grant_mask=0b11, platform="formal")
    assert (expected == CFG.invalid).any() and (expected != CFG.invalid).any()


@pytest.mark.slow
@pytest.mark.parametrize("paths, median", [(TWO_PATHS, 3), (TWO_PATHS, 5), (DIAGONAL_PATHS, 3), (DIAGONAL_PATHS, 5)])
def test_paths_and_medians_torn_rows(paths, median):
    """On this pair the left winner's ties given to the larger d change codes (two paths, the 3 x 3 median: 5)."""
    left, right = occlusion_pair(2, wall=2, card=5)
    check(left, right, config(paths, median), tables=torn_tables(), grant_mask=0b101)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2])
def test_random_pairs(seed):
    left, right = random_pair(seed)
    check(left, right, config(DIAGONAL_PATHS if seed == 2 else TWO_PATHS))


@pytest.mark.slow
@pytest.mark.parametrize("restart_after", [410, 525, 559])
def test_restart_in_the_middle_of_a_map(restart_after):
    """``start`` again mid-map (measured on this pair: in pass 1's steps, 8 clocks into pass 1's scan, 20 clocks
    into row 1's replay at pass 2's start): the map of a fresh start."""
    left, right = occlusion_pair(3)
    cfg = config()
    codes, *_ = run_engine(left, right, config=cfg, restart_after=restart_after)
    assert_same(codes, depth_map(left, right, cfg))


@pytest.mark.slow
def test_left_right_cocotb_small(simulator, tmp_path):
    """The Verilog on Verilator and Icarus (cocotb): the card before the wall with torn rows, equal to the golden
    map."""
    left, right = occlusion_pair(5, wall=3, card=6)
    outcome = run_cocotb_depth(left, right, G, config(), simulator, tmp_path, grant_mask=0b101,
                               tag_tables=torn_tables())
    assert outcome["mismatches"] == 0


def test_parameters_schedule_and_map_rate():
    """Three paths are refused; the pass's drain holds the scan (from where the end token would go to the median),
    the replay runs in the next pass, the output one row later; D 128 at 800 x 600 elaborates and still gives a map
    in 3 display frames at 1080p60 (45.6 ms without the check, 48.8 with)."""
    with pytest.raises(ValueError, match="left-right check takes two paths"):
        check_parameters(G, dataclasses.replace(CFG, left_right=True, paths=THREE_PATHS))
    plain, checked = schedule(G, CFG), schedule(G, config())
    assert checked.fill_start == plain.drain_clocks - Median3x3.LATENCY - 2 and checked.steps == plain.steps
    scan = LeftRightFill.scan_clocks(G.buf_width)
    assert checked.drain_clocks == checked.fill_start + scan and scan == G.buf_width + 4
    assert row_lag(config()) == 2 and row_lag(config(median=5)) == 3 and row_lag(CFG) == 1
    Fragment.get(DepthEngine(G, config(DIAGONAL_PATHS, 5)), None)
    assert check_map_rate(CEA_1080P60, SENSOR_800, DEPTH_800_BASE) == 3
    checked_800 = dataclasses.replace(DEPTH_800_BASE, left_right=True)
    assert check_map_rate(CEA_1080P60, SENSOR_800, checked_800) == 3
    assert schedule(SENSOR_800, checked_800).pass_clocks - schedule(SENSOR_800, DEPTH_800_BASE).pass_clocks == 790


@pytest.mark.slow
def test_the_package_with_the_check():
    """The probe's best: AD-census 16 >> 1, the diagonal as the second path, the 7 x 7 median over the valid codes
    and the left-right check, on 8-bit grey with torn rows: the map equals the golden map (and differs from the
    map without the check)."""
    from tests.test_depth_engine_ad import AD, G8, low_contrast_pair
    cfg = dataclasses.replace(AD, paths=DIAGONAL_PATHS, median=7, median_valid=True, left_right=True)
    left, right = low_contrast_pair(3)
    tables = torn_tables()
    tags = (engine_tags(tables[0]), engine_tags(tables[1]))
    codes, *_ = run_engine(left, right, geometry=G8, config=cfg, grant_mask=0b1, tag_tables=tables)
    expected = depth_map(left, right, cfg, row_tags=tags)
    assert_same(codes, expected)
    assert (expected != depth_map(left, right, dataclasses.replace(cfg, left_right=False), row_tags=tags)).any()
