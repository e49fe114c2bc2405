# amaranth: UnusedElaboratable=no
"""Every constructor that rejects its arguments raises before it builds any sub-block (a composite builds its parts
in ``elaborate`` and runs their checks first).

The rejected objects are created here, and this file silences Amaranth's "created but never used" warning for what
it creates (the linter comment on its first line, as Amaranth's own tests do); a sub-block the constructor had
already built is created in the block's own file and still warns."""

import gc
import warnings

import pytest
from amaranth.hdl import Fragment, UnusedElaboratable

from hdl.averaging_downscaler import AveragingDownscaler
from hdl.capture import CameraCapture
from hdl.capture_path import CapturePath
from hdl.ch7301c_output import CH7301COutput
from board.clocking import ClockPlan, GenesysClocking
from sim.models.clocking import SimClocking
from hdl.compositor import Compositor
from hdl.stereo_display import StereoDisplay
from hdl.text_layer import TextLayer
from hdl.segment_band import SegmentBand
from hdl.disparity import DisparitySubtractor
from hdl.downscaler import Downscaler
from hdl.grey import Grey
from hdl.i2c_init import InitSequencer, Phase
from hdl.i2c_master import I2CMaster
from hdl.init_tables import CH7301C_TABLE
from spec.depth import SMALL_DEPTH
from spec.layout import TextBox
from spec.rectification import SMALL_RECTIFICATION
from spec.sensor import SMALL_SENSOR, SensorGeometry
from spec.video import SMALL_TIMING, VideoTiming
from hdl.pattern_gen import PatternGenerator
from hdl.rgb565_assembler import RGB565Assembler
from hdl.switches import SwitchControl
from hdl.sync_gen import SyncGenerator
from hdl.system import StereoDepthSystem
from board.top import GenesysTop
from sim.replay.sensor import SensorReplay
from sim.testbench.system.testbench import SystemTestbench
from sim.testbench.system.rom_testbench import RomReplayTestbench
from sim.testbench.system.verilog_testbench import VerilogReplayTestbench
from hdl.frame_store.arbiter import MemoryArbiter
from hdl.frame_store.burst_packer import BurstPacker
from hdl.frame_store.burst_writer import BurstWriter
from hdl.frame_store.camera_writer import CameraWriter
from hdl.frame_store.frame_store import FrameStore
from hdl.map_window import MapWindow
from hdl.map_writer import MapWriter
from hdl.frame_store.layout import FrameStoreLayout
from hdl.frame_store.ownership import BufferOwnership
from hdl.frame_store.row_fetcher import RowFetcher
from hdl.frame_store.row_reader import RowReader
from hdl.frame_store.row_window import RowWindow

SMALL = dict(geometry=SMALL_SENSOR, timing=SMALL_TIMING, depth=SMALL_DEPTH, auto_rectification=SMALL_RECTIFICATION)

REJECTED = {
    "CameraCapture": lambda: CameraCapture(SensorGeometry(width=64, height=48, grey_bits=6)),
    "CameraCapture, averaging": lambda: CameraCapture(SensorGeometry(width=64, height=48, downscale="average")),
    "Downscaler": lambda: Downscaler(SensorGeometry(width=30, height=30, scale=3)),
    "AveragingDownscaler": lambda: AveragingDownscaler(SensorGeometry(width=30, height=30, scale=3, grey_bits=8,
                                                                      downscale="average")),
    "RGB565Assembler": lambda: RGB565Assembler(0),
    "CapturePath": lambda: CapturePath(SMALL_SENSOR, cameras=("a", "a")),
    "CapturePath, a camera's capture": lambda: CapturePath(SensorGeometry(width=64, height=48, grey_bits=6)),
    "Compositor": lambda: Compositor(SMALL_TIMING, SMALL_SENSOR, config=SMALL_DEPTH, thresholds=(2, 4),
                                     level_grey=(0, 255)),
    "StereoDisplay": lambda: StereoDisplay(SMALL_TIMING, SMALL_SENSOR, config=SMALL_DEPTH, out_rows=1),
    "StereoDisplay, maps in the store without the DDR2": lambda: StereoDisplay(SMALL_TIMING, SMALL_SENSOR,
                                                                               config=SMALL_DEPTH, maps="store"),
    "TextLayer": lambda: TextLayer((TextBox("0.5km", 0, 0, 1),), v_active=10),
    "TextLayer, overlapping boxes": lambda: TextLayer((TextBox("0.5m", 0, 0, 1),), {"readout": TextBox("00", 20, 7, 1)},
                                                      v_active=10),
    "SegmentBand": lambda: SegmentBand(SensorGeometry(grey_bits=9)),
    "DisparitySubtractor": lambda: DisparitySubtractor(SMALL_SENSOR, thresholds=()),
    "SwitchControl": lambda: SwitchControl(stages=1),
    "SyncGenerator": lambda: SyncGenerator(SMALL_TIMING, start=(10_000, 0)),
    "PatternGenerator": lambda: PatternGenerator(VideoTiming(h_active=4, h_front=1, h_sync=1, h_back=1,
                                                             v_active=1, v_front=1, v_sync=1, v_back=1)),
    "CH7301COutput": lambda: CH7301COutput(ddr="spartan"),
    "I2CMaster": lambda: I2CMaster(clk_hz=1_000_000, bus_hz=5_000_000),
    "InitSequencer": lambda: InitSequencer(CH7301C_TABLE, retries=-1),
    "I2CMaster, buses": lambda: I2CMaster(buses=0),
    "InitSequencer, buses": lambda: InitSequencer(CH7301C_TABLE, buses=0),
    "InitSequencer, phase bus": lambda: InitSequencer((Phase("dvi", CH7301C_TABLE, (1,)),), buses=1),
    "GenesysClocking": lambda: GenesysClocking(ClockPlan(dcm_m=40)),
    "SimClocking": lambda: SimClocking(lock_cycles=0),
    "StereoDepthSystem": lambda: StereoDepthSystem(**SMALL, ddr="virtex5"),
    "StereoDepthSystem, maps": lambda: StereoDepthSystem(**SMALL, memory="ddr2", maps="frames"),
    "StereoDepthSystem, its compositor": lambda: StereoDepthSystem(**SMALL, level_grey=(0,)),
    "GenesysTop": lambda: GenesysTop(ddr="behavioural"),
    "SensorReplay": lambda: SensorReplay([], domain="sync"),
    "SystemTestbench": lambda: SystemTestbench(define_domains=False, clock_ports=True, **SMALL),
    "RomReplayTestbench": lambda: RomReplayTestbench(replay_words={"a": [0]}, **SMALL),
    "VerilogReplayTestbench": lambda: VerilogReplayTestbench(replay_depth=1, periods_ps={"sync": 3, "pix": 4, "cam": 2},
                                                     **SMALL),
    "FrameStoreLayout": lambda: FrameStoreLayout(width=40, stride=48),
    "FrameStoreLayout, banks": lambda: FrameStoreLayout(banks=5),
    "FrameStoreLayout, maps": lambda: FrameStoreLayout(maps=2),
    "FrameStoreLayout, pixel bytes": lambda: FrameStoreLayout(pixel_bytes=3),
    "MapWriter": lambda: MapWriter(SMALL_SENSOR, SMALL_DEPTH, pace=0),
    "MapWindow": lambda: MapWindow(SMALL_SENSOR, 9, pixel_bits=8),
    "BufferOwnership": lambda: BufferOwnership(readers=2, buffers=3),
    "BurstPacker": lambda: BurstPacker(geometry=SensorGeometry(grey_bits=9)),
    "BurstWriter": lambda: BurstWriter(camera=2),
    "CameraWriter": lambda: CameraWriter(fifo_depth=6),
    "MemoryArbiter": lambda: MemoryArbiter(readers=1, urgent=2),
    "MemoryArbiter, last writers": lambda: MemoryArbiter(writers=1, last_writers=2),
    "RowFetcher": lambda: RowFetcher(depth=1),
    "RowReader": lambda: RowReader(depth=24),
    "FrameStore": lambda: FrameStore(streams=((2, True),)),
    "RowWindow": lambda: RowWindow(slots=1),
    "FrameStore, three cameras": lambda: FrameStore(FrameStoreLayout(cameras=3), cam_domains=("a", "b", "c")),
    "FrameStore, a camera writer": lambda: FrameStore(geometry=SensorGeometry(grey_bits=9)),
}


@pytest.fixture(autouse=True)
def warnings_on():
    """Amaranth stays quiet about unused elaboratables until something has been elaborated in the process (a
    crash before that is no reason to warn): elaborate one block so the warning is live."""
    Fragment.get(Grey(), None)


@pytest.mark.parametrize("name", REJECTED)
def test_rejected_constructor_checks_before_it_builds(name):
    make = REJECTED[name]
    gc.collect()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises((ValueError, TypeError)):
            make()
        gc.collect()
    unused = {str(w.message).split()[0].rpartition(".")[2] for w in caught if issubclass(w.category, UnusedElaboratable)}
    assert not unused, unused


def test_the_check_sees_a_sub_block_built_before_the_check(tmp_path, monkeypatch):
    """A constructor that builds a sub-block and then rejects its arguments does warn (about the sub-block, created
    in the block's own file): the test above would catch it."""
    (tmp_path / "careless_block.py").write_text(
        "from amaranth.lib import wiring\n"
        "from hdl.grey import Grey\n\n\n"
        "class Careless(wiring.Component):\n"
        "    def __init__(self):\n"
        "        super().__init__({})\n"
        "        self.grey = Grey()\n"
        "        raise ValueError('rejected')\n\n"
        "    def elaborate(self, platform):\n"
        "        raise AssertionError\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    from careless_block import Careless

    gc.collect()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with pytest.raises(ValueError):
            Careless()
        gc.collect()
    unused = [str(w.message) for w in caught if issubclass(w.category, UnusedElaboratable)]
    assert len(unused) == 1 and "Grey" in unused[0], unused
