"""One place that says how a whole-system simulation is set up: the design, time scale, clocks, models, golden frame.

:class:`SystemSetup` is shared by both simulators' runners (``sim/testbench/system/run_amaranth.py``,
``sim/testbench/system/run_cocotb.py`` and the scenario it runs inside the simulator), the tests, the benchmarks and the command
line, so every route simulates the same configuration and compares against the same golden frame.

A setup is a design (:attr:`SystemSetup.design`, an ``hdl.config.DesignConfig``: what a board build of the same
design is made from) plus the simulation's own settings. The design's fields are fields of the setup under the
design's names (``geometry``, ``timing``, ``layout``, ``thresholds``, ``level_grey``, ``depth``,
``auto_rectification``, ``sys_hz``, ``i2c_hz``, ``i2c_retry_delay_us``, ``pclk_hz``, ``memory``: where the frames
are, ``"bram"``, the design's block-RAM buffers, or ``"ddr2"``, the system's DDR2 build, simulated with the MIG model,
``sim/testbench/system/testbench.py``; ``maps``: where the depth maps are, ``"ring"`` or, with ``"ddr2"``,
``"store"``), so a setup is made,
replaced and written as JSON field by field; the design's MT9D112 table is :attr:`SystemSetup.cam_table`. The
simulation's own: the switch settings (``disparity``, ``rectification``, ``segment``), the table's speed-ups
(``time_scale``, ``quick_table``: ``sim/testbench/system/tables.py``), the cameras' phase and PCLK error
(``cam_phase_s``, ``cam_clock_ppm``), the I2C models' faults (``i2c_faults``), the simulated clock lock
(``lock_cycles``), when the pixel clock starts (``pix_after_init``) and the sensor models' timing
(``sensor_timing``).

Four presets:

* :meth:`SystemSetup.small`: ``DesignConfig.small()`` (64 x 48 sensors -> 16 x 12 buffers, a 112 x 52 display,
  D = 8, a 1 MHz I2C bus: a simulation speed-up the register-file models do not notice; the 100 kHz bus is
  exercised by the I2C block's own tests and by the full preset), its MT9D112 table with only the essential
  entries and its waits scaled by 1/50 (``sim/testbench/system/tables.py``). For the default test run.
* :meth:`SystemSetup.full`: ``DesignConfig.full()``, the board's design (1600 x 1200 -> 400 x 300, 1080p60, the
  board's MT9D112 table unchanged, the 100 kHz bus). For the slow test, the benchmark and the demo.
* :meth:`SystemSetup.full_800`: ``DesignConfig.full_800()``, the 800 x 600 build (the same sensors and table,
  8-bit 2 x 2 means, D = 128, the frames and the maps in the DDR2 with the MIG model, the maps 1:1 on the screen).
* :meth:`SystemSetup.small_800`: ``DesignConfig.small_800()``, the 800 x 600 build's structure at the small size
  (the small preset's sensors, table and speed-ups; 8-bit 2 x 2 means into 32 x 24 buffers, D = 16, the frames and
  the maps in the DDR2, half-size camera panels beside 1:1 maps). For the 800 x 600 build's tests on every backend.

The two small presets are the small size (:attr:`SystemSetup.small_size`): Amaranth's simulator runs them with the
sensor models in Python, and multi-frame runs on Amaranth's simulator and cocotb take them only.

The sensors' PCLK is the design's ``pclk_hz`` (``spec.board.CLOCKS.CAM_PCLK_HZ``: what the MT9D112 table
programs). Camera A is the left image, camera B the right image.

Simulation shortcuts, stated:

* a sensor model starts toggling PCLK only once its I2C register file says it is configured for RGB565 and
  streaming (the real sensor's PCLK runs from MCLK earlier, but the capture ignores everything before the first
  FV rising edge, so the frames are the same; this saves simulating idle PCLK while the I2C init runs);
* with ``pix_after_init`` (both presets by default) the pixel clock starts only once all three I2C buses report
  their init done, like a pixel PLL that locks late; the display domain is held in reset until then, and the
  switches are set after it starts. The display of those first milliseconds (25 ms at full size) would only
  show the still-empty buffers, and the display domain is where the simulators spend most of their time.
  ``pix_after_init=False`` runs it from time 0 (tests/test_system.py does once, in cocotb).

:meth:`SystemSetup.to_spec` / :meth:`SystemSetup.from_spec` turn a setup into JSON and back (the cocotb scenario gets
its setup that way).
"""

from dataclasses import dataclass, field, fields

import numpy as np

from golden.capture import capture_frame
from golden.disparity import composite_frame
from golden.stereo_pair import fit_to_sensor
from hdl.config import DesignConfig
from hdl.init_tables import Poll, Wait
from hdl.rectification_select import AUTO_CODE, MANUAL_RANGE, SEGMENT_CODE
from sim.models.ch7301c.target import CH7301CModel
from sim.models.mt9d112.target import MT9D112Model
from sim.models.mt9d112.sensor import MT9D112, SENSOR_TIMING, SMALL_SENSOR_TIMING
from sim.testbench.system.tables import model_timing, mt9d112_table
from spec.memory import MIG

__all__ = ["SystemSetup"]

_FULL = DesignConfig.full()
_FULL_800 = DesignConfig.full_800()
_SMALL_800 = DesignConfig.small_800()
#: The setup's fields that are the design's (``hdl.config.DesignConfig``'s of the same names).
DESIGN_FIELDS = ("geometry", "timing", "layout", "thresholds", "level_grey", "depth", "auto_rectification", "sys_hz",
                 "i2c_hz", "i2c_retry_delay_us", "pclk_hz", "memory", "maps")
#: The presets, by the name :meth:`SystemSetup.to_spec` gives them.
PRESETS = ("small", "full", "full_800", "small_800")
#: The simulation's speed-ups of the small preset (sim/testbench/system/tables.py).
_SMALL_SPEED_UPS = {"time_scale": 0.02, "quick_table": True}


def _design_fields(design):
    """A design's fields as setup fields; the layout left ``None`` (centred for the setup's own sizes)."""
    return {name: getattr(design, name) for name in DESIGN_FIELDS if name != "layout"}


@dataclass(frozen=True)
class SystemSetup:
    """A whole-system simulation: a design and the simulation's own settings (see the module docstring).

    Raises
    ------
    ValueError
        Switch settings the seven switches cannot give (``disparity``, ``rectification``, ``segment``).
    """
    geometry: object = _FULL.geometry
    timing: object = _FULL.timing
    layout: object = None              # None: DisplayLayout.centred for the setup's sizes
    thresholds: tuple = _FULL.thresholds
    level_grey: tuple = _FULL.level_grey
    depth: object = _FULL.depth                            # the depth engine's DepthConfig
    auto_rectification: object = _FULL.auto_rectification  # the vertical-offset estimator's RectificationConfig
    disparity: int = 0
    rectification: int = 0
    segment: bool = False              # the segmentation view (switches 1000001: needs rectification "auto")
    time_scale: float = 1.0            # applied to the MT9D112 table's waits and the model's boot/PLL times
    quick_table: bool = False          # only the MT9D112 table's essential entries (sim/testbench/system/tables.py)
    i2c_hz: int = _FULL.i2c_hz
    i2c_retry_delay_us: int = _FULL.i2c_retry_delay_us
    sys_hz: int = _FULL.sys_hz
    pclk_hz: int = _FULL.pclk_hz
    cam_phase_s: dict = field(default_factory=lambda: {"a": 0.0, "b": 3.1e-9})   # the cameras are not in phase
    cam_clock_ppm: dict = field(default_factory=dict)   # per camera: its PCLK off pclk_hz by this many ppm
    i2c_faults: dict = field(default_factory=dict)      # per bus: fault options of its model (sim.models.i2c.target)
    lock_cycles: int = 16
    pix_after_init: bool = False       # start the pixel clock only once the I2C init is done (see below)
    sensor_timing: object = None       # sim.models.mt9d112.sensor.SensorTiming; None: SENSOR_TIMING / SMALL_SENSOR_TIMING
    memory: str = _FULL.memory         # the frames in block RAM or, "ddr2", in the frame store with the MIG model
    maps: str = _FULL.maps             # the depth maps in the engine's ring or, "store", whole in the frame store

    @classmethod
    def small(cls, **kw):
        """``DesignConfig.small()`` with the small preset's speed-ups; ``kw`` overrides any field."""
        return cls(**{**_design_fields(DesignConfig.small()), **_SMALL_SPEED_UPS,
                      "sensor_timing": SMALL_SENSOR_TIMING, "pix_after_init": True, **kw})

    @classmethod
    def full(cls, **kw):
        """``DesignConfig.full()``, the board's design, simulated as it is; ``kw`` overrides any field."""
        return cls(**{**_design_fields(_FULL), "sensor_timing": SENSOR_TIMING, "pix_after_init": True, **kw})

    @classmethod
    def full_800(cls, **kw):
        """``DesignConfig.full_800()``, the 800 x 600 build, simulated as it is; ``kw`` overrides any field."""
        return cls(**{**_design_fields(_FULL_800), "layout": _FULL_800.layout, "sensor_timing": SENSOR_TIMING,
                      "pix_after_init": True, **kw})

    @classmethod
    def small_800(cls, **kw):
        """``DesignConfig.small_800()`` with the small preset's speed-ups; ``kw`` overrides any field."""
        return cls(**{**_design_fields(_SMALL_800), "layout": _SMALL_800.layout, **_SMALL_SPEED_UPS,
                      "sensor_timing": SMALL_SENSOR_TIMING, "pix_after_init": True, **kw})

    def to_spec(self):
        """This setup as JSON: ``{"preset": one of PRESETS, **fields that differ from the preset}``. Raises
        ``ValueError`` if a differing field has no JSON form (a layout, sensor timing or table of its own)."""
        base = type(self).from_spec({"preset": self.preset})
        spec = {"preset": self.preset}
        for f in fields(self):
            value = getattr(self, f.name)
            if value != getattr(base, f.name):
                if not isinstance(value, (int, float, bool, str, dict)):
                    raise ValueError(f"setup field {f.name} = {value!r} differs from the {self.preset} preset "
                                     "and has no JSON form")
                spec[f.name] = value
        return spec

    @classmethod
    def from_spec(cls, spec):
        """The setup a :meth:`to_spec` dictionary describes."""
        spec = dict(spec)
        preset = spec.pop("preset", "small")
        if preset not in PRESETS:
            raise ValueError(f"preset must be one of {', '.join(map(repr, PRESETS))}, not {preset!r}")
        return getattr(cls, preset)(**spec)

    @property
    def preset(self):
        """Which preset (:data:`PRESETS`) this setup's sizes are: by the sensor geometry, ``"small"`` for any
        geometry no other preset has."""
        return {_FULL.geometry: "full", _FULL_800.geometry: "full_800",
                _SMALL_800.geometry: "small_800"}.get(self.geometry, "small")

    @property
    def small_size(self):
        """True for the small presets' sizes (``"small"``, ``"small_800"``)."""
        return self.preset in ("small", "small_800")

    def __post_init__(self):
        if not 0 <= self.disparity <= 127:
            raise ValueError(f"disparity must be 0..127 (seven switches), got {self.disparity}")
        if self.rectification != "auto" and not (isinstance(self.rectification, int)
                                                 and self.rectification in MANUAL_RANGE):
            raise ValueError(f"rectification must be {MANUAL_RANGE.start}..{MANUAL_RANGE.stop - 1} (seven switches, "
                             f"two's complement) or 'auto', got {self.rectification!r}")
        if self.segment and self.rectification != "auto":
            raise ValueError("the segmentation view comes with the automatic rectification (switches 1000001): "
                             f"rectification must be 'auto', not {self.rectification!r}")

    @property
    def design(self):
        """The design this setup simulates (``hdl.config.DesignConfig``): its design fields, and its MT9D112 table
        with the setup's speed-ups (:attr:`cam_table`)."""
        return DesignConfig(**{name: getattr(self, name) for name in DESIGN_FIELDS}, cam_table=self.cam_table)

    @property
    def map_frames(self):
        """With the maps in the frame store (``maps == "store"``): the display frames a map takes
        (``hdl.stereo_display.check_map_rate``); 0 with the maps in the engine's ring."""
        if self.maps != "store":
            return 0
        from hdl.stereo_display import check_map_rate
        return check_map_rate(self.timing, self.geometry, self.depth)

    @property
    def display_layout(self):
        """The design's display layout (``layout``, or the centred one for the setup's sizes)."""
        return self.design.layout

    @property
    def cam_table(self):
        """The MT9D112 table the design holds: the board's at the setup's sensor size, with ``time_scale`` and
        ``quick_table`` applied (sim/testbench/system/tables.py)."""
        return mt9d112_table(self.geometry, time_scale=self.time_scale, quick=self.quick_table)

    def system_kwargs(self):
        """Keyword arguments for ``sim.testbench.system.testbench.SystemTestbench`` (and from there
        ``hdl.system.StereoDepthSystem``): the design's (``DesignConfig.top_kwargs``) and the simulated clocks'
        lock time."""
        return {**self.board_kwargs(), "lock_cycles": self.lock_cycles}

    def board_kwargs(self):
        """Keyword arguments for ``board.top.GenesysTop`` with this setup's design (the board has no lock counter)."""
        return self.design.top_kwargs()

    def i2c_models(self):
        """Fresh register-file models: ``{bus: [target, ...]}`` for the buses ``cam_a``, ``cam_b``, ``dvi``."""
        timing = model_timing(self.time_scale)
        faults = self.i2c_faults
        return {"cam_a": [MT9D112Model(**timing, **faults.get("cam_a", {}))],
                "cam_b": [MT9D112Model(**timing, **faults.get("cam_b", {}))],
                "dvi": [CH7301CModel(**faults.get("dvi", {}))]}

    def sensor(self, model, seed):
        """The video model of one camera, configured through its I2C register-file ``model``."""
        return MT9D112(model, timing=self.sensor_timing or SENSOR_TIMING, pclk_hz=self.pclk_hz, seed=seed)

    def camera_pclk_hz(self, camera):
        """Camera ``camera``'s (``"a"``/``"b"``) PCLK: ``pclk_hz`` off by its ``cam_clock_ppm`` (a sensor on an
        oscillator of its own; with the board's common MCLK both are exactly ``pclk_hz``)."""
        return self.pclk_hz * (1 + self.cam_clock_ppm.get(camera, 0.0) * 1e-6)

    def switch_words(self):
        """The SW7..SW0 values to set in turn: disparity (SW7 = 1), then rectification (SW7 = 0, SW6..SW0 its
        two's complement, hdl/switches.py; ``"auto"``: 1000000, with ``segment`` 1000001,
        hdl/rectification_select.py)."""
        rectification = AUTO_CODE if self.rectification == "auto" else self.rectification
        if self.segment:
            rectification = SEGMENT_CODE
        return [0x80 | self.disparity, rectification & 0x7F]

    def fit(self, image):
        """An RGB image fitted to the sensor (what the sensor model will output)."""
        image = np.asarray(image, dtype=np.uint8)
        if image.shape[:2] != (self.geometry.height, self.geometry.width):
            image = fit_to_sensor(image, self.geometry.width, self.geometry.height)
        return image

    def golden_frame(self, left, right, *, details=False, in_use=None, held=False, row_tags=None):
        """The golden model's displayed frame for the pair (images at any size: fitted to the sensor first).
        ``details=True``: ``(frame, depth codes, readout text)`` (``golden.disparity.composite_frame``). In
        automatic mode the rectification is the one the design reports in use (``in_use``) and the screen's
        rectification text says ``held`` when the design reports its estimate held. ``row_tags``: the buffer rows'
        frame tags (``golden.disparity.composite_frame``), for a map computed across a tear."""
        g = self.geometry
        lb = capture_frame(self.fit(left), g)
        rb = capture_frame(self.fit(right), g)
        rectification = self.rectification
        if rectification == "auto":
            if in_use is None:
                raise ValueError("the golden frame of an automatic-rectification run needs the offset in use")
            rectification = in_use
        auto = self.rectification == "auto"
        return composite_frame(lb, rb, self.disparity, rectification, self.timing, g, self.display_layout,
                               self.thresholds, self.level_grey, self.depth, details=details, segment=self.segment,
                               rectification_mode=(auto, auto and bool(held)), row_tags=row_tags)

    def deadline_s(self):
        """Simulated-time budget of a run: the I2C init (table waits + bus time, generously) plus a few frames."""
        table = self.cam_table
        waits = sum(e.us for e in table.entries if isinstance(e, Wait)) * 1e-6
        polls = sum(e.interval_us * 4 for e in table.entries if isinstance(e, Poll)) * 1e-6
        bus = len(table.entries) * 12 * 9 / self.i2c_hz
        cam_frame = (self.geometry.height + 20) * (2 * self.geometry.width + 400) / self.pclk_hz
        display_frame = self.timing.clocks_per_frame / self.timing.pixel_hz
        return 2 * (waits + polls + bus) + 4 * cam_frame + 4 * display_frame + 1e-3

    def expected_sim_time_s(self):
        """A rough estimate of a run's simulated time (for progress bars only): the I2C init (table waits and bus
        time), one sensor frame period, one and a half display frames; with the maps in the store two maps' display
        frames more (the map of the buffers before the capture, then the pair's)."""
        table = self.cam_table
        init = sum(e.us for e in table.entries if isinstance(e, Wait)) * 1e-6
        init += sum(e.interval_us for e in table.entries if isinstance(e, Poll)) * 3e-6
        init += len(table.entries) * 50 / self.i2c_hz
        g, t = self.geometry, self.timing
        sensor = (g.height + 10) * (2 * g.width + 256) / self.pclk_hz
        return init + sensor + (1.5 + 2 * self.map_frames) * t.clocks_per_frame / t.pixel_hz

    def clock_edges(self, t_end_s, t_pix_start_s, t_cam_start_s):
        """Rising edges of each clock domain in a run that ends at ``t_end_s`` (the pixel clock from
        ``t_pix_start_s``, the PCLKs from ``t_cam_start_s``; the DDR2 build's ``mem`` from time 0):
        ``{domain: edges}``."""
        return {"sync": t_end_s * self.sys_hz,
                "pix": max(0.0, t_end_s - t_pix_start_s) * self.timing.pixel_hz,
                "cam_a": max(0.0, t_end_s - t_cam_start_s) * self.pclk_hz,
                "cam_b": max(0.0, t_end_s - t_cam_start_s) * self.pclk_hz,
                **({"mem": t_end_s * MIG.CLK0_HZ} if self.memory == "ddr2" else {})}

    def frame_period_samples(self):
        """PCLK samples of one sensor frame period (vertical blanking + frame): the replay ROMs' depth."""
        t, g = self.sensor_timing or SENSOR_TIMING, self.geometry
        line = t.line_time(g.width)
        return t.v_blank_lines * line + t.frame_start + g.height * line - t.h_blank + t.frame_end
