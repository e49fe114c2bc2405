# amaranth: UnusedElaboratable=no
"""The depth engine with the AD-census cost (docs/depth.md, "cost": the census Hamming distance plus
min(|I_R - I_L|, ad_clip) >> ad_shift) against golden.depth.depth_map, bit for bit, on Amaranth's simulator at the
small size (16 x 12 buffers of 8-bit grey, D = 8, 4 lanes). Each map is also checked to differ from the census-only
map, so an engine that dropped the AD term would fail. The two-path map in the default run, the diagonal and three
paths slow."""

import dataclasses

import numpy as np
import pytest

from golden.depth import depth_map, matching_cost
from hdl.depth import DepthEngine
from spec.depth import DIAGONAL_PATHS, THREE_PATHS
from tests.test_depth_engine import CFG, G, SHAPE, assert_same, run_engine

G8 = dataclasses.replace(G, grey_bits=8)
AD = dataclasses.replace(CFG, pixel_bits=8, ad_clip=16, ad_shift=1)


def low_contrast_pair(seed):
    """A texture of greys 0..47 and its copy moved 3 pixels, with noise of -20..20: the grey differences of the
    true and the wrong matches fall on both sides of ad_clip (16)."""
    rng = np.random.default_rng(seed)
    texture = rng.integers(0, 48, (SHAPE[0], SHAPE[1] + 3))
    left = texture[:, :SHAPE[1]]
    right = np.clip(texture[:, 3:] + rng.integers(-20, 21, SHAPE), 0, 255)
    return left, right


def check(left, right, config, **kwargs):
    codes, *_ = run_engine(left, right, geometry=G8, config=config, **kwargs)
    expected = depth_map(left, right, config)
    assert_same(codes, expected)
    assert (codes != depth_map(left, right, dataclasses.replace(config, ad_clip=0, ad_shift=0))).any()
    cost = matching_cost(left, right, config)
    grey = np.minimum(np.abs(right[None, :, :SHAPE[1] - config.disparities]
                             - np.stack([left[:, d:d + SHAPE[1] - config.disparities]
                                         for d in range(config.disparities)])), config.ad_clip)
    assert (grey == config.ad_clip - 1).any() and (grey == config.ad_clip).any() and (cost == config.cost_max).any()


def test_ad_census_bit_exact():
    """Two paths, 1 in 4 reads granted: the map equals the golden AD-census map."""
    check(*low_contrast_pair(1), AD, grant_mask=0b11)


def test_ad_needs_the_buffers_grey():
    with pytest.raises(ValueError, match="grey_bits"):
        DepthEngine(G, AD)


@pytest.mark.slow
def test_ad_census_three_paths_bit_exact():
    """Three paths (the candidates' greys from the census shift register, forward and backward), ad_clip 24 >> 2."""
    config = dataclasses.replace(AD, paths=THREE_PATHS, max_cost=AD.max_cost * 3 // 2, ad_clip=24, ad_shift=2)
    check(*low_contrast_pair(2), config)


@pytest.mark.slow
def test_ad_census_diagonal_bit_exact():
    """The diagonal as the second path (``DIAGONAL_PATHS``) with AD-census 16 >> 1 and ``max_cost`` 136: the
    package of docs/depth.md's "What to build" at the small size."""
    check(*low_contrast_pair(3), dataclasses.replace(AD, paths=DIAGONAL_PATHS, max_cost=136), grant_mask=0b1)
