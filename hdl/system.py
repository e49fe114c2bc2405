"""StereoDepthSystem: the whole design of thesis figure 4.1, board-independent and simulatable.

Blocks (each in its own file, see docs/architecture.md):

* two cameras: an :class:`~hdl.i2c_init.InitSequencer` per camera bus (each MT9D112 has its own I2C bus) and a
  :class:`~hdl.capture_path.CapturePath` (capture + frame buffer per camera; camera A = left, B = right);
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
* the CH7301C's own :class:`~hdl.i2c_init.InitSequencer` on the board's I2C bus;
* status LEDs and the sensor/transmitter reset and power pins.

Clock domains (defined by the parent: :class:`~board.top.GenesysTop` with the board clocking on the board, the
simulation testbench with :class:`~sim.models.clocking.SimClocking` in simulation, whose exported Verilog names the clocks
``clk``, ``pix_clk``, ``cam_a_clk``, ``cam_b_clk``):

=========  ================================================================================================
``sync``   100 MHz: the three I2C init sequencers, the sensor/transmitter reset pins, LEDs 0..5
``pix``    148.5 MHz: sync generator, switches, compositor, depth engine, frame-buffer read ports, CH7301C output,
           the vertical-offset search and the rectification select, the row-tag trackers and their frame pairing, LED 6
``cam_a``  camera A's PCLK: its capture and frame-buffer write port, its row sums, its tracker's strobe toggles, LED 7
``cam_b``  camera B's PCLK: its capture and frame-buffer write port, its row sums, its tracker's strobe toggles
=========  ================================================================================================

CH7301C output stage: with ``ddr="behavioural"`` (simulation, Verilog export) the system ends in
:class:`~hdl.ch7301c_output.CH7301COutput`'s behavioural dual-edge model and has the CH7301C pins (``ch7301c``).
With ``ddr=None`` (the board) it stops at the compositor's video stream (``video``, ``pix``) and
:class:`board.top.GenesysTop` builds the pins from Virtex-5 ODDRs (through ``amaranth.lib.io.DDRBuffer``), including
the XCLK pair as two single-ended ODDR outputs in the 90-degree ``pix90`` domain: the Genesys's XCLK pins are
LVCMOS33 (docs/board.md), so the OBUFDS of ``CH7301COutput(ddr="virtex5")`` cannot drive them.

Status LEDs (``panel.leds``): 0 camera A bus init done, 1 camera A bus error, 2 camera B bus init done, 3 camera B
bus error, 4 CH7301C init done, 5 CH7301C: steady on = I2C error (bring-up stopped), blinking with LED 6 = its
version or device ID byte (0x4A / 0x4B) read another value than the table's (``init.dvi.mismatch``, bring-up
went on), 6 display heartbeat (toggles every ``2**heartbeat_log2`` display frames: 32 frames = 0.53 s at
60 Hz), 7 camera A heartbeat (toggles every ``2**cam_heartbeat_log2`` captured frames, about 0.5 s at 15 fps),
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

from amaranth import DomainRenamer, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.capture import CameraSignature, CaptureStatusSignature
from hdl.capture_path import CapturePath
from hdl.ch7301c_output import CH7301COutput, CH7301CSignature
from hdl.stereo_display import LATENCY as COMPOSITOR_LATENCY, StereoDisplay
from hdl.forward import forward
from hdl.frame_skew import FrameSkewMeter, FrameSkewSignature
from hdl.i2c_init import InitSequencer, InitStatusSignature
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
from hdl.sync_gen import SyncGenerator
from hdl.video_bus import VideoSignature
from hdl.reset_tree import add_reset_subtree
from hdl.row_tags import RowTagTracker
from hdl.frame_pairing import FramePairing

__all__ = ["StereoDepthSystem", "PanelSignature", "ControlSignature", "DISPLAY_LATENCY", "CAMERAS", "I2C_BUSES"]

#: Pixel clocks from a sync-generator raster position to that pixel on the CH7301C pins.
DISPLAY_LATENCY = COMPOSITOR_LATENCY + 1
#: Camera names: "a" is the left camera, "b" the right one; camera ``c`` runs in domain ``cam_<c>``.
CAMERAS = ("a", "b")
#: The I2C buses: one per camera, one for the CH7301C.
I2C_BUSES = ("cam_a", "cam_b", "dvi")

#: The board's user panel as the design sees it: the eight slide switches in (asynchronous), the eight LEDs out.
PanelSignature = wiring.Signature({"sw": In(8), "leds": Out(8)})

#: Reset and power pins of the sensors and the transmitter (``sync``).
ControlSignature = wiring.Signature({
    "cam_rst_n": Out(1), "cam_pwdn": Out(1), "cam_vdden": Out(1), "dvi_reset_n": Out(1),
})


class StereoDepthSystem(wiring.Component):
    """The whole system without clocking or pins: see the module docstring.

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

    Attributes
    ----------
    cam_a, cam_b : ``In(CameraSignature)``
        Camera pins (``cam_<c>`` domain).
    capture : ``Out``, per camera ``cam_a``, ``cam_b`` a ``CaptureStatusSignature``
        Each capture's status (``cam_<c>``).
    i2c : ``Out``, per bus ``cam_a``, ``cam_b``, ``dvi`` an ``I2CSignature``
        The open-drain I2C pins (``sync``).
    init : ``Out``, per bus an ``InitStatusSignature``
        Each init sequencer's status (``sync``).
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

    Every member is handed down to the block that drives or reads it (:func:`hdl.forward.forward`).

    Raises
    ------
    ValueError
        Any block's parameter check; ``ddr`` other than ``"behavioural"`` or ``None``.
    """

    def __init__(self, geometry=SENSOR, timing=CEA_1080P60, layout=None, *, thresholds=DIFF_THRESHOLDS,
                 level_grey=DIFF_LEVEL_GREY, depth=DEPTH, auto_rectification=RECTIFICATION, cam_table=MT9D112_TABLE,
                 dvi_table=CH7301C_TABLE, clk_hz=CLOCKS.SYS_HZ, i2c_hz=CLOCKS.I2C_HZ, i2c_retry_delay_us=1000,
                 r_byte_first=True, ddr="behavioural", heartbeat_log2=5, cam_heartbeat_log2=3, skew_line_clocks=None):
        if ddr not in ("behavioural", None):
            raise ValueError(f"ddr must be 'behavioural' or None (board: pins built by board.top), not {ddr!r}")
        self.geometry = geometry
        self.video_timing = timing
        self.heartbeat_log2 = heartbeat_log2
        self.cam_heartbeat_log2 = cam_heartbeat_log2
        # The blocks, built now so that bad parameters fail at construction and the members can be forwarded.
        self.capture_path = CapturePath(geometry, cameras=CAMERAS, r_byte_first=r_byte_first, read_domain="pix")
        self.row_tags = {c: RowTagTracker(geometry, cam_domain=f"cam_{c}", pix_domain="pix") for c in CAMERAS}
        self.frame_pairing = FramePairing()
        self.display = StereoDisplay(timing, geometry, layout, config=depth, thresholds=thresholds,
                                        level_grey=level_grey)
        self.sync_gen = SyncGenerator(timing)
        self.switches = SwitchControl(domain="pix")
        self.estimator = VerticalOffsetEstimator(geometry, auto_rectification, left_domain="cam_a",
                                                 right_domain="cam_b")
        self.select = RectificationSelect(auto_rectification)
        self.output = CH7301COutput(timing, ddr=ddr) if ddr is not None else None
        line = skew_line_clocks or -(-(2 * geometry.width + 256) * clk_hz // CLOCKS.CAM_PCLK_HZ)
        self.skew_meter = FrameSkewMeter(
            line_clocks=line, max_clocks=max(line, line * (geometry.height + 8) // 2),
            cam_domains=tuple(f"cam_{c}" for c in CAMERAS))
        tables = {"cam_a": cam_table, "cam_b": cam_table, "dvi": dvi_table}
        self.sequencers = {
            bus: InitSequencer(table, clk_hz=clk_hz, bus_hz=i2c_hz, retry_delay_us=i2c_retry_delay_us)
            for bus, table in tables.items()
        }
        super().__init__(self._members(tables))
        # The switches' settings output is the select's own manual input (one set of signals, named after the
        # select's member: the system's ``settings`` are the select's output).
        forward(self.select, "manual", self.switches, "settings")
        self._forward_members()

    def _members(self, tables):
        members = {
            **{f"cam_{c}": In(CameraSignature) for c in CAMERAS},
            "capture": Out(wiring.Signature({f"cam_{c}": Out(CaptureStatusSignature) for c in CAMERAS})),
            "i2c": Out(wiring.Signature({bus: Out(I2CSignature) for bus in I2C_BUSES})),
            "init": Out(wiring.Signature({bus: Out(InitStatusSignature(len(tables[bus]))) for bus in I2C_BUSES})),
            "panel": Out(PanelSignature),
            "control": Out(ControlSignature),
            "video": Out(VideoSignature),
            "frame_start": Out(1),
            "settings": Out(SettingsSignature),
            "skew": Out(FrameSkewSignature(self.skew_meter.bits)),
            "rectification": Out(wiring.Signature({n: Out(1) for n in ("auto", "confident", "held", "locked")})),
        }
        if self.output is not None:
            members["ch7301c"] = Out(CH7301CSignature)
        return members

    def _forward_members(self):
        for c in CAMERAS:
            forward(self, f"cam_{c}", self.capture_path, (f"cam_{c}", "pins"))
            forward(self, ("capture", f"cam_{c}"), self.capture_path, (f"cam_{c}", "status"))
            for strobe in ("frame_start", "row_start", "row_end"):     # the capture's strobes, read by its tracker
                forward(self, ("capture", f"cam_{c}", strobe), self.row_tags[c], strobe)
        for bus, seq in self.sequencers.items():
            forward(self, ("i2c", bus), seq, "i2c")
            forward(self, ("init", bus), seq, "status")
        forward(self, ("panel", "sw"), self.switches)
        forward(self, "video", self.display)
        forward(self, "frame_start", self.sync_gen)
        forward(self, "settings", self.select)
        forward(self, "skew", self.skew_meter, "status")
        forward(self, ("rectification", "auto"), self.select)
        for name in ("confident", "held", "locked"):
            forward(self, ("rectification", name), self.estimator)
        if self.output is not None:
            forward(self, "ch7301c", self.output, "pins")

    def elaborate(self, platform):
        m = Module()

        # --- I2C init: one sequencer per bus (sync) -----------------------------------------------------------
        for bus, seq in self.sequencers.items():
            m.submodules[f"init_{bus}"] = seq
        # The cameras' tables meet at their Barrier and go on together (docs/hardware-facts.md, "in step").
        cam_a, cam_b = self.sequencers["cam_a"], self.sequencers["cam_b"]
        m.d.comb += [seq.release.eq(cam_a.barrier & cam_b.barrier) for seq in (cam_a, cam_b)]

        # Sensor / transmitter reset and power: low in reset, high from the first sync clock after it.
        out_of_reset = Signal()
        m.d.sync += out_of_reset.eq(1)
        control = self.control
        m.d.comb += [
            control.cam_rst_n.eq(out_of_reset), control.dvi_reset_n.eq(out_of_reset),
            control.cam_vdden.eq(out_of_reset), control.cam_pwdn.eq(0),
        ]

        # --- cameras: capture + frame buffers (cam_a / cam_b write, pix read) ----------------------------------
        capture = add_reset_subtree(m, "capture", self.capture_path, "pix")
        m.submodules.skew_meter = meter = self.skew_meter
        m.d.comb += [meter.start_a.eq(capture.cam_a.status.frame_start),
                     meter.start_b.eq(capture.cam_b.status.frame_start)]

        # --- display (pix) -------------------------------------------------------------------------------------
        pix = DomainRenamer("pix")
        add_reset_subtree(m, "sync_gen", pix(self.sync_gen), "pix")
        switches = add_reset_subtree(m, "switches", self.switches, "pix")
        add_reset_subtree(m, "display", pix(self.display), "pix")
        wiring.connect(m, self.sync_gen, self.display.timing)
        self._rectification(m, capture, pix)
        wiring.connect(m, self.select.settings, self.display.settings)
        m.d.comb += self.display.segment.eq(self.select.segment)
        wiring.connect(m, self.select.mode, self.display.rectification_mode)
        wiring.connect(m, self.display.left, capture.cam_a.read)       # camera A = left
        wiring.connect(m, self.display.right, capture.cam_b.read)      # camera B = right
        add_reset_subtree(m, "frame_pairing", pix(self.frame_pairing), "pix")
        for c, side in zip(CAMERAS, ("left", "right")):
            tracker = add_reset_subtree(m, f"row_tags_{c}", self.row_tags[c], "pix")
            wiring.connect(m, getattr(self.display, f"{side}_tags"), tracker.read)
            wiring.connect(m, tracker.pair, getattr(self.frame_pairing, c))
        m.d.comb += switches.frame_start.eq(self.sync_gen.frame_start)
        if self.output is not None:
            add_reset_subtree(m, "output", pix(self.output), "pix")
            wiring.connect(m, self.display.video, self.output.video)

        # --- LEDs ------------------------------------------------------------------------------------------------
        frames = Signal(self.heartbeat_log2 + 1)
        with m.If(self.sync_gen.frame_start):
            m.d.pix += frames.eq(frames + 1)
        init = self.init
        m.d.comb += [
            self.panel.leds[0].eq(init.cam_a.done), self.panel.leds[1].eq(init.cam_a.error),
            self.panel.leds[2].eq(init.cam_b.done), self.panel.leds[3].eq(init.cam_b.error),
            self.panel.leds[4].eq(init.dvi.done),
            self.panel.leds[5].eq(init.dvi.error | (init.dvi.mismatch & frames[-1])),
            self.panel.leds[6].eq(frames[-1]),
            self.panel.leds[7].eq(self.capture.cam_a.frame_count[self.cam_heartbeat_log2]
                                  | (self.skew.valid & ~self.skew.aligned)),
        ]
        return m

    def _rectification(self, m, capture, pix):
        """The estimator watches both captures' writes (camera A = left); the select picks manual or automatic."""
        est, select = self.estimator, self.select
        add_reset_subtree(m, "vertical_offset", pix(est), "pix")
        add_reset_subtree(m, "rectification_select", pix(select), "pix")
        for side, port in (("left", capture.cam_a), ("right", capture.cam_b)):
            watch = getattr(est, side)
            m.d.comb += [watch.addr.eq(port.write.addr), watch.data.eq(port.write.data),
                         watch.en.eq(port.write.en), watch.frame_done.eq(port.status.frame_done)]
        m.d.comb += [select.estimate.eq(est.offset), select.estimate_held.eq(est.held),
                     select.frame_start.eq(self.sync_gen.frame_start)]
