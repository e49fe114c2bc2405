"""The depth golden model's parameters (docs/depth.md, "Parameters"): the paths (right to left, the diagonals), the
pixel width and D = 128, each new threshold at its boundary; today's defaults are today's model."""

import dataclasses

import numpy as np
import pytest

from golden.depth import depth_map, path_cost, path_step, second_best, winner
from spec.depth import DEPTH, DEPTH_800, DEPTH_800_THREE, PATH_STEPS, THREE_PATHS, TWO_PATHS, DepthConfig

CFG = DepthConfig(disparities=8, lanes=4)


def _path_loop(cost, path, config):
    """The recursion of docs/depth.md pixel by pixel: p' = p + PATH_STEPS[path], zero outside the image."""
    dx, dy = PATH_STEPS[path]
    d_count, h, w = cost.shape
    out = np.zeros(cost.shape, dtype=np.int64)
    ys = range(h) if dy <= 0 else range(h - 1, -1, -1)
    xs = list(range(w)) if dx <= 0 else list(range(w - 1, -1, -1))
    for y in ys:
        for x in xs:
            py, px = y + dy, x + dx
            prev = out[:, py, px] if 0 <= py < h and 0 <= px < w else np.zeros(d_count, dtype=np.int64)
            out[:, y, x] = path_step(cost[:, y, x][:, None], prev[:, None], config.p1, config.p2)[:, 0]
    return out


@pytest.mark.parametrize("path", list(PATH_STEPS))
def test_every_path_equals_a_pixel_loop(path):
    cost = np.random.default_rng(7).integers(0, CFG.census_bits + 1, (8, 5, 9))
    assert (path_cost(cost, path, CFG) == _path_loop(cost, path, CFG)).all()


def test_right_to_left_starts_at_the_last_column():
    """x = W - 1 is the path's first pixel: L = C there (and only there, for a cost that is not flat)."""
    cost = np.random.default_rng(8).integers(0, 49, (8, 3, 6))
    rl = path_cost(cost, "right_to_left", CFG)
    assert (rl[:, :, -1] == cost[:, :, -1]).all()
    assert (rl[:, :, -2] != cost[:, :, -2]).any()
    assert (rl == path_cost(cost[:, :, ::-1], "left_to_right", CFG)[:, :, ::-1]).all()


def test_restart_applies_to_the_paths_down_the_image():
    """A restart at row 2 makes every downward path start afresh there (as at row 0); a path along the row refuses
    a restart."""
    cost = np.random.default_rng(9).integers(0, 49, (8, 5, 6))
    restart = np.array([True, False, True, False, False])
    for path in ("top_to_bottom", "top_left_to_bottom_right", "top_right_to_bottom_left"):
        assert (path_cost(cost, path, CFG, restart=restart)[:, 2:] == path_cost(cost[:, 2:], path, CFG)).all()
    with pytest.raises(ValueError, match="step down"):
        path_cost(cost, "right_to_left", CFG, restart=restart)


def test_the_sum_of_the_configured_paths():
    """depth_map sums exactly the configured paths (details keep each); two paths are today's model."""
    rng = np.random.default_rng(10)
    left, right = rng.integers(0, 32, (10, 14)), rng.integers(0, 32, (10, 14))
    three = dataclasses.replace(CFG, paths=THREE_PATHS, max_cost=180)
    got = depth_map(left, right, three, details=True)
    assert list(got.paths) == list(THREE_PATHS)
    raw, _ = winner(sum(path_cost(got.cost, p, three) for p in THREE_PATHS), three)
    assert (got.raw == raw).all()
    assert CFG.paths == TWO_PATHS == DEPTH.paths and DEPTH.pixel_bits == 5 and DEPTH.sum_bits == 9


def test_sum_widths_and_the_none_value():
    """sum_max = P (N + P2) fits sum_bits; with 3 paths (432) still 9 bits, S2 = 511 where no far disparity
    exists; 4 paths: 576 -> 10 bits, S2 = 1023. S* = sum_max with k = 64 and no S2 is valid (never ambiguous)."""
    assert (DEPTH_800_THREE.sum_max, DEPTH_800_THREE.sum_bits) == (432, 9)
    four = dataclasses.replace(DEPTH_800_THREE, paths=THREE_PATHS + ("top_left_to_bottom_right",))
    assert (four.sum_max, four.sum_bits) == (576, 10)
    for config in (DEPTH_800_THREE, four):
        d3 = dataclasses.replace(config, disparities=3, lanes=1, max_cost=config.sum_max)
        total = np.array([config.sum_max + 1, config.sum_max, config.sum_max + 1])[:, None, None]
        assert int(second_best(total, np.array([[1]]), d3)[0, 0]) == 2 ** config.sum_bits - 1
        assert int(winner(total, d3)[0][0, 0]) == d3.fraction          # d* = 1, valid


def test_max_cost_boundary_with_three_paths():
    """DEPTH_800_THREE's max_cost 180 (60 per path): S* = 180 valid, 181 invalid."""
    assert DEPTH_800_THREE.max_cost == 180
    config = dataclasses.replace(DEPTH_800_THREE, disparities=8, lanes=4)
    total = np.full((8, 1, 2), 400)
    total[3, 0, :] = [180, 181]
    total[2, 0, :] = total[4, 0, :] = 300
    codes, _ = winner(total, config)
    assert codes.tolist() == [[3 * 16, config.invalid]]


def test_d128_last_disparity_boundary():
    """D = 128: d* = 126 is valid (code 16 x 126 + q), d* = 127 = D - 1 invalid (code 2048, 12 bits)."""
    total = np.full((128, 1, 2), 300)
    total[125:128, 0, 0] = [100, 50, 100]
    total[126:128, 0, 1] = [100, 50]
    codes, _ = winner(total, DEPTH_800)
    assert codes.tolist() == [[16 * 126, DEPTH_800.invalid]]
    assert (DEPTH_800.invalid, DEPTH_800.code_bits) == (2048, 12)


def test_pixel_width_boundary():
    """The grey values read: 2**pixel_bits - 1 accepted, 2**pixel_bits refused (5 bits today, 8 in the 800 x 600
    build)."""
    for config, top in ((CFG, 31), (dataclasses.replace(CFG, pixel_bits=8), 255)):
        image = np.zeros((6, 10), dtype=np.int64)
        image[2, 3] = top
        depth_map(image, image, config)
        image[2, 3] = top + 1
        with pytest.raises(ValueError, match=f"0..{top}"):
            depth_map(image, image, config)


def test_bad_paths_are_refused():
    for paths in ((), ("left_to_right", "left_to_right"), ("left_to_right", "bottom_to_top")):
        with pytest.raises(ValueError, match="paths must be"):
            DepthConfig(paths=paths)
