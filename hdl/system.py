"""StereoDepthSystem: the whole design of thesis figure 4.1, board-independent and simulatable.

Blocks (each in its own file, see docs/architecture.md):

* the I2C bring-up: one :class:`~hdl.i2c_init.InitSequencer` for the three buses (each MT9D112 has its own, the
  CH7301C has the Genesys's): it plays the CH7301C table on the CH7301C's bus, then the MT9D112 table on both
  camera buses at once (its master drives both alike, so every write reaches both sensors at the same clock, and
  needs both to answer);
* two cameras: a :class:`~hdl.capture_path.CapturePath` (capture + frame buffer per camera; camera A = left,
  B = right);
* the display: :class:`~hdl.sync_gen.SyncGenerator` -> :class:`~hdl.stereo_display.StereoDisplay` (the
  :class:`~hdl.compositor.Compositor` with its :class:`~hdl.disparity.DisparitySubtractor` and the
  :class:`~hdl.depth.DepthEngine`, sharing each frame buffer's one read port through a
  :class:`~hdl.read_arbiter.ReadArbiter`) -> :class:`~hdl.ch7301c_output.CH7301COutput`;
  :class:`~hdl.switches.SwitchControl` turns SW7..SW0 into the disparity and rectification registers (the
  rectification also moves the left rows the depth engine reads); the
  :class:`~hdl.vertical_offset.VerticalOffsetEstimator` watches both captures' writes and finds the vertical
  offset between the cameras; :class:`~hdl.rectification_select.RectificationSelect` uses it in place of the
  manual rectification when the switches hold ``AUTO_CODE`` (SW7 = 0, SW6..SW0 = 1000000, docs/rectification.md)
  or ``SEGMENT_CODE`` (1000001: also the segmentation view in the difference map's place, docs/display.md);
* status LEDs and the sensor/transmitter reset and power pins.

Clock domains (defined by the parent: :class:`~board.top.GenesysTop` with the board clocking on the board, the
simulation testbench with :class:`~sim.models.clocking.SimClocking` in simulation, whose exported Verilog names the clocks
``clk``, ``pix_clk``, ``cam_a_clk``, ``cam_b_clk``):

=========  ================================================================================================
``sync``   100 MHz: the I2C init sequencer, the sensor/transmitter reset pins, LEDs 0..5
``pix``    148.5 MHz: sync generator, switches, compositor, depth engine, frame-buffer read ports, CH7301C output,
           the vertical-offset search and the rectification select, the row-tag trackers and their frame pairing, LED 6
``cam_a``  camera A's PCLK: its capture and frame-buffer write port, its row sums, its tracker's strobe toggles, LED 7
``cam_b``  camera B's PCLK: its capture and frame-buffer write port, its row sums, its tracker's strobe toggles
``mem``    with ``memory="ddr2"`` only: MIG's ``clk0`` (125 MHz), the frame store's memory side and ``mig``
=========  ================================================================================================

Frame memory (``memory``): ``"bram"`` (the default, the thesis design) keeps each camera's frame in a block-RAM
frame buffer that its capture overwrites while the display reads it (below). ``"ddr2"`` puts the frames in the
board's DDR2 behind Xilinx MIG: the captures write into a :class:`~hdl.frame_store.frame_store.FrameStore`
(docs/frame_store.md), which the system reaches through its ``mig`` port (MIG's user interface, ``mem``); the
display takes the latest complete pair at every display frame's start and its compositor and depth engine read it
through four read streams (:class:`~hdl.store_windows.StoreWindows`). A held pair is whole, so that build has no
row-tag trackers and no frame pairing in ``pix`` (the frame store pairs the frames by its own tags).

Depth maps (``maps``, with ``"ddr2"``): ``"ring"`` (the default) the compositor reads the engine's ring of result
rows as the engine writes it, a map a display frame; ``"store"`` the engine's maps go whole into the frame store's
map buffers and the display shows the latest whole one (:class:`~hdl.map_writer.MapWriter`,
:class:`~hdl.map_window.MapWindow`, docs/frame_store.md, "Depth maps in the store"): for a map longer than a display
frame (800 x 600, D = 128).

CH7301C output stage: with ``ddr="behavioural"`` (simulation, Verilog export) the system ends in
:class:`~hdl.ch7301c_output.CH7301COutput`'s behavioural dual-edge model and has the CH7301C pins (``ch7301c``).
With ``ddr=None`` (the board) it stops at the compositor's video stream (``video``, ``pix``) and
:class:`board.top.GenesysTop` builds the pins from Virtex-5 ODDRs (through ``amaranth.lib.io.DDRBuffer``), including
the XCLK pair as two single-ended ODDR outputs in the 90-degree ``pix90`` domain: the Genesys's XCLK pins are
LVCMOS33 (docs/board.md), so the OBUFDS of ``CH7301COutput(ddr="virtex5")`` cannot drive them.

Status LEDs (``panel.leds``): 0 camera A bus init done, 1 camera A bus error, 2 camera B bus init done, 3 camera B
bus error (the cameras' init is shared: 0 and 2 light together; an error lights 1 and 3 together, except a NACK,
which lights the LED of the bus or buses that did not acknowledge), 4 CH7301C init done, 5 CH7301C: steady on =
I2C error (its bring-up stopped; the cameras' goes on), blinking with LED 6 = its version or device ID byte
(0x4A / 0x4B) read another value than the table's (``init.dvi.mismatch``, bring-up went on), 6 display
heartbeat (toggles every ``2**heartbeat_log2`` display frames: 32 frames = 0.53 s at 60 Hz), 7 camera A heartbeat (toggles every ``2**cam_heartbeat_log2`` captured frames, about 0.5 s at 15 fps),
steady on while the last frame-start skew measurement was more than one sensor line (``skew.aligned`` low).

Sensor and transmitter control pins (``control``, ``sync``): ``cam_rst_n`` and ``dvi_reset_n`` are low while
``sync`` is in reset (so until the clocks are locked) and high from the first clock after; ``cam_vdden``
(VmodCAM supply enable) is high once out of reset; ``cam_pwdn`` is low. The MT9D112 table starts with a wait
longer than the sensor's 7000-MCLK boot time, so the first I2C access follows the reset release correctly.

Frame-start skew (``skew``, ``sync``): :class:`~hdl.frame_skew.FrameSkewMeter` measures camera B's frame start
minus camera A's in ``sync`` clocks at every frame; ``skew.aligned`` is the goal of at most one sensor line
(``skew_line_clocks``: by default a line of ``2 * width + 256`` PCLKs at ``CLOCKS.CAM_PCLK_HZ``, the sensor model's
horizontal blanking; the real sensor's is not known, docs/hardware-facts.md).

Latency: from a raster position of the sync generator to the CH7301C pins, :data:`DISPLAY_LATENCY` pixel clocks
(compositor 6 + output 1). The display runs from reset; each frame buffer shows whatever its camera last wrote
(zeros before the first capture): there is no double buffering (thesis design), so a display frame scanned
while a capture is in progress can show part old, part new image.
"""

from dataclasses import KW_ONLY, dataclass

from amaranth import DomainRenamer, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.capture import CameraSignature, CaptureStatusSignature, check_geometry as check_capture
from hdl.capture_path import CapturePath
from hdl.ch7301c_output import CH7301COutput, CH7301CSignature
from hdl.stereo_display import LATENCY as COMPOSITOR_LATENCY, StereoDisplay, check_display
from hdl.frame_skew import FrameSkewMeter, FrameSkewSignature, skew_bits
from hdl.i2c_init import ErrorCode, InitSequencer, InitStatusSignature, Phase, check_parameters as check_sequencer
from hdl.i2c_master import I2CSignature
from hdl.init_tables import CH7301C_TABLE, MT9D112_TABLE
from spec.board import CLOCKS
from spec.depth import DEPTH
from spec.display import DIFF_LEVEL_GREY, DIFF_THRESHOLDS
from spec.sensor import SENSOR
from spec.video import CEA_1080P60
from hdl.rectification_select import RectificationSelect
from hdl.switches import SettingsSignature, SwitchControl
from hdl.vertical_offset import VerticalOffsetEstimator
from spec.rectification import RECTIFICATION
from hdl.sync_gen import SyncGenerator, check_timing
from hdl.video_bus import VideoSignature
from hdl.reset_tree import add_reset_subtree
from hdl.row_tags import RowTagTracker
from hdl.frame_pairing import FramePairing
from hdl.frame_store.frame_store import FrameStore
from hdl.frame_store.layout import FrameStoreLayout
from hdl.mig_user import MIGUserSignature
from hdl.stereo_display import MEMORIES
from hdl.store_windows import STREAMS

__all__ = ["StereoDepthSystem", "SystemParameters", "PanelSignature", "ControlSignature", "DISPLAY_LATENCY", "CAMERAS",
           "I2C_BUSES", "I2C_SEQUENCER", "DISPLAY_MISSED_BITS"]

#: Pixel clocks from a sync-generator raster position to that pixel on the CH7301C pins.
DISPLAY_LATENCY = COMPOSITOR_LATENCY + 1
#: Camera names: "a" is the left camera, "b" the right one; camera ``c`` runs in domain ``cam_<c>``.
CAMERAS = ("a", "b")
#: The I2C buses: one per camera, one for the CH7301C.
I2C_BUSES = ("cam_a", "cam_b", "dvi")
#: The init sequencer (the system's submodule) that plays every bus's table.
I2C_SEQUENCER = "i2c_init"
#: The DDR2 build's ``display_missed`` count: pix clocks with a compositor read refused, saturating.
DISPLAY_MISSED_BITS = 16

#: The board's user panel as the design sees it: the eight slide switches in (asynchronous), the eight LEDs out.
PanelSignature = wiring.Signature({"sw": In(8), "leds": Out(8)})

#: Reset and power pins of the sensors and the transmitter (``sync``).
ControlSignature = wiring.Signature({
    "cam_rst_n": Out(1), "cam_pwdn": Out(1), "cam_vdden": Out(1), "dvi_reset_n": Out(1),
})


@dataclass(frozen=True)
class SystemParameters:
    """The parameters of a :class:`StereoDepthSystem`, checked; its signature follows from them.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
        Sensors and buffers.
    timing : :class:`spec.video.VideoTiming`
        The video mode.
    layout : :class:`spec.layout.DisplayLayout` or None
        Screen layout (default centred).
    thresholds, level_grey : sequence of int
        The disparity display (:class:`~hdl.compositor.Compositor`).
    depth : :class:`spec.depth.DepthConfig`
        The depth engine.
    auto_rectification : :class:`spec.rectification.RectificationConfig`
        The vertical-offset estimator (its search must fit the buffers: ``SMALL_RECTIFICATION`` for
        ``SMALL_SENSOR``).
    cam_table, dvi_table : :class:`hdl.init_tables.InitTable`
        The I2C init tables.
    clk_hz, i2c_hz : int
        ``sync`` clock and I2C bus rates.
    i2c_retry_delay_us : int
    r_byte_first : bool
        The byte order the captures expect.
    ddr : str or None
        ``"behavioural"``: the CH7301C pins from the behavioural dual-edge model (simulation, Verilog export);
        ``None``: the video stream only (the board top level builds the pins).
    heartbeat_log2, cam_heartbeat_log2 : int
        LED blink rates.
    skew_line_clocks : int or None
        One sensor line in ``sync`` clocks, the frame-skew goal (default: see the module docstring).
    memory : str
        Where the frames are: ``"bram"`` (block-RAM buffers) or ``"ddr2"`` (the frame store behind ``mig``).
    store_slots : int
        With ``"ddr2"``: the row slots of each read stream.
    maps : str
        Where the depth maps are: ``"ring"`` (the engine's ring) or, with ``"ddr2"`` only, ``"store"`` (whole maps
        in the frame store, the latest shown).

    Raises
    ------
    ValueError
        Any block's parameter check; ``ddr`` other than ``"behavioural"`` or ``None``; ``memory`` not one of
        :data:`hdl.stereo_display.MEMORIES`; ``maps`` not one of :data:`hdl.stereo_display.MAPS`, or ``"store"``
        without ``"ddr2"``.
    TypeError
        An init table that is not an ``InitTable``.
    """
    geometry: object = SENSOR
    timing: object = CEA_1080P60
    layout: object = None
    _: KW_ONLY
    thresholds: tuple = DIFF_THRESHOLDS
    level_grey: tuple = DIFF_LEVEL_GREY
    depth: object = DEPTH
    auto_rectification: object = RECTIFICATION
    cam_table: object = MT9D112_TABLE
    dvi_table: object = CH7301C_TABLE
    clk_hz: int = CLOCKS.SYS_HZ
    i2c_hz: int = CLOCKS.I2C_HZ
    i2c_retry_delay_us: int = 1000
    r_byte_first: bool = True
    ddr: object = "behavioural"
    heartbeat_log2: int = 5
    cam_heartbeat_log2: int = 3
    skew_line_clocks: object = None
    memory: str = "bram"
    store_slots: int = 4
    maps: str = "ring"

    def __post_init__(self):
        if self.ddr not in ("behavioural", None):
            raise ValueError(f"ddr must be 'behavioural' or None (board: pins built by board.top), not {self.ddr!r}")
        if self.memory not in MEMORIES:
            raise ValueError(f"memory must be one of {', '.join(map(repr, MEMORIES))}, not {self.memory!r}")
        check_capture(self.geometry)
        check_display(self.timing, self.geometry, self.layout, config=self.depth, thresholds=self.thresholds,
                      level_grey=self.level_grey, memory=self.memory, maps=self.maps)
        check_timing(self.timing)
        self.auto_rectification.check(self.geometry.buf_height)
        skew_bits(*self.skew_clocks)
        for table in self.tables.values():
            check_sequencer(table, clk_hz=self.clk_hz, bus_hz=self.i2c_hz)

    @property
    def tables(self):
        """The init table of each I2C bus."""
        return {"cam_a": self.cam_table, "cam_b": self.cam_table, "dvi": self.dvi_table}

    @property
    def skew_clocks(self):
        """``(line_clocks, max_clocks)`` of the frame-skew meter."""
        g = self.geometry
        line = self.skew_line_clocks or -(-(2 * g.width + 256) * self.clk_hz // CLOCKS.CAM_PCLK_HZ)
        return line, max(line, line * (g.height + 8) // 2)

    def signature(self):
        """The system's signature (see :class:`StereoDepthSystem`'s Attributes)."""
        members = {
            **{f"cam_{c}": In(CameraSignature) for c in CAMERAS},
            "capture": Out(wiring.Signature({f"cam_{c}": Out(CaptureStatusSignature) for c in CAMERAS})),
            "i2c": Out(wiring.Signature({bus: Out(I2CSignature) for bus in I2C_BUSES})),
            "init": Out(wiring.Signature({bus: Out(InitStatusSignature(len(table)))
                                          for bus, table in self.tables.items()})),
            "panel": Out(PanelSignature),
            "control": Out(ControlSignature),
            "video": Out(VideoSignature),
            "frame_start": Out(1),
            "settings": Out(SettingsSignature),
            "skew": Out(FrameSkewSignature(skew_bits(*self.skew_clocks))),
            "rectification": Out(wiring.Signature({n: Out(1) for n in ("auto", "confident", "held", "locked")})),
        }
        if self.ddr is not None:
            members["ch7301c"] = Out(CH7301CSignature)
        if self.memory == "ddr2":
            members["mig"] = Out(MIGUserSignature())
            members["display_missed"] = Out(DISPLAY_MISSED_BITS)
        return wiring.Signature(members)

    @property
    def store_layout(self):
        """With ``memory="ddr2"``: the frame store's layout (a buffer of the capture's size per frame; with
        ``maps="store"`` three map buffers of the engine's codes)."""
        if self.maps == "store":
            return FrameStoreLayout(width=self.geometry.buf_width, height=self.geometry.buf_height, maps=3,
                                    map_bits=self.depth.code_bits)
        return FrameStoreLayout(width=self.geometry.buf_width, height=self.geometry.buf_height)


class StereoDepthSystem(wiring.Component):
    """The whole system without clocking or pins: see the module docstring.

    Parameters
    ----------
    *args, **kwargs
        The parameters: :class:`SystemParameters`.

    Attributes
    ----------
    params : :class:`SystemParameters`
    geometry, video_timing
        The parameters ``geometry`` and ``timing``.
    cam_a, cam_b : ``In(CameraSignature)``
        Camera pins (``cam_<c>`` domain).
    capture : ``Out``, per camera ``cam_a``, ``cam_b`` a ``CaptureStatusSignature``
        Each capture's status (``cam_<c>``).
    i2c : ``Out``, per bus ``cam_a``, ``cam_b``, ``dvi`` an ``I2CSignature``
        The open-drain I2C pins (``sync``).
    init : ``Out``, per bus an ``InitStatusSignature``
        The status of each bus's table (``sync``): ``dvi`` the CH7301C table's, ``cam_a`` and ``cam_b`` both the
        cameras' shared table's.
    panel : ``Out(PanelSignature)``
        Switches (asynchronous) and LEDs.
    control : ``Out(ControlSignature)``
    video : ``Out(VideoSignature)``
        The compositor's stream (``pix``): what the output stage takes.
    ch7301c : ``Out(CH7301CSignature)``
        The CH7301C pins (``pix``), with ``ddr="behavioural"`` only.
    skew : ``Out(FrameSkewSignature)``
        The cameras' frame-start skew (see above).
    frame_start : ``Out(1)``
        The sync generator's strobe (``pix``), :data:`DISPLAY_LATENCY` clocks before pixel (0, 0) reaches the pins.
    settings : ``Out(SettingsSignature)``
        The settings in use (``pix``): the switch registers, or in automatic mode the estimator's rectification.
    rectification : ``Out``: ``auto``, ``confident``, ``held``, ``locked``
        The automatic rectification's mode and the estimator's last verdict (``pix``).
    mig : ``Out(MIGUserSignature())``
        With ``memory="ddr2"`` only: MIG's user interface (``mem``).
    display_missed : ``Out(DISPLAY_MISSED_BITS)``
        With ``memory="ddr2"`` only: ``pix`` clocks since reset in which the frame store refused a compositor read
        the picture uses (:class:`hdl.store_windows.StoreWindows`), saturating; 0 in a sound run.

    Each member is connected to the block that drives or reads it (``wiring.connect``, flipped).

    Raises
    ------
    ValueError, TypeError
        As :class:`SystemParameters`.
    """

    def __init__(self, *args, **kwargs):
        self.params = SystemParameters(*args, **kwargs)
        self.geometry, self.video_timing = self.params.geometry, self.params.timing
        super().__init__(self.params.signature())

    def elaborate(self, platform):
        m = Module()
        p = self.params
        sequencer = self._init(m)
        capture = add_reset_subtree(m, "capture", CapturePath(p.geometry, cameras=CAMERAS, r_byte_first=p.r_byte_first,
                                                              read_domain="pix", buffers=p.memory == "bram"), "pix")
        for c in CAMERAS:
            port = capture.port(c)
            wiring.connect(m, wiring.flipped(getattr(self, f"cam_{c}")), port.pins)
            wiring.connect(m, wiring.flipped(getattr(self.capture, f"cam_{c}")), port.status)
        line, most = p.skew_clocks
        m.submodules.skew_meter = meter = FrameSkewMeter(line_clocks=line, max_clocks=most,
                                                         cam_domains=tuple(f"cam_{c}" for c in CAMERAS))
        m.d.comb += [meter.start_a.eq(capture.cam_a.status.frame_start),
                     meter.start_b.eq(capture.cam_b.status.frame_start)]
        wiring.connect(m, wiring.flipped(self.skew), meter.status)
        sync_gen = self._display(m, capture)
        self._leds(m, sync_gen, sequencer)
        return m

    def _init(self, m):
        """The I2C init sequencer (``sync``) of all three buses: the CH7301C's table on its bus, then the cameras'
        table on both camera buses at once (so the sensors are configured in step, docs/hardware-facts.md); the
        sensor / transmitter reset and power pins. Returns the sequencer."""
        p = self.params
        cam_buses = tuple(I2C_BUSES.index(f"cam_{c}") for c in CAMERAS)
        phases = (Phase("dvi", p.dvi_table, (I2C_BUSES.index("dvi"),)), Phase("cams", p.cam_table, cam_buses))
        m.submodules[I2C_SEQUENCER] = seq = InitSequencer(phases, buses=len(I2C_BUSES), clk_hz=p.clk_hz,
                                                          bus_hz=p.i2c_hz, retry_delay_us=p.i2c_retry_delay_us)
        for k, bus in enumerate(I2C_BUSES):
            wiring.connect(m, wiring.flipped(getattr(self.i2c, bus)), seq.i2c[k])
        wiring.connect(m, seq.status.cams, *(wiring.flipped(getattr(self.init, f"cam_{c}")) for c in CAMERAS))
        wiring.connect(m, seq.status.dvi, wiring.flipped(self.init.dvi))

        # Sensor / transmitter reset and power: low in reset, high from the first sync clock after it.
        out_of_reset = Signal()
        m.d.sync += out_of_reset.eq(1)
        control = self.control
        m.d.comb += [
            control.cam_rst_n.eq(out_of_reset), control.dvi_reset_n.eq(out_of_reset),
            control.cam_vdden.eq(out_of_reset), control.cam_pwdn.eq(0),
        ]
        return seq

    def _display(self, m, capture):
        """The pixel-clock side: sync generator, switches, rectification, the display, the row tags and the output
        stage. Returns the sync generator."""
        p = self.params
        pix = DomainRenamer("pix")
        sync_gen = add_reset_subtree(m, "sync_gen", pix(SyncGenerator(p.timing)), "pix")
        switches = add_reset_subtree(m, "switches", SwitchControl(domain="pix"), "pix")
        display = add_reset_subtree(m, "display", pix(StereoDisplay(
            p.timing, p.geometry, p.layout, config=p.depth, thresholds=p.thresholds, level_grey=p.level_grey,
            memory=p.memory, slots=p.store_slots, maps=p.maps)), "pix")
        m.d.comb += [switches.sw.eq(self.panel.sw), switches.frame_start.eq(sync_gen.frame_start),
                     self.frame_start.eq(sync_gen.frame_start)]
        wiring.connect(m, sync_gen, display.timing)
        select = self._rectification(m, capture, pix, sync_gen)
        wiring.connect(m, switches.settings, select.manual)
        wiring.connect(m, select.settings, display.settings, wiring.flipped(self.settings))
        m.d.comb += display.segment.eq(select.segment)
        wiring.connect(m, select.mode, display.rectification_mode)
        if p.memory == "ddr2":
            self._frame_store(m, capture, display)
        else:
            self._buffers(m, capture, display, pix)
        if p.ddr is None:
            wiring.connect(m, wiring.flipped(self.video), display.video)
        else:
            output = add_reset_subtree(m, "output", pix(CH7301COutput(p.timing, ddr=p.ddr)), "pix")
            wiring.connect(m, display.video, output.video, wiring.flipped(self.video))
            wiring.connect(m, wiring.flipped(self.ch7301c), output.pins)
        return sync_gen

    def _buffers(self, m, capture, display, pix):
        """The block-RAM build: the display on the buffers' read ports, the row tags and the frame pairing."""
        p = self.params
        wiring.connect(m, display.left, capture.cam_a.read)       # camera A = left
        wiring.connect(m, display.right, capture.cam_b.read)      # camera B = right
        pairing = add_reset_subtree(m, "frame_pairing", pix(FramePairing()), "pix")
        for c, side in zip(CAMERAS, ("left", "right")):
            tracker = add_reset_subtree(m, f"row_tags_{c}", RowTagTracker(p.geometry, cam_domain=f"cam_{c}",
                                                                          pix_domain="pix"), "pix")
            status = capture.port(c).status
            m.d.comb += [getattr(tracker, strobe).eq(getattr(status, strobe))     # the capture's, read by its tracker
                         for strobe in ("frame_start", "row_start", "row_end")]
            wiring.connect(m, getattr(display, f"{side}_tags"), tracker.read)
            wiring.connect(m, tracker.pair, getattr(pairing, c))

    def _frame_store(self, m, capture, display):
        """The DDR2 build: the captures into the frame store, its streams to the display, its memory side on
        ``mig``."""
        p = self.params
        # Its read side in a pix reset subtree as the display's windows are: they leave reset in the same clock.
        store = add_reset_subtree(m, "frame_store", FrameStore(
            p.store_layout, p.geometry, streams=STREAMS, slots=p.store_slots,
            cam_domains=tuple(f"cam_{c}" for c in CAMERAS), read_domain="pix", mem_domain="mem"), "pix")
        for i, c in enumerate(CAMERAS):
            port = capture.port(c)
            wiring.connect(m, port.write, store.cameras[i].write)
            wiring.connect(m, port.status, store.cameras[i].status)
        for i in range(len(STREAMS)):
            wiring.connect(m, display.streams[i], store.streams[i])
        m.d.comb += [store.take.eq(display.take), display.taken.eq(store.taken)]
        if p.maps == "store":
            wiring.connect(m, display.map_feed, store.map_feed)
            wiring.connect(m, display.map_stream, store.map_stream)
            m.d.comb += [store.map_take.eq(display.map_take), display.map_taken.eq(store.map_taken),
                         display.map_valid.eq(store.map_valid), display.map_room.eq(store.map_room)]
        wiring.connect(m, wiring.flipped(self.mig), store.mig)
        missed = self.display_missed
        with m.If(display.display_missed & ~missed.all()):
            m.d.pix += missed.eq(missed + 1)

    def _rectification(self, m, capture, pix, sync_gen):
        """The estimator watches both captures' writes (camera A = left); the select picks manual or automatic.
        Returns the select."""
        p = self.params
        est = add_reset_subtree(m, "vertical_offset", pix(VerticalOffsetEstimator(
            p.geometry, p.auto_rectification, left_domain="cam_a", right_domain="cam_b")), "pix")
        select = add_reset_subtree(m, "rectification_select", pix(RectificationSelect(p.auto_rectification)), "pix")
        for side, port in (("left", capture.cam_a), ("right", capture.cam_b)):
            watch = getattr(est, side)
            m.d.comb += [watch.addr.eq(port.write.addr), watch.data.eq(port.write.data),
                         watch.en.eq(port.write.en), watch.frame_done.eq(port.status.frame_done)]
        m.d.comb += [select.estimate.eq(est.offset), select.estimate_held.eq(est.held),
                     select.frame_start.eq(sync_gen.frame_start), self.rectification.auto.eq(select.auto)]
        m.d.comb += [getattr(self.rectification, name).eq(getattr(est, name)) for name in ("confident", "held", "locked")]
        return select

    def _leds(self, m, sync_gen, sequencer):
        """The status LEDs (see the module docstring)."""
        p = self.params
        frames = Signal(p.heartbeat_log2 + 1)
        with m.If(sync_gen.frame_start):
            m.d.pix += frames.eq(frames + 1)
        init = self.init
        # A camera bus's error LED: the shared init's error, unless it is a NACK that bus gave no part in.
        nack = (init.cam_a.error_code == ErrorCode.NACK_ADDR) | (init.cam_a.error_code == ErrorCode.NACK_DATA)
        blamed = [~nack | sequencer.nacked[I2C_BUSES.index(f"cam_{c}")] for c in CAMERAS]
        m.d.comb += [
            self.panel.leds[0].eq(init.cam_a.done), self.panel.leds[1].eq(init.cam_a.error & blamed[0]),
            self.panel.leds[2].eq(init.cam_b.done), self.panel.leds[3].eq(init.cam_b.error & blamed[1]),
            self.panel.leds[4].eq(init.dvi.done),
            self.panel.leds[5].eq(init.dvi.error | (init.dvi.mismatch & frames[-1])),
            self.panel.leds[6].eq(frames[-1]),
            self.panel.leds[7].eq(self.capture.cam_a.frame_count[p.cam_heartbeat_log2]
                                  | (self.skew.valid & ~self.skew.aligned)),
        ]
