"""StereoDepthSystem: the whole design of thesis figure 4.1, board-independent and simulatable.

Blocks (each in its own file, see docs/architecture.md):

* two cameras: an :class:`~hdl.i2c_init.InitSequencer` per camera bus (each MT9D112 has its own I2C bus) and a
  :class:`~hdl.capture_path.CapturePath` (capture + frame buffer per camera; camera A = left, B = right);
* the display: :class:`~hdl.sync_gen.SyncGenerator` -> :class:`~hdl.compositor.Compositor` (which holds the
  :class:`~hdl.disparity.DisparitySubtractor` and reads both frame buffers) -> :class:`~hdl.ch7301c_output.
  CH7301COutput`; :class:`~hdl.switches.SwitchControl` turns SW7..SW0 into the disparity and rectification
  registers;
* the CH7301C's own :class:`~hdl.i2c_init.InitSequencer` on the board's I2C bus;
* status LEDs and the sensor/transmitter reset and power pins.

Clock domains (defined by the parent: :class:`~hdl.top.GenesysTop` on the board, :class:`SimSystem` in
simulation; exported Verilog of :class:`SimSystem` names the clocks ``clk``, ``pix_clk``, ``cam_a_clk``,
``cam_b_clk``):

=========  ================================================================================================
``sync``   100 MHz: the three I2C init sequencers, the sensor/transmitter reset pins, LEDs 0..5
``pix``    148.5 MHz: sync generator, switches, compositor, frame-buffer read ports, CH7301C output, LED 6
``cam_a``  camera A's PCLK: its capture and frame-buffer write port, LED 7
``cam_b``  camera B's PCLK: its capture and frame-buffer write port
=========  ================================================================================================

CH7301C output stage: with ``ddr="behavioural"`` (simulation, Verilog export) the system ends in
:class:`~hdl.ch7301c_output.CH7301COutput`'s behavioural dual-edge model and has the CH7301C pins as ports. With
``ddr=None`` (the board) it stops at the compositor's video stream (``video_rgb``, ``video_de``, ``video_hsync``,
``video_vsync``, ``pix``) and :class:`hdl.top.GenesysTop` builds the pins from Virtex-5 ODDRs (through
``amaranth.lib.io.DDRBuffer``), including the XCLK pair as two single-ended ODDR outputs in the 90-degree
``pix90`` domain: the Genesys's XCLK pins are LVCMOS33 (docs/board.md), so the OBUFDS of
``CH7301COutput(ddr="virtex5")`` cannot drive them.

Status LEDs (``leds``): 0 camera A bus init done, 1 camera A bus error, 2 camera B bus init done, 3 camera B
bus error, 4 CH7301C init done, 5 CH7301C error, 6 display heartbeat (toggles every ``2**heartbeat_log2``
display frames: 32 frames = 0.53 s at 60 Hz), 7 camera A heartbeat (toggles every ``2**cam_heartbeat_log2``
captured frames, about 0.5 s at 15 fps).

Sensor and transmitter control pins (``sync``): ``cam_rst_n`` and ``dvi_reset_n`` are low while ``sync`` is in
reset (so until the clocks are locked) and high from the first clock after; ``cam_vdden`` (VmodCAM supply
enable) is high once out of reset; ``cam_pwdn`` is low. The MT9D112 table starts with a wait longer than the
sensor's 7000-MCLK boot time, so the first I2C access follows the reset release correctly.

Latency: from a raster position of the sync generator to the CH7301C pins, :data:`DISPLAY_LATENCY` pixel clocks
(compositor 6 + output 1). The display runs from reset; each frame buffer shows whatever its camera last wrote
(zeros before the first capture): there is no double buffering (thesis design), so a display frame scanned
while a capture is in progress can show part old, part new image.
"""

from amaranth import DomainRenamer, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from .capture_path import CapturePath
from .ch7301c_output import CH7301COutput, ch7301c_pin_members, forward_ch7301c_pins
from .compositor import LATENCY as COMPOSITOR_LATENCY, Compositor
from .i2c_init import InitSequencer
from .init_tables import CH7301C_TABLE, MT9D112_TABLE
from .params import CEA_1080P60, CLOCKS, DIFF_LEVEL_GREY, DIFF_THRESHOLDS, SENSOR
from .switches import SwitchControl
from .sync_gen import SyncGenerator

__all__ = ["StereoDepthSystem", "SimSystem", "DISPLAY_LATENCY", "CAMERAS", "I2C_BUSES"]

#: Pixel clocks from a sync-generator raster position to that pixel on the CH7301C pins.
DISPLAY_LATENCY = COMPOSITOR_LATENCY + 1
#: Camera names: "a" is the left camera, "b" the right one.
CAMERAS = ("a", "b")
#: The I2C buses: one per camera, one for the CH7301C.
I2C_BUSES = ("cam_a", "cam_b", "dvi")


def _bus_members():
    members = {}
    for bus in I2C_BUSES:
        members.update({
            f"{bus}_scl_o": Out(1), f"{bus}_scl_oe": Out(1), f"{bus}_scl_i": In(1, init=1),
            f"{bus}_sda_o": Out(1), f"{bus}_sda_oe": Out(1), f"{bus}_sda_i": In(1, init=1),
            f"{bus}_init_done": Out(1), f"{bus}_init_error": Out(1),
        })
    return members


class StereoDepthSystem(wiring.Component):
    """The whole system without clocking or pins: see the module docstring.

    Parameters: ``geometry`` (sensor and buffers), ``timing`` (video mode), ``layout`` (screen layout, default
    centred), ``thresholds``/``level_grey`` (disparity display), ``cam_table``/``dvi_table`` (I2C init tables),
    ``clk_hz``/``i2c_hz`` (``sync`` clock and I2C bus rates), ``i2c_retry_delay_us``, ``r_byte_first`` (byte
    order the capture expects), ``ddr`` (``"behavioural"``: the CH7301C pins from the behavioural dual-edge
    model, for simulation and Verilog export; ``None``: the video stream only, for the board top level),
    ``heartbeat_log2``/``cam_heartbeat_log2`` (LED blink rates).

    Ports: camera pins ``cam_<c>_data[8]``, ``cam_<c>_lv``, ``cam_<c>_fv`` (``cam_<c>`` domain); open-drain
    I2C pins ``<bus>_scl_o/oe/i``, ``<bus>_sda_o/oe/i`` and ``<bus>_init_done/error`` for ``cam_a``, ``cam_b``,
    ``dvi`` (``sync``); ``sw[8]`` (asynchronous); ``leds[8]``; ``cam_rst_n``, ``cam_pwdn``, ``cam_vdden``,
    ``dvi_reset_n``; CH7301C pins ``data[12]``, ``hsync``, ``vsync``, ``de``, ``xclk_p``, ``xclk_n`` (with
    ``ddr="behavioural"``); the video stream ``video_rgb[24]``, ``video_de``, ``video_hsync``, ``video_vsync``
    (``pix``, what the output stage takes); and for
    test benches ``frame_start`` (``pix``, the sync generator's strobe, :data:`DISPLAY_LATENCY` clocks before
    pixel (0, 0) reaches the pins), ``disparity``/``rectification`` (``pix``, the switch registers) and per
    camera ``cam_<c>_frame_done``, ``cam_<c>_frame_ok``, ``cam_<c>_frame_count`` (``cam_<c>``).
    """

    def __init__(self, geometry=SENSOR, timing=CEA_1080P60, layout=None, *, thresholds=DIFF_THRESHOLDS,
                 level_grey=DIFF_LEVEL_GREY, cam_table=MT9D112_TABLE, dvi_table=CH7301C_TABLE,
                 clk_hz=CLOCKS.SYS_HZ, i2c_hz=CLOCKS.I2C_HZ, i2c_retry_delay_us=1000, r_byte_first=True,
                 ddr="behavioural", heartbeat_log2=5, cam_heartbeat_log2=3):
        self.geometry = geometry
        self.video_timing = timing
        self.layout = layout
        self.thresholds = thresholds
        self.level_grey = level_grey
        self.cam_table = cam_table
        self.dvi_table = dvi_table
        self.clk_hz = clk_hz
        self.i2c_hz = i2c_hz
        self.i2c_retry_delay_us = i2c_retry_delay_us
        self.r_byte_first = r_byte_first
        self.ddr = ddr
        self.heartbeat_log2 = heartbeat_log2
        self.cam_heartbeat_log2 = cam_heartbeat_log2
        if ddr not in ("behavioural", None):
            raise ValueError(f"ddr must be 'behavioural' or None (board: pins built by hdl.top), not {ddr!r}")
        members = {
            "sw": In(8),
            "leds": Out(8),
            "cam_rst_n": Out(1), "cam_pwdn": Out(1), "cam_vdden": Out(1), "dvi_reset_n": Out(1),
            "video_rgb": Out(24), "video_de": Out(1), "video_hsync": Out(1), "video_vsync": Out(1),
            "frame_start": Out(1), "disparity": Out(7), "rectification": Out(7),
        }
        if ddr is not None:
            members.update(ch7301c_pin_members())
        for c in CAMERAS:
            members.update({
                f"cam_{c}_data": In(8), f"cam_{c}_lv": In(1), f"cam_{c}_fv": In(1),
                f"cam_{c}_frame_done": Out(1), f"cam_{c}_frame_ok": Out(1), f"cam_{c}_frame_count": Out(16),
            })
        members.update(_bus_members())
        super().__init__(members)
        # Build the blocks now so that bad parameters fail at construction, not at elaboration.
        self._capture = CapturePath(geometry, cameras=CAMERAS, r_byte_first=r_byte_first, read_domain="pix")
        self._compositor = Compositor(timing, geometry, layout, thresholds=thresholds, level_grey=level_grey)
        self._output = CH7301COutput(timing, ddr=ddr) if ddr is not None else None
        self._sequencers = {
            bus: InitSequencer(table, clk_hz=clk_hz, bus_hz=i2c_hz, retry_delay_us=i2c_retry_delay_us)
            for bus, table in (("cam_a", cam_table), ("cam_b", cam_table), ("dvi", dvi_table))
        }

    def _bus(self, bus, name):
        return getattr(self, f"{bus}_{name}")

    def elaborate(self, platform):
        m = Module()

        # --- I2C init: one sequencer per bus (sync) -----------------------------------------------------------
        for bus, seq in self._sequencers.items():
            m.submodules[f"init_{bus}"] = seq
            for line in ("scl", "sda"):
                m.d.comb += [
                    self._bus(bus, f"{line}_o").eq(getattr(seq, f"{line}_o")),
                    self._bus(bus, f"{line}_oe").eq(getattr(seq, f"{line}_oe")),
                    getattr(seq, f"{line}_i").eq(self._bus(bus, f"{line}_i")),
                ]
            m.d.comb += [self._bus(bus, "init_done").eq(seq.done), self._bus(bus, "init_error").eq(seq.error)]

        # Sensor / transmitter reset and power: low in reset, high from the first sync clock after it.
        out_of_reset = Signal()
        m.d.sync += out_of_reset.eq(1)
        m.d.comb += [
            self.cam_rst_n.eq(out_of_reset), self.dvi_reset_n.eq(out_of_reset),
            self.cam_vdden.eq(out_of_reset), self.cam_pwdn.eq(0),
        ]

        # --- cameras: capture + frame buffers (cam_a / cam_b write, pix read) ----------------------------------
        m.submodules.capture = cap = self._capture
        for c in CAMERAS:
            m.d.comb += [
                cap.port(c, "data").eq(getattr(self, f"cam_{c}_data")),
                cap.port(c, "lv").eq(getattr(self, f"cam_{c}_lv")),
                cap.port(c, "fv").eq(getattr(self, f"cam_{c}_fv")),
                getattr(self, f"cam_{c}_frame_done").eq(cap.port(c, "frame_done")),
                getattr(self, f"cam_{c}_frame_ok").eq(cap.port(c, "frame_ok")),
                getattr(self, f"cam_{c}_frame_count").eq(cap.port(c, "frame_count")),
            ]

        # --- display (pix) -------------------------------------------------------------------------------------
        pix = DomainRenamer("pix")
        m.submodules.sync_gen = sync_gen = pix(SyncGenerator(self.video_timing))
        m.submodules.switches = switches = SwitchControl(domain="pix")
        m.submodules.compositor = comp = pix(self._compositor)
        wiring.connect(m, sync_gen, comp.timing)
        m.d.comb += [
            self.video_rgb.eq(comp.video.rgb), self.video_de.eq(comp.video.de),
            self.video_hsync.eq(comp.video.hsync), self.video_vsync.eq(comp.video.vsync),
        ]
        if self._output is not None:
            m.submodules.output = out = pix(self._output)
            wiring.connect(m, comp.video, out.video)
            forward_ch7301c_pins(m, self, out)
        m.d.comb += [
            switches.sw.eq(self.sw),
            switches.frame_start.eq(sync_gen.frame_start),
            comp.disparity.eq(switches.disparity),
            comp.rectification.eq(switches.rectification),
            cap.port("a", "r_addr").eq(comp.left_addr),       # camera A = left
            comp.left_data.eq(cap.port("a", "r_data")),
            cap.port("b", "r_addr").eq(comp.right_addr),      # camera B = right
            comp.right_data.eq(cap.port("b", "r_data")),
            self.frame_start.eq(sync_gen.frame_start),
            self.disparity.eq(switches.disparity),
            self.rectification.eq(switches.rectification),
        ]

        # --- LEDs ------------------------------------------------------------------------------------------------
        frames = Signal(self.heartbeat_log2 + 1)
        with m.If(sync_gen.frame_start):
            m.d.pix += frames.eq(frames + 1)
        m.d.comb += [
            self.leds[0].eq(self.cam_a_init_done), self.leds[1].eq(self.cam_a_init_error),
            self.leds[2].eq(self.cam_b_init_done), self.leds[3].eq(self.cam_b_init_error),
            self.leds[4].eq(self.dvi_init_done), self.leds[5].eq(self.dvi_init_error),
            self.leds[6].eq(frames[-1]),
            self.leds[7].eq(cap.port("a", "frame_count")[self.cam_heartbeat_log2]),
        ]
        return m


class SimSystem(wiring.Component):
    """:class:`StereoDepthSystem` with the simulation clocking model (:class:`hdl.clocking.SimClocking`): the
    design the simulations and the exported-Verilog tests run.

    Defines the domains ``sync``, ``pix``, ``cam_a``, ``cam_b``; their clocks come from the simulator (Amaranth:
    ``add_clock``; Verilog: ports ``clk``, ``pix_clk``, ``cam_a_clk``, ``cam_b_clk``), their resets from the
    model's reset tree, released ``lock_cycles`` ``sync`` clocks after ``button`` goes low. Ports: those of
    :class:`StereoDepthSystem` plus ``button`` (the reset button, active high) and ``locked``.
    ``system_kwargs`` go to :class:`StereoDepthSystem` (``ddr`` is always ``"behavioural"`` here).

    With ``define_domains=False`` the domains (``self.clocking.domains``) are left to the parent to add: a
    domain's clock becomes a port of exported Verilog only when the domain is defined in the top module.
    """

    def __init__(self, *, lock_cycles=16, define_domains=True, **system_kwargs):
        from .clocking import SimClocking
        self.define_domains = define_domains
        if system_kwargs.get("ddr", "behavioural") != "behavioural":
            raise ValueError("SimSystem simulates the behavioural dual-edge output only")
        self.system = StereoDepthSystem(**system_kwargs)
        self.clocking = SimClocking(cam_domains=tuple(f"cam_{c}" for c in CAMERAS), lock_cycles=lock_cycles)
        members = dict(self.system.signature.members)
        members.update({"button": In(1), "locked": Out(1)})
        super().__init__(members)

    def elaborate(self, platform):
        m = Module()
        if self.define_domains:
            m.domains += self.clocking.domains
        m.submodules.clocking = clk = self.clocking
        m.submodules.system = sys_ = self.system
        m.d.comb += [clk.button.eq(self.button), self.locked.eq(clk.locked)]
        for name, member in self.system.signature.members.items():
            ours, theirs = getattr(self, name), getattr(sys_, name)
            if member.flow == In:
                m.d.comb += theirs.eq(ours)
            else:
                m.d.comb += ours.eq(theirs)
        return m
