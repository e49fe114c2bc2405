// Behavioural simulation model of the Virtex-5 PLL_ADV (phase-locked loop), for the board-top simulation.
//
// Written from UG190 chapter 3 ("Phase-Locked Loops (PLLs)"): the attribute names and ranges are UG190's
// (CLKFBOUT_MULT 1..64, DIVCLK_DIVIDE 1..52, CLKOUT[0:5]_DIVIDE 1..128, CLKOUT[0:5]_PHASE in degrees of that
// output's own period, CLKOUT[0:5]_DUTY_CYCLE as a fraction, CLKIN1_PERIOD/CLKIN2_PERIOD in ns):
//
//   f_VCO = f_CLKIN x CLKFBOUT_MULT / DIVCLK_DIVIDE,   f_CLKOUTn = f_VCO / CLKOUTn_DIVIDE,
//   f_CLKFBOUT = f_VCO / CLKFBOUT_MULT (= the phase detector's frequency; CLKFBOUT must come back on CLKFBIN).
//
// Behaviour modelled:
// * RST = 1 (asynchronous): every output low, LOCKED low. After RST falls the model measures the period of
//   CLKIN1 (CLKINSEL = 1) over MEASURE_EDGES rising edges, checks it against CLKIN1_PERIOD (more than 1 % apart
//   is an error: UG190 asks for the real input period there), waits the lock time, and starts every output at a
//   rising edge of the input (t0): CLKOUTn rises at t0 + CLKOUTn_PHASE / 360 x T_n + k x T_n and stays high
//   CLKOUTn_DUTY_CYCLE x T_n (sim/board/xilinx/xil_clocking.v: the lock sequence and the output generator shared with
//   DCM_ADV). Edge times are computed from t0, so the outputs do not drift from the input over a long run.
//   Outputs with phase 0 are aligned to the input's rising edges every time the two periods meet (UG190: the
//   feedback path aligns CLKFBOUT, and with it the zero-phase outputs, to CLKIN).
// * LOCKED rises once the outputs run and CLKFBIN has shown two rising edges that coincide with CLKFBOUT's
//   (the feedback loop is closed); it stays low for ever if the feedback is not connected.
// * CLKOUTDCMn and CLKFBDCM are copies of CLKOUTn and CLKFBOUT (the DCM-facing outputs).
// * Not modelled ($fatal if used): CLKIN2 (CLKINSEL = 0), the dynamic reconfiguration port (DEN), REL, jitter, the BANDWIDTH and COMPENSATION settings (accepted: they change jitter and insertion delay,
//   not the frequencies or phases a logic simulation sees), loss of lock on a changing input.
//
// The lock time is a model parameter (SIM_LOCK_TIME_NS, default `XIL_PLL_LOCK_TIME_NS` or 10 us): DS202's
// maximum lock time could not be read from a stored copy here, so the default is not the data sheet's figure.
// Time unit: 1 ns, precision 1 ps (sim/board/xilinx/__init__.py).
`ifndef XIL_PLL_LOCK_TIME_NS
`define XIL_PLL_LOCK_TIME_NS 10000.0
`endif
module PLL_ADV #(
  parameter BANDWIDTH = "OPTIMIZED",
  parameter CLK_FEEDBACK = "CLKFBOUT",
  parameter CLKFBOUT_DESKEW_ADJUST = "NONE",
  parameter CLKOUT0_DESKEW_ADJUST = "NONE",
  parameter CLKOUT1_DESKEW_ADJUST = "NONE",
  parameter CLKOUT2_DESKEW_ADJUST = "NONE",
  parameter CLKOUT3_DESKEW_ADJUST = "NONE",
  parameter CLKOUT4_DESKEW_ADJUST = "NONE",
  parameter CLKOUT5_DESKEW_ADJUST = "NONE",
  parameter integer CLKFBOUT_MULT = 1,
  parameter real CLKFBOUT_PHASE = 0.0,
  parameter real CLKIN1_PERIOD = 0.0,
  parameter real CLKIN2_PERIOD = 0.0,
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
  parameter EN_REL = "FALSE",
  parameter PLL_PMCD_MODE = "FALSE",
  parameter real REF_JITTER = 0.100,
  parameter RESET_ON_LOSS_OF_LOCK = "FALSE",
  parameter RST_DEASSERT_CLK = "CLKIN1",
  parameter SIM_DEVICE = "VIRTEX5",
  parameter real SIM_LOCK_TIME_NS = `XIL_PLL_LOCK_TIME_NS,
  parameter integer MEASURE_EDGES = 16
) (
  output CLKFBDCM,
  output CLKFBOUT,
  output CLKOUT0,
  output CLKOUT1,
  output CLKOUT2,
  output CLKOUT3,
  output CLKOUT4,
  output CLKOUT5,
  output CLKOUTDCM0,
  output CLKOUTDCM1,
  output CLKOUTDCM2,
  output CLKOUTDCM3,
  output CLKOUTDCM4,
  output CLKOUTDCM5,
  output [15:0] DO,
  output DRDY,
  output LOCKED,
  input CLKFBIN,
  input CLKIN1,
  input CLKIN2,
  input CLKINSEL,
  input [4:0] DADDR,
  input DCLK,
  input DEN,
  input [15:0] DI,
  input DWE,
  input REL,
  input RST
);
  // ---- attribute checks (UG190 ranges) ------------------------------------------------------------------
  function automatic check_div(input integer value, input integer lo, input integer hi);
    check_div = (value >= lo && value <= hi);
  endfunction

  initial begin
    if (!check_div(CLKFBOUT_MULT, 1, 64)) $fatal(1, "PLL_ADV %m: CLKFBOUT_MULT = %0d outside 1..64", CLKFBOUT_MULT);
    if (!check_div(DIVCLK_DIVIDE, 1, 52)) $fatal(1, "PLL_ADV %m: DIVCLK_DIVIDE = %0d outside 1..52", DIVCLK_DIVIDE);
    if (!check_div(CLKOUT0_DIVIDE, 1, 128) || !check_div(CLKOUT1_DIVIDE, 1, 128)
        || !check_div(CLKOUT2_DIVIDE, 1, 128) || !check_div(CLKOUT3_DIVIDE, 1, 128)
        || !check_div(CLKOUT4_DIVIDE, 1, 128) || !check_div(CLKOUT5_DIVIDE, 1, 128))
      $fatal(1, "PLL_ADV %m: a CLKOUTn_DIVIDE is outside 1..128");
    if (EN_REL != "FALSE") $fatal(1, "PLL_ADV %m: EN_REL = TRUE (REL) is not modelled");
    if (PLL_PMCD_MODE != "FALSE") $fatal(1, "PLL_ADV %m: PLL_PMCD_MODE is not modelled");
  end

  // ---- lock sequence and outputs (xil_clocking.v) ---------------------------------------------------------
  always @(DEN) if (DEN === 1'b1) $fatal(1, "PLL_ADV %m: the dynamic reconfiguration port (DEN) is not modelled");
  always @(REL) if (REL === 1'b1) $fatal(1, "PLL_ADV %m: REL is not modelled");
  always @(CLKINSEL or RST) if (CLKINSEL === 1'b0 && RST === 1'b0) $fatal(1, "PLL_ADV %m: CLKIN2 is not modelled");

  wire running;
  wire [31:0] epoch;
  wire [63:0] period_bits, t0_bits;
  wire [6:0] outs;               // CLKOUT0..5, CLKFBOUT

  xil_clock_lock #(.MEASURE_EDGES(MEASURE_EDGES), .LOCK_TIME_NS(SIM_LOCK_TIME_NS), .EXPECTED_NS(CLKIN1_PERIOD),
                   .FEEDBACK(1'b1)) lock (
    .clkin(CLKIN1), .rst(RST), .fb(CLKFBIN), .fb_out(outs[6]), .running(running), .locked(LOCKED),
    .epoch(epoch), .period_bits(period_bits), .t0_bits(t0_bits));

  genvar g;
  generate
    for (g = 0; g < 7; g = g + 1) begin : out
      localparam integer DIV = g == 0 ? CLKOUT0_DIVIDE : g == 1 ? CLKOUT1_DIVIDE : g == 2 ? CLKOUT2_DIVIDE :
                               g == 3 ? CLKOUT3_DIVIDE : g == 4 ? CLKOUT4_DIVIDE : g == 5 ? CLKOUT5_DIVIDE :
                               CLKFBOUT_MULT;
      localparam real PH = g == 0 ? CLKOUT0_PHASE : g == 1 ? CLKOUT1_PHASE : g == 2 ? CLKOUT2_PHASE :
                           g == 3 ? CLKOUT3_PHASE : g == 4 ? CLKOUT4_PHASE : g == 5 ? CLKOUT5_PHASE : CLKFBOUT_PHASE;
      localparam real DUTY = g == 0 ? CLKOUT0_DUTY_CYCLE : g == 1 ? CLKOUT1_DUTY_CYCLE :
                             g == 2 ? CLKOUT2_DUTY_CYCLE : g == 3 ? CLKOUT3_DUTY_CYCLE :
                             g == 4 ? CLKOUT4_DUTY_CYCLE : g == 5 ? CLKOUT5_DUTY_CYCLE : 0.5;
      // T_n = T_in x DIVCLK_DIVIDE / CLKFBOUT_MULT x CLKOUTn_DIVIDE; phase in degrees of T_n
      xil_clock_out #(.RATIO(1.0 * DIVCLK_DIVIDE * DIV / CLKFBOUT_MULT),
                      .PHASE((PH < 0.0 ? PH + 360.0 : PH) / 360.0), .DUTY(DUTY)) gen (
        .running(running), .epoch(epoch), .period_bits(period_bits), .t0_bits(t0_bits), .out(outs[g]));
    end
  endgenerate

  assign {CLKFBOUT, CLKOUT5, CLKOUT4, CLKOUT3, CLKOUT2, CLKOUT1, CLKOUT0} = outs;
  assign {CLKFBDCM, CLKOUTDCM5, CLKOUTDCM4, CLKOUTDCM3, CLKOUTDCM2, CLKOUTDCM1, CLKOUTDCM0} = outs;
  assign DO = 16'd0;
  assign DRDY = 1'b0;
endmodule
