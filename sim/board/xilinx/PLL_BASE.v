// Behavioural simulation model of the Virtex-5 PLL_BASE, for the board-top simulation.
//
// UG190 chapter 3 ("Phase-Locked Loops (PLLs)") describes PLL_BASE as the PLL's basic primitive: the same PLL as
// PLL_ADV with one clock input (CLKIN, period CLKIN_PERIOD in ns), the feedback pair CLKFBOUT/CLKFBIN, RST,
// the six outputs CLKOUT0..5 with their DIVIDE / PHASE / DUTY_CYCLE attributes and LOCKED; no second input, no
// dynamic reconfiguration port, no DCM-facing outputs. So this model is the PLL_ADV model
// (sim/board/xilinx/PLL_ADV.v: frequencies, phases, duty cycles, lock, reset) with CLKIN1 = CLKIN, CLKINSEL = 1
// and the ports PLL_BASE lacks tied off. What PLL_ADV's model does not model, this one does not either.
// Time unit: 1 ns, precision 1 ps (sim/board/xilinx/__init__.py).
`ifndef XIL_PLL_LOCK_TIME_NS
`define XIL_PLL_LOCK_TIME_NS 10000.0
`endif
module PLL_BASE #(
  parameter BANDWIDTH = "OPTIMIZED",
  parameter integer CLKFBOUT_MULT = 1,
  parameter real CLKFBOUT_PHASE = 0.0,
  parameter real CLKIN_PERIOD = 0.0,
  parameter integer CLKOUT0_DIVIDE = 1,
  parameter real CLKOUT0_DUTY_CYCLE = 0.5,
  parameter real CLKOUT0_PHASE = 0.0,
  parameter integer CLKOUT1_DIVIDE = 1,
  parameter real CLKOUT1_DUTY_CYCLE = 0.5,
  parameter real CLKOUT1_PHASE = 0.0,
  parameter integer CLKOUT2_DIVIDE = 1,
  parameter real CLKOUT2_DUTY_CYCLE = 0.5,
  parameter real CLKOUT2_PHASE = 0.0,
  parameter integer CLKOUT3_DIVIDE = 1,
  parameter real CLKOUT3_DUTY_CYCLE = 0.5,
  parameter real CLKOUT3_PHASE = 0.0,
  parameter integer CLKOUT4_DIVIDE = 1,
  parameter real CLKOUT4_DUTY_CYCLE = 0.5,
  parameter real CLKOUT4_PHASE = 0.0,
  parameter integer CLKOUT5_DIVIDE = 1,
  parameter real CLKOUT5_DUTY_CYCLE = 0.5,
  parameter real CLKOUT5_PHASE = 0.0,
  parameter COMPENSATION = "SYSTEM_SYNCHRONOUS",
  parameter integer DIVCLK_DIVIDE = 1,
  parameter real REF_JITTER = 0.100,
  parameter RESET_ON_LOSS_OF_LOCK = "FALSE",
  parameter real SIM_LOCK_TIME_NS = `XIL_PLL_LOCK_TIME_NS
) (
  output CLKFBOUT,
  output CLKOUT0,
  output CLKOUT1,
  output CLKOUT2,
  output CLKOUT3,
  output CLKOUT4,
  output CLKOUT5,
  output LOCKED,
  input CLKFBIN,
  input CLKIN,
  input RST
);
  PLL_ADV #(
    .BANDWIDTH(BANDWIDTH), .CLKFBOUT_MULT(CLKFBOUT_MULT), .CLKFBOUT_PHASE(CLKFBOUT_PHASE),
    .CLKIN1_PERIOD(CLKIN_PERIOD), .DIVCLK_DIVIDE(DIVCLK_DIVIDE), .COMPENSATION(COMPENSATION),
    .REF_JITTER(REF_JITTER), .RESET_ON_LOSS_OF_LOCK(RESET_ON_LOSS_OF_LOCK), .SIM_LOCK_TIME_NS(SIM_LOCK_TIME_NS),
    .CLKOUT0_DIVIDE(CLKOUT0_DIVIDE), .CLKOUT0_DUTY_CYCLE(CLKOUT0_DUTY_CYCLE), .CLKOUT0_PHASE(CLKOUT0_PHASE),
    .CLKOUT1_DIVIDE(CLKOUT1_DIVIDE), .CLKOUT1_DUTY_CYCLE(CLKOUT1_DUTY_CYCLE), .CLKOUT1_PHASE(CLKOUT1_PHASE),
    .CLKOUT2_DIVIDE(CLKOUT2_DIVIDE), .CLKOUT2_DUTY_CYCLE(CLKOUT2_DUTY_CYCLE), .CLKOUT2_PHASE(CLKOUT2_PHASE),
    .CLKOUT3_DIVIDE(CLKOUT3_DIVIDE), .CLKOUT3_DUTY_CYCLE(CLKOUT3_DUTY_CYCLE), .CLKOUT3_PHASE(CLKOUT3_PHASE),
    .CLKOUT4_DIVIDE(CLKOUT4_DIVIDE), .CLKOUT4_DUTY_CYCLE(CLKOUT4_DUTY_CYCLE), .CLKOUT4_PHASE(CLKOUT4_PHASE),
    .CLKOUT5_DIVIDE(CLKOUT5_DIVIDE), .CLKOUT5_DUTY_CYCLE(CLKOUT5_DUTY_CYCLE), .CLKOUT5_PHASE(CLKOUT5_PHASE)
  ) pll (
    .CLKIN1(CLKIN), .CLKIN2(1'b0), .CLKINSEL(1'b1), .CLKFBIN(CLKFBIN), .CLKFBOUT(CLKFBOUT), .RST(RST),
    .REL(1'b0), .DCLK(1'b0), .DEN(1'b0), .DWE(1'b0), .DADDR(5'd0), .DI(16'd0),
    .CLKOUT0(CLKOUT0), .CLKOUT1(CLKOUT1), .CLKOUT2(CLKOUT2), .CLKOUT3(CLKOUT3), .CLKOUT4(CLKOUT4),
    .CLKOUT5(CLKOUT5), .LOCKED(LOCKED),
    .CLKFBDCM(), .CLKOUTDCM0(), .CLKOUTDCM1(), .CLKOUTDCM2(), .CLKOUTDCM3(), .CLKOUTDCM4(), .CLKOUTDCM5(),
    .DO(), .DRDY());
endmodule
