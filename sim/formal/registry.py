"""The formal harnesses of the default run (``make formal``, ``make test``) and their slow full-size variants."""

from spec.depth import SMALL_DEPTH
from spec.layout import DisplayLayout
from spec.sensor import SENSOR, SMALL_SENSOR
from spec.video import SMALL_TIMING

from sim.formal.harnesses.capture import CaptureAverageHarness, CaptureHarness
from sim.formal.harnesses.compositor import CompositorHarness, packed_layout
from sim.formal.harnesses.depth import (DepthEngineHarness, DepthMapHarness, DepthMedian5MapHarness, DepthThreeHarness,
                                       DepthMedian7MapHarness, DepthThreeMapHarness)
from sim.formal.harnesses.depth_codes import MedianCodesHarness, SubpixelCodesHarness, WinnerCodesHarness
from sim.formal.harnesses.disparity import DisparityHarness
from sim.formal.harnesses.frame_buffer import FrameBufferHarness
from sim.formal.harnesses.frame_pairing import FramePairingHarness
from sim.formal.harnesses.frame_store import FrameStoreOwnershipHarness
from sim.formal.harnesses.frame_store_credits import FrameStoreCreditsHarness
from sim.formal.harnesses.frame_store_packer import FrameStorePackerHarness
from sim.formal.harnesses.frame_store_writer import FrameStoreWriterHarness
from sim.formal.harnesses.i2c import I2CBroadcastMasterHarness, I2CMasterHarness, InitSequencerHarness
from sim.formal.harnesses.left_winner import LeftWinnerHarness
from sim.formal.harnesses.map_store import MapOwnershipHarness
from sim.formal.harnesses.matching_cost import MatchingCostBTHarness
from sim.formal.harnesses.read_arbiter import ReadArbiterHarness
from sim.formal.harnesses.reverse_path import AD_CONFIG, ReversePathHarness
from sim.formal.harnesses.row_tags import RowTagTrackerHarness
from sim.formal.harnesses.segment_band import SegmentBandHarness
from sim.formal.harnesses.switches import SwitchControlHarness
from sim.formal.harnesses.sync_gen import SyncGenerator1080pHarness, SyncGeneratorHarness
from sim.formal.harnesses.vertical_offset import VerticalOffsetHarness

#: name -> factory (a fresh harness per run: harnesses keep their properties between elaborations). The longest
#: first, so that `make formal`'s two workers finish together.
DEFAULT = {
    "depth": DepthEngineHarness,
    "depth_map": DepthMapHarness,
    "depth_median5_map": DepthMedian5MapHarness,
    "depth_median7_map": DepthMedian7MapHarness,
    "depth_three": DepthThreeHarness,
    "depth_three_map": DepthThreeMapHarness,
    "compositor": CompositorHarness,
    "sync_gen_small": SyncGeneratorHarness,
    "sync_gen_1080p": SyncGenerator1080pHarness,
    "switches": SwitchControlHarness,
    "frame_buffer": FrameBufferHarness,
    "capture": CaptureHarness,
    "capture_average": CaptureAverageHarness,
    "disparity": DisparityHarness,
    "i2c_master": I2CMasterHarness,
    "i2c_master_buses": I2CBroadcastMasterHarness,
    "i2c_init": InitSequencerHarness,
    "read_arbiter": ReadArbiterHarness,
    "winner_codes": WinnerCodesHarness,
    "median_codes": MedianCodesHarness,
    "vertical_offset": VerticalOffsetHarness,
    "subpixel_codes": SubpixelCodesHarness,
    "segment_band": SegmentBandHarness,
    "row_tags": RowTagTrackerHarness,
    "reverse_path": ReversePathHarness,
    "reverse_path_ad": lambda: _named(ReversePathHarness(AD_CONFIG), "reverse_path_ad"),
    "left_winner": LeftWinnerHarness,
    "matching_cost_bt": MatchingCostBTHarness,
    "frame_pairing": FramePairingHarness,
    "frame_store_ownership": FrameStoreOwnershipHarness,
    "map_store_ownership": MapOwnershipHarness,
    "frame_store_credits": FrameStoreCreditsHarness,
    "frame_store_writer": FrameStoreWriterHarness,
    "frame_store_packer": FrameStorePackerHarness,
}


def _named(harness, name):
    harness.name = name
    return harness


def _all_covers(harness):
    harness.all_covers = True
    return harness


#: The same properties at full size, with the default (centred) layout or with half-size camera images: minutes to
#: hours each.
SLOW = {
    "disparity_full": lambda: _named(DisparityHarness(SENSOR), "disparity_full"),
    "capture_full": lambda: _named(CaptureHarness(SENSOR), "capture_full"),
    "depth_all_covers": lambda: _named(_all_covers(DepthEngineHarness()), "depth_all_covers"),
    "compositor_centred": lambda: _named(CompositorHarness(
        layout=DisplayLayout.centred(SMALL_TIMING, SMALL_SENSOR, SMALL_DEPTH)), "compositor_centred"),
    "compositor_half_images": lambda: _named(CompositorHarness(
        layout=packed_layout(image_shrink=2, map_scale=1)), "compositor_half_images"),
}
