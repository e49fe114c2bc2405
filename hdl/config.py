"""The design configuration: everything a board build and a simulation of the same design share.

A :class:`DesignConfig` names one design of :class:`hdl.system.StereoDepthSystem`: its sizes (sensor geometry,
video timing, display layout), the difference map's thresholds and level greys, the depth engine's and the
vertical-offset estimator's configurations, the I2C init tables its sequencers hold in ROM, its clocks, and where
the camera frames are (``memory``: ``"bram"``, the thesis's block-RAM frame buffers, or ``"ddr2"``, the frame store
in the board's DDR2 behind Xilinx MIG, docs/memory.md).
:meth:`DesignConfig.top_kwargs` gives the keyword arguments of ``hdl.system.StereoDepthSystem`` and of
``board.top.GenesysTop`` for it. The board build (``board.top.board_plan``, ``stereodepth verilog``,
``resources``, ``timing``) reads it from here; a whole-system simulation
(``sim.testbench.system.setup.SystemSetup``) holds one beside the simulation's own settings.

Four presets:

* :meth:`DesignConfig.full`: the board's design, 1600 x 1200 sensors -> 400 x 300 buffers, 1080p60, the
  board's MT9D112 table, the 100 kHz I2C bus.
* :meth:`DesignConfig.full_800`: the 800 x 600 build on the same board: each buffer pixel the 8-bit mean of a
  2 x 2 sensor block (``SENSOR_800``), ``DEPTH_800`` (D = 128, AD-census, the diagonal as the second path, the
  left-right check, the separable 7 x 7 median), the camera frames and the depth maps in the DDR2
  (``memory="ddr2"``, ``maps="store"``), the camera images at half size beside 1:1 maps (``DisplayLayout.full_maps``),
  the difference thresholds for 8-bit grey (``spec.display.diff_thresholds``).
* :meth:`DesignConfig.small`: the small design the default test run simulates: ``SMALL_SENSOR`` (64 x 48 -> 16 x
  12 buffers) on ``SMALL_TIMING`` (112 x 52 active), ``SMALL_DEPTH`` (D = 8), ``SMALL_RECTIFICATION``, the
  board's MT9D112 table programming the 64 x 48 output size (``hdl/sensor_table.py``: the output size is a
  design fact), a 1 MHz I2C bus (the Fast-mode Plus rate, the fastest the I2C master accepts) with a 20 us retry
  delay. The simulation's speed-ups of the table (waits scaled, entries a model does not need left out) are not
  part of the design: ``sim/testbench/system/tables.py``.
* :meth:`DesignConfig.small_800`: the 800 x 600 build's structure at the small size: :meth:`small` with
  ``SMALL_SENSOR_800`` (the same 64 x 48 sensors, 8-bit 2 x 2 means -> 32 x 24 buffers), ``SMALL_DEPTH_800``
  (``DEPTH_800``'s options, paths and pixels, D = 16), the frames and the maps in the DDR2, half-size camera panels beside
  1:1 maps (``DisplayLayout.full_maps`` on ``SMALL_TIMING``; a map takes two display frames, as the full build's
  takes three) and the 8-bit difference thresholds.
"""

from dataclasses import dataclass, fields

from hdl.sensor_table import sized_mt9d112_table
from hdl.system import SystemParameters
from spec.board import CLOCKS
from spec.depth import DEPTH_800, SMALL_DEPTH, SMALL_DEPTH_800
from spec.display import diff_thresholds
from spec.layout import DisplayLayout
from spec.rectification import SMALL_RECTIFICATION
from spec.sensor import SENSOR_800, SMALL_SENSOR, SMALL_SENSOR_800
from spec.video import SMALL_TIMING

__all__ = ["DesignConfig"]

#: The system's own parameter defaults: the board's design is the design the blocks default to.
_SYSTEM = {f.name: f.default for f in fields(SystemParameters)}


@dataclass(frozen=True)
class DesignConfig:
    """One design of the system (see the module docstring).

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
        The sensors' output size and the buffers.
    timing : :class:`spec.video.VideoTiming`
        The display's video mode.
    layout : :class:`spec.layout.DisplayLayout` or None
        The display layout; ``None``: ``DisplayLayout.centred(timing, geometry, depth)``.
    thresholds, level_grey : tuple
        The difference map's level thresholds and greys (``spec.display``).
    depth : :class:`spec.depth.DepthConfig`
        The depth engine.
    auto_rectification : :class:`spec.rectification.RectificationConfig`
        The vertical-offset estimator.
    cam_table, dvi_table : :class:`hdl.init_tables.InitTable` or None
        The tables the MT9D112 and CH7301C sequencers play; ``cam_table=None``: the board's MT9D112 table at
        ``geometry``'s output size (:func:`hdl.sensor_table.sized_mt9d112_table`).
    sys_hz : int
        The ``sync`` domain's clock (the I2C masters' and sequencers' time base).
    i2c_hz : int
        The I2C bus rate of all three buses.
    i2c_retry_delay_us : int
        The sequencers' pause before retrying a NACKed transaction.
    pclk_hz : int
        The sensors' PCLK as ``cam_table`` programs it: the ``cam_a``/``cam_b`` domains' clock.
    memory : str
        Where the camera frames are: ``"bram"`` (block-RAM frame buffers) or ``"ddr2"`` (the frame store behind
        MIG's user interface, the system's ``mig`` port; a board build then needs the user's MIG core,
        ``stereodepth verilog --mig DIR``).
    maps : str
        Where the depth maps are: ``"ring"`` (the engine's ring of result rows, a map a display frame) or, with
        ``"ddr2"`` only, ``"store"`` (whole maps in the frame store, the latest whole one shown: docs/frame_store.md,
        "Depth maps in the store").

    Attributes
    ----------
    layout, cam_table
        Never ``None``: resolved as above when the configuration is made.
    """
    geometry: object = _SYSTEM["geometry"]
    timing: object = _SYSTEM["timing"]
    layout: object = None
    thresholds: tuple = _SYSTEM["thresholds"]
    level_grey: tuple = _SYSTEM["level_grey"]
    depth: object = _SYSTEM["depth"]
    auto_rectification: object = _SYSTEM["auto_rectification"]
    cam_table: object = None
    dvi_table: object = _SYSTEM["dvi_table"]
    sys_hz: int = _SYSTEM["clk_hz"]
    i2c_hz: int = _SYSTEM["i2c_hz"]
    i2c_retry_delay_us: int = _SYSTEM["i2c_retry_delay_us"]
    pclk_hz: int = CLOCKS.CAM_PCLK_HZ
    memory: str = _SYSTEM["memory"]
    maps: str = _SYSTEM["maps"]

    def __post_init__(self):
        # frozen: the resolved defaults are set the way dataclasses' own __init__ sets fields
        if self.layout is None:
            object.__setattr__(self, "layout", DisplayLayout.centred(self.timing, self.geometry, self.depth))
        if self.cam_table is None:
            object.__setattr__(self, "cam_table", sized_mt9d112_table(self.geometry))

    @classmethod
    def full(cls, **kw):
        """The board's design; ``kw`` overrides fields."""
        return cls(**kw)

    @classmethod
    def full_800(cls, **kw):
        """The 800 x 600 build (see the module docstring); ``kw`` overrides fields."""
        timing = kw.get("timing", _SYSTEM["timing"])
        return cls(**{"geometry": SENSOR_800, "depth": DEPTH_800,
                      "layout": DisplayLayout.full_maps(timing, SENSOR_800, DEPTH_800),
                      "thresholds": diff_thresholds(SENSOR_800.grey_bits), "memory": "ddr2", "maps": "store", **kw})

    @classmethod
    def small(cls, **kw):
        """The small design of the default test run (see the module docstring); ``kw`` overrides fields."""
        return cls(**{"geometry": SMALL_SENSOR, "timing": SMALL_TIMING, "depth": SMALL_DEPTH,
                      "auto_rectification": SMALL_RECTIFICATION, "i2c_hz": 1_000_000, "i2c_retry_delay_us": 20,
                      **kw})

    @classmethod
    def small_800(cls, **kw):
        """The 800 x 600 build at the small size (see the module docstring); ``kw`` overrides fields."""
        timing = kw.get("timing", SMALL_TIMING)
        return cls.small(**{"geometry": SMALL_SENSOR_800, "depth": SMALL_DEPTH_800,
                            "layout": DisplayLayout.full_maps(timing, SMALL_SENSOR_800, SMALL_DEPTH_800),
                            "thresholds": diff_thresholds(SMALL_SENSOR_800.grey_bits), "memory": "ddr2",
                            "maps": "store", **kw})

    def top_kwargs(self):
        """Keyword arguments of ``hdl.system.StereoDepthSystem`` and ``board.top.GenesysTop`` for this design."""
        return dict(geometry=self.geometry, timing=self.timing, layout=self.layout, thresholds=self.thresholds,
                    level_grey=self.level_grey, depth=self.depth, auto_rectification=self.auto_rectification,
                    cam_table=self.cam_table, dvi_table=self.dvi_table, clk_hz=self.sys_hz, i2c_hz=self.i2c_hz,
                    i2c_retry_delay_us=self.i2c_retry_delay_us, memory=self.memory, maps=self.maps)
