"""The board's Verilog simulated as built: the ``top.v`` of ``stereodepth verilog`` with the Virtex-5 primitive models
(``sim/board/xilinx``) and the testbench around it that the sensor models, the I2C models and the HDMI sink drive and
read through the board's pins.

* :func:`board_verilog`: the ``top.v`` text the board build writes (``board.top.board_plan``, the same path as
  ``stereodepth verilog``), for the board's sizes or a :class:`sim.testbench.system.setup.SystemSetup`'s small ones.
  ``--pins`` (a pin file) changes only the UCF: the Verilog is the same with the placeholder pins
  (tests/test_board_top.py checks it).
* :data:`TESTBENCH`: the Verilog around ``top``: the I2C buses as wired-AND lines with pull-ups (the Genesys and
  VmodCAM have them) that the Python models pull low, and the board's pins as ports named by the flat-name rule
  (``board.export.flat_name``): ``cam_a__data``, ``ch7301c__xclk_p``, ``bus__dvi__scl``, ``panel__leds``, ...,
  which the cocotb test reads through ``sim.runners.cocotb.TopPorts``. The top's pads are ``inout``, so the bus is
  resolved here as on the board (``pullup`` plus the models' pull-downs), not by ``sim.models.i2c.bus.OpenDrainBus``,
  which resolves a design's ``o``/``oe`` pins; the driver that runs the models on it is the same
  (``sim.models.i2c.bus.start_cocotb_targets``).
* :data:`BOARD_PRIMITIVES`, :data:`BOARD_VERILATOR_ARGS`: the primitive models to build beside it and the Verilator
  switches they need (:func:`board_primitives`: with the DDR2, MIG's PLL_BASE too).
* :func:`mig_core_verilog`: for a DDR2 build (``memory="ddr2"``), the implementation of the MIG core that ``top.v``
  instantiates as a black box (``board.mig.MIGCore``, the module named after the core): the MIG model
  (``sim.models.mig``) behind MIG's port names (``sim.models.mig.mig_top_verilog``), its memory window the frame
  store's buffers, its read latency the middle of its range unless the run's ``+mig_read_latency=N`` plusarg sets
  it. The DDR2 pins stay idle (the model has the memory inside): what is simulated is the core's user interface
  as the design sees it, not MIG's PHY, calibration or the DRAM's timing (docs/memory.md).

tests/test_board_top.py runs it under cocotb (its test module ``tests/cocotb/cocotb_board_top.py``) with the
sensor, I2C and HDMI-sink models on the pins and compares the frame with the golden model's.

Clocks: the 100 MHz oscillator is the only clock the testbench drives; MCLK, the pixel clock and XCLK come out
of the DCM/PLL models, PCLK from the sensor models. Time unit 1 ns, precision 1 ps (the models need them).
"""

from sim.board.xilinx import VERILATOR_ARGS

__all__ = ["board_setup", "board_top_kwargs", "board_verilog", "mig_core_verilog", "board_primitives", "TESTBENCH",
           "BOARD_PRIMITIVES", "BOARD_VERILATOR_ARGS", "MIG_MODEL_MODULE"]

TESTBENCH = """
module board_tb (
  input clk100, input btn_rst_n, input [7:0] panel__sw, output [7:0] panel__leds,
  input cam_a__pclk, input [7:0] cam_a__data, input cam_a__lv, input cam_a__fv,
  output cam_a__mclk, output cam_a__rst_n, output cam_a__pwdn,
  input cam_b__pclk, input [7:0] cam_b__data, input cam_b__lv, input cam_b__fv,
  output cam_b__mclk, output cam_b__rst_n, output cam_b__pwdn,
  output cam_vdden,
  output [11:0] ch7301c__data, output ch7301c__hsync, output ch7301c__vsync, output ch7301c__de,
  output ch7301c__xclk_p, output ch7301c__xclk_n, output ch7301c__reset_n,
  // I2C: each line is pulled up (the Genesys and the VmodCAM have the resistors); the models pull it low
  // through bus__<b>__ext_*_low; bus__<b>__scl / __sda read the line
  input bus__cam_a__ext_scl_low, input bus__cam_a__ext_sda_low, output bus__cam_a__scl, output bus__cam_a__sda,
  input bus__cam_b__ext_scl_low, input bus__cam_b__ext_sda_low, output bus__cam_b__scl, output bus__cam_b__sda,
  input bus__dvi__ext_scl_low, input bus__dvi__ext_sda_low, output bus__dvi__scl, output bus__dvi__sda
);
  wire cam_a_scl, cam_a_sda, cam_b_scl, cam_b_sda, dvi_scl, dvi_sda;
  pullup (cam_a_scl); pullup (cam_a_sda); pullup (cam_b_scl); pullup (cam_b_sda); pullup (dvi_scl); pullup (dvi_sda);
  assign cam_a_scl = bus__cam_a__ext_scl_low ? 1'b0 : 1'bz;
  assign cam_a_sda = bus__cam_a__ext_sda_low ? 1'b0 : 1'bz;
  assign cam_b_scl = bus__cam_b__ext_scl_low ? 1'b0 : 1'bz;
  assign cam_b_sda = bus__cam_b__ext_sda_low ? 1'b0 : 1'bz;
  assign dvi_scl = bus__dvi__ext_scl_low ? 1'b0 : 1'bz;
  assign dvi_sda = bus__dvi__ext_sda_low ? 1'b0 : 1'bz;
  assign bus__cam_a__scl = cam_a_scl; assign bus__cam_a__sda = cam_a_sda;
  assign bus__cam_b__scl = cam_b_scl; assign bus__cam_b__sda = cam_b_sda;
  assign bus__dvi__scl = dvi_scl; assign bus__dvi__sda = dvi_sda;

  top top_i (
    .clk100_0__io(clk100), .rst_0__io(btn_rst_n), .switches_0__io(panel__sw), .leds_0__io(panel__leds),
    .vmodcam_0__pclk__io(cam_a__pclk), .vmodcam_0__d__io(cam_a__data), .vmodcam_0__lv__io(cam_a__lv),
    .vmodcam_0__fv__io(cam_a__fv), .vmodcam_0__mclk__io(cam_a__mclk), .vmodcam_0__rst_n__io(cam_a__rst_n),
    .vmodcam_0__pwdn__io(cam_a__pwdn), .vmodcam_0__scl__io(cam_a_scl), .vmodcam_0__sda__io(cam_a_sda),
    .vmodcam_1__pclk__io(cam_b__pclk), .vmodcam_1__d__io(cam_b__data), .vmodcam_1__lv__io(cam_b__lv),
    .vmodcam_1__fv__io(cam_b__fv), .vmodcam_1__mclk__io(cam_b__mclk), .vmodcam_1__rst_n__io(cam_b__rst_n),
    .vmodcam_1__pwdn__io(cam_b__pwdn), .vmodcam_1__scl__io(cam_b_scl), .vmodcam_1__sda__io(cam_b_sda),
    .vmodcam_vdden_0__io(cam_vdden),
    .ch7301c_0__d__io(ch7301c__data), .ch7301c_0__h__io(ch7301c__hsync), .ch7301c_0__v__io(ch7301c__vsync),
    .ch7301c_0__de__io(ch7301c__de), .ch7301c_0__xclk_p__io(ch7301c__xclk_p),
    .ch7301c_0__xclk_n__io(ch7301c__xclk_n), .ch7301c_0__reset_n__io(ch7301c__reset_n),
    .ch7301c_i2c_0__scl__io(dvi_scl), .ch7301c_i2c_0__sda__io(dvi_sda)
  );
endmodule
"""

#: Verilator switches for the board: the primitive models' (timing, time base) and Amaranth's Verilog style
#: (-Wno-ASCRANGE: Yosys writes a zero-width signal, a field the small DDR2 build's frame store does not need, as
#: ``[-1:0]``; nothing reads it).
BOARD_VERILATOR_ARGS = (*VERILATOR_ARGS, "-Wno-CASEINCOMPLETE", "-Wno-ASCRANGE")
#: The Xilinx primitives the board top instantiates.
BOARD_PRIMITIVES = ("IBUF", "OBUFT", "IOBUF", "BUFG", "FDCE", "FDPE", "ODDR", "DCM_ADV", "PLL_ADV")
#: The Verilog module of the exported MIG model inside the core's stand-in (:func:`mig_core_verilog`).
MIG_MODEL_MODULE = "mig_model_core"


def board_primitives(memory="bram"):
    """The Xilinx primitives the board top of a design with ``memory`` instantiates: :data:`BOARD_PRIMITIVES`, and
    with the DDR2 MIG's PLL_BASE (``board.clocking.MIGClocking``)."""
    return BOARD_PRIMITIVES + (("PLL_BASE",) if memory == "ddr2" else ())


def board_setup(spec):
    """The :class:`~sim.testbench.system.setup.SystemSetup` of ``spec``: ``{"preset": one of its PRESETS, **fields}``
    (default ``"small"``), every field (``quick_table`` included) overriding the preset's."""
    from dataclasses import replace
    from sim.testbench.system.setup import SystemSetup
    spec = dict(spec)
    preset = spec.pop("preset", "small")
    return replace(SystemSetup.from_spec({"preset": preset}), **spec)


def board_top_kwargs(setup, *, heartbeat_log2=1, cam_heartbeat_log2=1, **overrides):
    """``GenesysTop`` keyword arguments for a :class:`~sim.testbench.system.setup.SystemSetup`'s design (its
    ``board_kwargs``: sizes, layout, tables, I2C rate; the board has the DCM/PLL, no simulated lock); the LED blink
    rates are shortened so a short simulation sees them toggle."""
    kw = setup.board_kwargs()
    kw.update(heartbeat_log2=heartbeat_log2, cam_heartbeat_log2=cam_heartbeat_log2, **overrides)
    return kw


def board_verilog(top_kwargs=None, *, pins=None):
    """The ``top.v`` the board build writes for ``board.top.GenesysTop(**top_kwargs)`` (``None``: the board's
    defaults, i.e. exactly ``make verilog``'s file). A DDR2 build's MIG core is left the black box it is in the
    board's file (append :func:`mig_core_verilog` to simulate it)."""
    from board.top import board_plan
    _, plan = board_plan(pins=pins, files=(".v",), mig_black_box=True, **(top_kwargs or {}))
    return plan.files["top.v"]


def mig_core_verilog(top_kwargs):
    """The stand-in for the MIG core of ``GenesysTop(**top_kwargs)`` (a DDR2 build): a Verilog module named after
    the core (``mig_core``, default ``board.mig.DEFAULT_CORE_NAME``) with MIG's ports and parameters, holding the
    exported MIG model (:data:`MIG_MODEL_MODULE`, its storage module appended) whose window is the system's frame
    store (``SystemParameters.store_layout``). See the module docstring."""
    from board.export import export_verilog
    from board.mig import DEFAULT_CORE_NAME
    from board.top import GenesysTop
    from sim.models.mig import STORAGE_VERILOG, MIGModel, layout_window, mig_top_verilog
    top = GenesysTop(**top_kwargs)
    top._MustUse__silence = True                        # made for its parameters only, never elaborated
    if top.memory != "ddr2":
        raise ValueError("mig_core_verilog is for a board top with the DDR2 (memory=\"ddr2\")")
    layout = top.params.store_layout
    model = MIGModel(**layout_window(layout), storage="verilog")
    return (export_verilog(model, MIG_MODEL_MODULE) + STORAGE_VERILOG
            + mig_top_verilog(module=top_kwargs.get("mig_core", DEFAULT_CORE_NAME), core=MIG_MODEL_MODULE))
