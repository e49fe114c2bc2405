# amaranth: UnusedElaboratable=no
"""Each harness bites: one deliberate bug per block (a mutated parameter or a wrong connection) makes its proof
fail, names the broken property and leaves a counterexample VCD in ``build/formal/<harness>/``."""

import dataclasses

import pytest
from amaranth import Signal

from hdl.depth.engine import DepthEngine
from hdl.depth.subpixel import Subpixel
from hdl.depth.winner import Winner
from hdl.capture import CameraCapture
from hdl.compositor import Compositor
from hdl.disparity import DisparitySubtractor
from hdl.frame_buffer import FrameBuffer
from hdl.i2c_init import InitSequencer
from hdl.i2c_master import I2CMaster
from hdl.init_tables import InitTable
from spec.sensor import SensorGeometry
from hdl.read_arbiter import ReadArbiter
from hdl.row_tags import RowTagTracker
from hdl.frame_pairing import FramePairing
from hdl.sync_gen import SyncGenerator
from sim.formal.runner import check

from sim.formal.harnesses.capture import CaptureAverageHarness, CaptureHarness
from sim.formal.harnesses.compositor import CompositorHarness
from sim.formal.harnesses.depth import DepthEngineHarness, DepthMapHarness, DepthThreeMapHarness
from sim.formal.harnesses.depth_codes import SubpixelCodesHarness, WinnerCodesHarness
from sim.formal.harnesses.disparity import DisparityHarness
from sim.formal.harnesses.frame_buffer import FrameBufferHarness
from sim.formal.harnesses.i2c import (BUS_HZ, CLK_HZ, TIMEOUT_US, I2CBroadcastMasterHarness, I2CMasterHarness,
                                      InitSequencerHarness)
from sim.formal.harnesses.read_arbiter import ReadArbiterHarness
from sim.formal.harnesses.reverse_path import ReversePathHarness
from hdl.depth.reverse_path import ReversePath
from sim.formal.harnesses.row_tags import RowTagTrackerHarness
from sim.formal.harnesses.frame_pairing import FramePairingHarness
from sim.formal.harnesses.frame_store import FrameStoreOwnershipHarness
from sim.formal.harnesses.map_store import MapOwnershipHarness
from sim.formal.harnesses.matching_cost import MatchingCostBTHarness
from hdl.depth.matching_cost import MatchingCost
from sim.formal.harnesses.frame_store_credits import DEPTH as CREDIT_DEPTH, LAYOUT as CREDIT_LAYOUT, FrameStoreCreditsHarness
from hdl.frame_store.row_fetcher import RowFetcher
from sim.formal.harnesses.frame_store_packer import (GEOMETRY as PACKER_GEOMETRY, LAYOUT as PACKER_LAYOUT,
                                                     FrameStorePackerHarness)
from sim.formal.harnesses.frame_store_writer import CAMERA as WRITER_CAMERA, LAYOUT as WRITER_LAYOUT, FrameStoreWriterHarness
from hdl.frame_store.burst_writer import BurstWriter
from hdl.frame_store.ownership import BufferOwnership
from sim.formal.harnesses.segment_band import SegmentBandHarness
from sim.formal.harnesses.switches import SwitchControlHarness
from sim.formal.harnesses.sync_gen import SyncGeneratorHarness
from sim.formal.harnesses.vertical_offset import VerticalOffsetHarness
from hdl.frame_store.burst_packer import BurstPacker
from hdl.vertical_offset import VerticalOffsetEstimator


class SyncPulseTooWide(SyncGeneratorHarness):
    """hsync one clock wider than CEA-861 (the back porch one shorter, so the line length is right)."""
    def dut(self):
        t = self.timing
        return SyncGenerator(dataclasses.replace(t, h_sync=t.h_sync + 1, h_back=t.h_back - 1), start=self.start)


class SwitchesLoadAnyTime(SwitchControlHarness):
    """frame_start wired high: the registers follow the switches at any clock (tearing)."""
    def connect(self, m, dut, sw, frame_start):
        m.d.comb += [dut.sw.eq(sw), dut.frame_start.eq(1)]
        return dut.settings.disparity, dut.settings.rectification


class BufferDeeperThanImage(FrameBufferHarness):
    """The memory sized for a 4 x 4 image behind the 3 x 3 image's addresses: out-of-range writes land."""
    def dut(self):
        return FrameBuffer(SensorGeometry(width=16, height=16, scale=4))


class CaptureWrongByteOrder(CaptureHarness):
    """The capture set for G byte first while the sensor sends R byte first."""
    def dut(self):
        return CameraCapture(self.geometry, r_byte_first=False)


class CaptureRowEndAtRunEnd(CaptureHarness):
    """The row end strobe seen also at every frame end (the frame-done strobe, a clock before a row's end)."""
    def row_strobes(self, dut):
        return dut.status.row_start, dut.status.row_end | dut.status.frame_done


class CaptureAverageWiderImage(CaptureAverageHarness):
    """The averaging capture built for a sensor one block wider: the block past the buffer's edge is written, and
    every row's blocks a block further on."""
    def dut(self):
        g = self.geometry
        return CameraCapture(dataclasses.replace(g, width=g.width + g.scale))


class TrackerMoreRows(RowTagTrackerHarness):
    """The tracker built for one buffer row more than the buffer has: a row start past the last row is taken."""
    def dut(self):
        g = self.geometry
        return RowTagTracker(dataclasses.replace(g, height=g.height + g.scale), bits=2, cam_domain="sync",
                             pix_domain="sync")


class PairingWiderTag(FramePairingHarness):
    """The pairing counts with one tag bit more than the trackers keep: its tags do not wrap where theirs do."""
    def dut(self):
        return FramePairing(3)


class SubtractorWiderImage(DisparityHarness):
    """The subtractor believes the image is 4 pixels wider: shifted reads wrap into the next row."""
    def dut(self):
        g = self.geometry
        return DisparitySubtractor(dataclasses.replace(g, width=g.width + 4 * g.scale), self.thresholds)


class MasterLongTimeout(I2CMasterHarness):
    """The master built with twice the documented stuck-bus time-out."""
    def dut(self):
        return I2CMaster(clk_hz=CLK_HZ, bus_hz=BUS_HZ, timeout_us=2 * TIMEOUT_US)


class BroadcastMasterLongTimeout(I2CBroadcastMasterHarness):
    """The two-bus master built with twice the documented stuck-bus time-out."""
    def dut(self):
        return I2CMaster(clk_hz=CLK_HZ, bus_hz=BUS_HZ, timeout_us=2 * TIMEOUT_US, buses=self.buses)


class SequencerShortTable(InitSequencerHarness):
    """The sequencer's ROM holds only the table's last entry: it reports done before the table is played."""
    def dut(self):
        short = InitTable(self.table.device, self.table.entries[-1:])
        return InitSequencer(short, clk_hz=CLK_HZ, bus_hz=BUS_HZ, retries=self.retries, retry_delay_us=10,
                             timeout_us=TIMEOUT_US)


class DepthEngineWiderImage(DepthEngineHarness):
    """The engine built for a buffer one pixel wider than the one it reads: its row addresses run ahead (the input
    rows' proof only)."""
    parts = ("reads",)

    def dut(self):
        g = self.geometry
        wider = dataclasses.replace(g, width=g.width + g.scale)
        return DepthEngine(wider, self.config, out_rows=self.out_rows)


class EngineWrappingPassCounter(DepthEngine):
    """The pass counter one value short (``range(H + 1)``): on the 3-row buffer (H + 1 = 4) it wraps to 0 once the
    map is done."""
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.pass_row = Signal(range(self.geometry.buf_height + 1), name="y")


class DepthMapWrappingPassCounter(DepthMapHarness):
    """The map harness's results proof on the engine whose pass counter wraps."""
    parts = ("results",)

    def dut(self):
        return EngineWrappingPassCounter(self.geometry, self.config, out_rows=self.out_rows)


class EngineWithoutPairs(DepthEngine):
    """The engine that never compares the two images' tags (each image's own rule only)."""
    def _pair_bits(self, m, rings):
        return []


class DepthEngineWithoutPairs(DepthEngineHarness):
    """The engine without ``_pair_bits`` (the row tags' proof only)."""
    parts = ("tags",)

    def dut(self):
        return EngineWithoutPairs(self.geometry, self.config, out_rows=self.out_rows)


class EngineShortBackwardDrain(DepthEngine):
    """Three paths: the backward drain one clock short, so the row's last code (x = 0) is written in the replay's
    first clock, after the replay has read the old one."""
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.back_drain -= 1


class DepthThreeShortBackwardDrain(DepthThreeMapHarness):
    """The three-path map harness's results proof on the engine whose backward drain is one clock short."""
    def dut(self):
        return EngineShortBackwardDrain(self.geometry, self.config, out_rows=self.out_rows)


class ReversePathOneColumnWider(ReversePathHarness):
    """The right-to-left path built for a row one column wider than its tokens' (W = 8 behind the 7-column
    contract): it starts at a column the row does not have (the start's proof only)."""
    def prove(self, m, name, test, *, bound=None, group=None):
        if group == "start":
            return super().prove(m, name, test, bound=bound, group=group)

    def dut(self):
        return ReversePath(self.config, width=self.width + 1, other_paths=self.other_paths)


class EngineFirstArbiter(ReadArbiter):
    """Priority to the engine: the arbiter built with its two readers swapped (the display refused while the
    engine requests: it would miss pixels)."""
    def elaborate(self, platform):
        display, engine = self.display, self.engine
        self.display, self.engine = engine, display
        try:
            return super().elaborate(platform)
        finally:
            self.display, self.engine = display, engine


class ArbiterEngineFirst(ReadArbiterHarness):
    def dut(self):
        return EngineFirstArbiter(self.geometry)


class CompositorLeftMovedDown(CompositorHarness):
    """The compositor built with the left image one line lower than the layout it is checked against."""
    def dut(self):
        regions = tuple(dataclasses.replace(r, y0=r.y0 + 1) if r.source == "left" else r
                        for r in self.layout.regions)
        return Compositor(self.timing, self.geometry, dataclasses.replace(self.layout, regions=regions),
                          config=self.config, out_rows=self.out_rows)


class WinnerMoreDisparities(WinnerCodesHarness):
    """The winner built for D = 8 behind the D = 6 engine: disparities 6 and 7 come out as codes."""
    def dut(self):
        return Winner(dataclasses.replace(self.config, disparities=8), self.width)


class SubpixelThresholdOneHigher(SubpixelCodesHarness):
    """The sub-pixel stage built with max_cost one higher than the rule it is checked against: a winner whose
    summed cost is exactly one past the threshold comes out valid."""
    def dut(self):
        return Subpixel(dataclasses.replace(self.config, max_cost=self.config.max_cost + 1), self.width)


class EstimatorTallerImage(VerticalOffsetHarness):
    """The estimator built for buffers one row taller than the profile memories it is checked against: the sweep
    reads one row past the last."""
    def dut(self):
        g = self.geometry
        return VerticalOffsetEstimator(dataclasses.replace(g, height=g.height + g.scale), self.config)


class EstimatorWiderSearch(VerticalOffsetHarness):
    """The estimator searching +-(R + 1) behind a +-R contract: its costs (and offsets) leave the 2R + 1 words."""
    def dut(self):
        return VerticalOffsetEstimator(self.geometry, dataclasses.replace(self.config, search_rows=3))


class SegmentBandCentreOneHigher(SegmentBandHarness):
    """The block given the disparity register plus one: the band centred a pixel too near."""
    def connect(self, m, dut, disparity, enable, code, grey):
        m.d.comb += [dut.disparity.eq(disparity + 1), dut.enable.eq(enable), dut.code.eq(code), dut.grey.eq(grey)]
        return dut.rgb, dut.chars.as_value()


class OwnershipTwoBuffers(FrameStoreOwnershipHarness):
    """Two buffers a camera for one reader (the constructor's check skipped): the latest and a held pair leave the
    writer no buffer of its own."""
    def dut(self):
        class Unchecked(BufferOwnership):
            def __init__(self):
                BufferOwnership.__init__(self, 2, 1, 3)
                self.buffers = 2
        return Unchecked()


class MapOwnershipTwoBuffers(MapOwnershipHarness):
    """Two map buffers for the display (the constructor's check skipped): the latest map and the held one leave the
    writer no buffer of its own."""
    def dut(self):
        class Unchecked(BufferOwnership):
            def __init__(self):
                BufferOwnership.__init__(self, 1, 1, 3)
                self.buffers = 2
        return Unchecked()


class FetcherCountsADeeperFifo(FrameStoreCreditsHarness):
    """The fetcher's credits counted for a FIFO two words deeper than the one it writes."""
    def dut(self):
        return RowFetcher(CREDIT_LAYOUT, 0, depth=CREDIT_DEPTH + 2)


class WriterForBuffersARowOn(FrameStoreWriterHarness):
    """The writer built for buffers a row further on than they are laid out: its last row spills over."""
    def dut(self):
        return BurstWriter(dataclasses.replace(WRITER_LAYOUT, base=WRITER_LAYOUT.base + WRITER_LAYOUT.stride_words),
                           WRITER_CAMERA)


class WriterForLongerRows(FrameStoreWriterHarness):
    """The writer built for rows a word longer than the packer's: it takes the next row's first word as the row's
    last and makes one word fewer: bursts of words from two rows."""
    def dut(self):
        return BurstWriter(dataclasses.replace(WRITER_LAYOUT, width=WRITER_LAYOUT.width + 8), WRITER_CAMERA)


class WriterToldEveryFrameIsWhole(FrameStoreWriterHarness):
    """The capture's verdict wired high: frames the capture called broken finish complete."""
    def connect_verdict(self, m, dut, ok):
        m.d.comb += dut.entries.data.ok.eq(1)


class PackerForShorterRows(FrameStorePackerHarness):
    """The packer built for rows a pixel shorter than the frames are: a row one pixel short looks whole to it."""
    def dut(self):
        return BurstPacker(dataclasses.replace(PACKER_LAYOUT, width=PACKER_LAYOUT.width - 1), PACKER_GEOMETRY)


class CostClipOneLower(MatchingCostBTHarness):
    """The cost block built with the AD term's clip one lower (15 for 16): the term saturates a half-step early."""
    def dut(self):
        return MatchingCost(dataclasses.replace(self.config, ad_clip=self.config.ad_clip - 1))


BITES = {
    "sync_gen": (SyncPulseTooWide, "hsync_window_and_polarity"),
    "switches": (SwitchesLoadAnyTime, "_changes_only_after_frame_start"),
    "frame_buffer": (BufferDeeperThanImage, "memory_written_only_below_depth"),
    "capture": (CaptureWrongByteOrder, "pixel_bytes_paired_in_order"),
    # Too wide an image breaks both left_read_at_shifted_pixel and left_read_in_buffer (the last rows' shifted
    # reads pass the buffer's end); the solver reports whichever it reaches first.
    "disparity": (SubtractorWiderImage, "left_read_"),
    "i2c_master": (MasterLongTimeout, "stuck_scl_command_still_within_bound"),
    "i2c_master_buses": (BroadcastMasterLongTimeout, "stuck_scl_command_still_within_bound"),
    "i2c_init": (SequencerShortTable, "done_only_after_whole_table"),
    "depth": (DepthEngineWiderImage, "read_address_is_row_and_column"),
    # The engine served first breaks both display_never_refused and engine_granted_exactly_when_display_idle in
    # the same clock; the solver's counterexample may name either.
    "read_arbiter": (ArbiterEngineFirst, ("display_never_refused", "engine_granted_exactly_when_display_idle")),
    "winner_codes": (WinnerMoreDisparities, "code_is_disparity_or_invalid"),
    "subpixel_codes": (SubpixelThresholdOneHigher, "invalid_by_the_rule"),
    "compositor": (CompositorLeftMovedDown, "left_request_exactly_for_its_image_or_the_difference_map"),
    "vertical_offset": (EstimatorTallerImage, "profile_read_in_memory"),
    "vertical_offset_range": (EstimatorWiderSearch, "cost_read_in_memory"),
    "segment_band": (SegmentBandCentreOneHigher, "band"),
    "capture_rows": (CaptureRowEndAtRunEnd, "row_end_exactly_after_kept_run_end"),
    "capture_average": (CaptureAverageWiderImage, ("writes_only_kept_pixels", "write_address_")),
    "row_tags": (TrackerMoreRows, "busy_exactly_for_row_in_progress"),
    "frame_pairing": (PairingWiderTag, "_by_the_rule"),
    "depth_pairs": (DepthEngineWithoutPairs, "pair_mismatch_in_window_makes_the_row_invalid"),
    "frame_store_ownership": (OwnershipTwoBuffers, "writes the latest"),
    "map_store_ownership": (MapOwnershipTwoBuffers, "writes the latest"),
    "frame_store_credits": (FetcherCountsADeeperFifo, "room"),
    "frame_store_writer": (WriterForBuffersARowOn, "write_inside_the_owned_buffer"),
    "frame_store_writer_complete": (WriterToldEveryFrameIsWhole, "complete_only_after_exactly_the_frame_s_bursts"),
    "frame_store_writer_words": (WriterForLongerRows, "complete_only_after_exactly_the_frame_s_bursts"),
    "frame_store_packer": (PackerForShorterRows, "end_ok_only_for_a_frame_of_whole_rows"),
    "depth_pass_counter": (DepthMapWrappingPassCounter, "rows_ready_counts_finished_passes"),
    "depth_three_back_drain": (DepthThreeShortBackwardDrain, "codes_written_before_replay"),
    "reverse_path": (ReversePathOneColumnWider, "first_exactly_at_the_last_column"),
    "matching_cost_bt": (CostClipOneLower, "cost_is_census_plus_bt_term"),
}


#: Bites that take more than a few seconds of CPU: ``make test-slow`` runs them.
SLOW_BITES = {"depth_three_back_drain"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in SLOW_BITES else n
                                  for n in sorted(BITES)])
def test_bug_is_caught(name):
    mutant, broken = BITES[name]
    broken = (broken,) if isinstance(broken, str) else broken
    harness = mutant()
    harness.name = f"bite_{name}"
    report = check(harness)
    assert not report.ok
    failed = [g for g in report.groups if g.outcome.status == "failed"]
    assert failed, "\n".join(report.lines())
    assert any(b in prop for b in broken for g in failed for prop in g.failed), "\n".join(report.lines())
    vcd = failed[0].vcd
    assert vcd.exists() and vcd.parent.name == harness.name and vcd.parent.parent.name == "formal"
    assert vcd.stat().st_size > 0
    line = report.lines()[0]
    assert line.startswith(f"FAIL bite_{name}: ") and any(b in line for b in broken) and str(vcd) in line
