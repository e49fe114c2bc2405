"""The MIG model behind the port names of MIG's generated top module, so a board top that instantiates the user's
core (``MEMCtrl`` in freecores/genesys_ddr2) simulates with the model in its place."""

from spec.memory import MIG

from .model import READ_LATENCY_RANGE
from .violations import MESSAGE_FORMAT, MESSAGES, Violation

__all__ = ["mig_top_verilog", "LATENCY_PLUSARG"]

#: The plusarg that sets the read latency of a run without a rebuild (``+mig_read_latency=20``).
LATENCY_PLUSARG = "mig_read_latency"

#: MIG 3.6.1's generated top-level parameters for the Genesys (ddr2-facts.md), so an instantiation that sets them
#: compiles; the model does not read them.
_PARAMETERS = dict(BANK_WIDTH=2, CKE_WIDTH=1, CLK_WIDTH=2, COL_WIDTH=10, CS_NUM=1, CS_WIDTH=1, CS_BITS=0,
                   DM_WIDTH=8, DQ_WIDTH=64, DQ_PER_DQS=8, DQS_WIDTH=8, DQ_BITS=6, DQS_BITS=3, ODT_WIDTH=1,
                   ROW_WIDTH=13, ADDITIVE_LAT=0, BURST_LEN=4, BURST_TYPE=0, CAS_LAT=3, ECC_ENABLE=0,
                   APPDATA_WIDTH=128, MULTI_BANK_EN=1, TWO_T_TIME_EN=1, ODT_TYPE=1, REDUCE_DRV=0, REG_ENABLE=0,
                   TREFI_NS=7800, TRAS=40000, TRCD=15000, TRFC=105000, TRP=15000, TRTP=7500, TWR=15000,
                   TWTR=7500, HIGH_PERFORMANCE_MODE='"TRUE"', SIM_ONLY=0, DEBUG_EN=0, CLK_PERIOD=8000,
                   DQS_IO_COL="16'b0000000000000000", DQ_IO_MS="64'b0", USE_DM_PORT=1, RST_ACT_LOW=1)


#: The generated top module's ports (ddr2-facts.md, from MEMCtrl.v of freecores/genesys_ddr2).
_PORTS = f"""\
  inout  [63:0] ddr2_dq,
  inout  [7:0]  ddr2_dqs,
  inout  [7:0]  ddr2_dqs_n,
  output [12:0] ddr2_a,
  output [1:0]  ddr2_ba,
  output        ddr2_ras_n,
  output        ddr2_cas_n,
  output        ddr2_we_n,
  output [0:0]  ddr2_cs_n,
  output [0:0]  ddr2_odt,
  output [0:0]  ddr2_cke,
  output [7:0]  ddr2_dm,
  output [1:0]  ddr2_ck,
  output [1:0]  ddr2_ck_n,
  input         sys_rst_n,
  input         locked,
  input         clk0,
  input         clk90,
  input         clkdiv0,
  input         clk200,
  output        clk0_tb,
  output        rst0_tb,
  output        phy_init_done,
  input  [{MIG.CMD_WIDTH - 1}:0]  app_af_cmd,
  input  [{MIG.ADDR_WIDTH - 1}:0] app_af_addr,
  input         app_af_wren,
  input  [{MIG.DATA_WIDTH - 1}:0] app_wdf_data,
  input  [{MIG.MASK_WIDTH - 1}:0] app_wdf_mask_data,
  input         app_wdf_wren,
  output        app_af_afull,
  output        app_wdf_afull,
  output [{MIG.DATA_WIDTH - 1}:0] rd_data_fifo_out,
  output        rd_data_valid
"""

#: The DDR2 pins, idle: commands deselected, the data bus released.
_IDLE_PINS = """\
  assign ddr2_dq = 64'bz;
  assign ddr2_dqs = 8'bz;
  assign ddr2_dqs_n = 8'bz;
  assign ddr2_a = 13'd0;
  assign ddr2_ba = 2'd0;
  assign ddr2_ras_n = 1'b1;
  assign ddr2_cas_n = 1'b1;
  assign ddr2_we_n = 1'b1;
  assign ddr2_cs_n = 1'b1;
  assign ddr2_odt = 1'b0;
  assign ddr2_cke = 1'b0;
  assign ddr2_dm = 8'd0;
  assign ddr2_ck = 2'b00;
  assign ddr2_ck_n = 2'b11;
"""


def _display_case(indent):
    """A Verilog ``case`` on the violation code that ``$display``s the one-line message of each code."""
    lines = [f"{indent}case (violation__code)"]
    for violation, text in MESSAGES.items():
        line = MESSAGE_FORMAT.replace("{addr:08x}", "%08x").replace("{cycle}", "%0d").format(
            text=text.replace('"', "'"), name=violation.name, addr="{addr}", cycle="{cycle}")
        lines.append(f'{indent}  {violation.value}: $display("{line}", violation__addr, violation__cycle);')
    lines.append(f'{indent}  default: $display("MIG model: unknown violation code %0d", violation__code);')
    lines.append(f"{indent}endcase")
    return "\n".join(lines)


def mig_top_verilog(*, module="MEMCtrl", core, latency=None):
    """Verilog text of ``module`` with MIG's generated top module's ports and parameters, holding the exported
    model ``core`` (the Verilog module name of ``export_verilog(MIGModel(..., storage="verilog"), core)``; append
    that text and ``STORAGE_VERILOG``).

    * ``clk0`` clocks the model; ``rst0_tb`` is high while ``sys_rst_n`` (active low: RST_ACT_LOW 1) or
      ``locked`` is low and for two ``clk0`` edges after, and resets the model; ``clk0_tb`` is ``clk0``.
    * The ``app_*`` ports, ``rd_data_fifo_out``, ``rd_data_valid`` and ``phy_init_done`` are the model's.
    * The DDR2 pins are idle (commands deselected, DQ released); ``clk90``, ``clkdiv0``, ``clk200`` are unused.
    * The read latency is ``latency`` (default the middle of ``READ_LATENCY_RANGE``), or the run's
      ``+mig_read_latency=N`` plusarg: no rebuild per draw. ``core`` is built with the default
      ``latency_range``.
    * On the model's first violation the module prints the one-line message (the table of
      :mod:`sim.models.mig.violations`) and stops the simulation with ``$fatal``.
    """
    lo, hi = READ_LATENCY_RANGE
    latency = (lo + hi) // 2 if latency is None else latency
    params = ",\n".join(f"  parameter {k} = {v}" for k, v in _PARAMETERS.items())
    return f"""
// MIG 3.x's generated top module ({module}) for simulation: the MIG model (sim/models/mig/mig_top.py).
module {module} #(
{params}
) (
{_PORTS});
{_IDLE_PINS}  assign clk0_tb = clk0;

  wire reset_in = !sys_rst_n || !locked;
  reg [1:0] reset_sync = 2'b11;
  always @(posedge clk0 or posedge reset_in)
    if (reset_in) reset_sync <= 2'b11;
    else reset_sync <= {{reset_sync[0], 1'b0}};
  assign rst0_tb = reset_sync[1];

  reg [{hi.bit_length() - 1}:0] read_latency;
  integer plusarg_latency;
  initial begin
    read_latency = {latency};
    if ($value$plusargs("{LATENCY_PLUSARG}=%d", plusarg_latency)) read_latency = plusarg_latency;
  end

  wire [3:0] violation__code;
  wire [{MIG.ADDR_WIDTH - 1}:0] violation__addr;
  wire [31:0] violation__cycle;
  {core} model (
    .clk(clk0), .rst(rst0_tb), .latency(read_latency), .read_ready(1'b1), .refreshing(),
    .user__command__cmd(app_af_cmd), .user__command__addr(app_af_addr), .user__command__wren(app_af_wren),
    .user__command__afull(app_af_afull),
    .user__write__data(app_wdf_data), .user__write__mask(app_wdf_mask_data), .user__write__wren(app_wdf_wren),
    .user__write__afull(app_wdf_afull),
    .user__read__data(rd_data_fifo_out), .user__read__valid(rd_data_valid),
    .user__phy_init_done(phy_init_done),
    .violation__code(violation__code), .violation__addr(violation__addr), .violation__cycle(violation__cycle)
  );

  always @(posedge clk0)
    if (violation__code != {Violation.NONE.value}) begin
{_display_case("      ")}
      $fatal(1, "MIG model: stopped on a violation of MIG's user interface");
    end
endmodule
"""
