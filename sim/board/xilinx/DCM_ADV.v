// Behavioural simulation model of the Virtex-5 DCM_ADV (digital clock manager), for the board-top simulation.
//
// Written from UG190 chapter 2 ("Clock Management Technology"): attribute names and ranges are UG190's.
// * Frequency synthesis: CLKFX = CLKIN x CLKFX_MULTIPLY / CLKFX_DIVIDE (M 2..32, D 1..32), 50 % duty cycle;
//   CLKFX180 is CLKFX shifted by half its period. CLKFX is started on a rising edge of CLKIN, so its edges meet
//   CLKIN's every CLKFX_DIVIDE input periods (= every CLKFX_MULTIPLY output periods), as UG190 describes for a
//   DCM with feedback ("CLKFX is phase aligned with CLK0 every D cycles of CLK0 and every M cycles of CLKFX").
// * DLL outputs (CLK0, CLK90, CLK180, CLK270, CLK2X, CLK2X180, CLKDV = CLKIN / CLKDV_DIVIDE): only with
//   CLK_FEEDBACK = "1X" or "2X" (the DLL needs its feedback); they are then aligned to CLKIN (zero
//   insertion delay in simulation) and LOCKED waits for CLKFB to follow CLK0 (1X) or CLK2X (2X). With
//   CLK_FEEDBACK = "NONE" they stay low: only the frequency synthesizer runs (the board's configuration).
// * CLKOUT_PHASE_SHIFT = "FIXED" shifts every output by PHASE_SHIFT / 256 of the input period; "NONE" no shift.
// * RST = 1 (asynchronous): every output low, LOCKED low. After RST falls the model measures CLKIN over
//   MEASURE_EDGES rising edges, checks it against CLKIN_PERIOD (more than 1 % apart is an error), waits the lock
//   time and starts the outputs at a rising edge of CLKIN, raising LOCKED with them (with feedback: once CLKFB
//   has followed twice). The lock sequence and the output generator are shared with PLL_ADV
//   (sim/board/xilinx/xil_clocking.v).
// * Not modelled ($fatal if used): variable phase shift (PSEN), the dynamic reconfiguration port (DEN),
//   CLKIN_DIVIDE_BY_2, jitter, STATUS bits (0), loss of lock on a changing input.
// The lock time is a model parameter (SIM_LOCK_TIME_NS, default `XIL_DCM_LOCK_TIME_NS` or 10 us); DS202's
// LOCK_FX figure could not be read here, so it is not the data sheet's number. Time unit 1 ns, precision 1 ps.
`ifndef XIL_DCM_LOCK_TIME_NS
`define XIL_DCM_LOCK_TIME_NS 10000.0
`endif
module DCM_ADV #(
  parameter real CLKDV_DIVIDE = 2.0,
  parameter integer CLKFX_DIVIDE = 1,
  parameter integer CLKFX_MULTIPLY = 4,
  parameter CLKIN_DIVIDE_BY_2 = "FALSE",
  parameter real CLKIN_PERIOD = 10.0,
  parameter CLKOUT_PHASE_SHIFT = "NONE",
  parameter CLK_FEEDBACK = "1X",
  parameter DCM_AUTOCALIBRATION = "TRUE",
  parameter DCM_PERFORMANCE_MODE = "MAX_SPEED",
  parameter DESKEW_ADJUST = "SYSTEM_SYNCHRONOUS",
  parameter DFS_FREQUENCY_MODE = "LOW",
  parameter DLL_FREQUENCY_MODE = "LOW",
  parameter DUTY_CYCLE_CORRECTION = "TRUE",
  parameter [15:0] FACTORY_JF = 16'hF0F0,
  parameter integer PHASE_SHIFT = 0,
  parameter SIM_DEVICE = "VIRTEX5",
  parameter STARTUP_WAIT = "FALSE",
  parameter real SIM_LOCK_TIME_NS = `XIL_DCM_LOCK_TIME_NS,
  parameter integer MEASURE_EDGES = 16
) (
  output CLK0,
  output CLK180,
  output CLK270,
  output CLK2X,
  output CLK2X180,
  output CLK90,
  output CLKDV,
  output CLKFX,
  output CLKFX180,
  output [15:0] DO,
  output DRDY,
  output LOCKED,
  output PSDONE,
  input CLKFB,
  input CLKIN,
  input [6:0] DADDR,
  input DCLK,
  input DEN,
  input [15:0] DI,
  input DWE,
  input PSCLK,
  input PSEN,
  input PSINCDEC,
  input RST
);
  localparam FEEDBACK = (CLK_FEEDBACK == "1X" || CLK_FEEDBACK == "2X");

  initial begin
    if (CLKFX_MULTIPLY < 2 || CLKFX_MULTIPLY > 32)
      $fatal(1, "DCM_ADV %m: CLKFX_MULTIPLY = %0d outside 2..32", CLKFX_MULTIPLY);
    if (CLKFX_DIVIDE < 1 || CLKFX_DIVIDE > 32)
      $fatal(1, "DCM_ADV %m: CLKFX_DIVIDE = %0d outside 1..32", CLKFX_DIVIDE);
    if (CLK_FEEDBACK != "NONE" && CLK_FEEDBACK != "1X" && CLK_FEEDBACK != "2X")
      $fatal(1, "DCM_ADV %m: CLK_FEEDBACK = %s is not NONE, 1X or 2X", CLK_FEEDBACK);
    if (CLKOUT_PHASE_SHIFT != "NONE" && CLKOUT_PHASE_SHIFT != "FIXED")
      $fatal(1, "DCM_ADV %m: CLKOUT_PHASE_SHIFT = %s is not modelled (NONE or FIXED)", CLKOUT_PHASE_SHIFT);
    if (PHASE_SHIFT < -255 || PHASE_SHIFT > 255)
      $fatal(1, "DCM_ADV %m: PHASE_SHIFT = %0d outside -255..255", PHASE_SHIFT);
    if (CLKIN_DIVIDE_BY_2 != "FALSE")
      $fatal(1, "DCM_ADV %m: CLKIN_DIVIDE_BY_2 is not modelled");
  end

  always @(DEN) if (DEN === 1'b1) $fatal(1, "DCM_ADV %m: the dynamic reconfiguration port (DEN) is not modelled");
  always @(PSEN) if (PSEN === 1'b1) $fatal(1, "DCM_ADV %m: variable phase shift (PSEN) is not modelled");

  // ---- lock sequence and outputs (xil_clocking.v) ---------------------------------------------------------
  localparam real SHIFT = CLKOUT_PHASE_SHIFT == "FIXED" ? PHASE_SHIFT / 256.0 : 0.0;
  wire running;
  wire [31:0] epoch;
  wire [63:0] period_bits, t0_bits;
  wire [8:0] outs;               // CLK0, CLK90, CLK180, CLK270, CLK2X, CLK2X180, CLKDV, CLKFX, CLKFX180

  xil_clock_lock #(.MEASURE_EDGES(MEASURE_EDGES), .LOCK_TIME_NS(SIM_LOCK_TIME_NS), .EXPECTED_NS(CLKIN_PERIOD),
                   .START_FRACTION(SHIFT < 0.0 ? SHIFT + 1.0 : SHIFT), .FEEDBACK(FEEDBACK)) lock (
    .clkin(CLKIN), .rst(RST), .fb(CLKFB), .fb_out(CLK_FEEDBACK == "2X" ? outs[4] : outs[0]), .running(running),
    .locked(LOCKED), .epoch(epoch), .period_bits(period_bits), .t0_bits(t0_bits));

  wire dll_running = running & FEEDBACK;      // the DLL outputs need the feedback
  genvar g;
  generate
    for (g = 0; g < 9; g = g + 1) begin : out
      // period as a multiple of CLKIN's; first rising edge as a fraction of the output's own period
      localparam real RATIO = g < 4 ? 1.0 : g < 6 ? 0.5 : g == 6 ? CLKDV_DIVIDE : 1.0 * CLKFX_DIVIDE / CLKFX_MULTIPLY;
      localparam real PHASE = g == 1 ? 0.25 : g == 2 || g == 5 || g == 8 ? 0.5 : g == 3 ? 0.75 : 0.0;
      xil_clock_out #(.RATIO(RATIO), .PHASE(PHASE), .DUTY(0.5)) gen (
        .running(g < 7 ? dll_running : running), .epoch(epoch), .period_bits(period_bits), .t0_bits(t0_bits),
        .out(outs[g]));
    end
  endgenerate

  assign {CLKFX180, CLKFX, CLKDV, CLK2X180, CLK2X, CLK270, CLK180, CLK90, CLK0} = outs;
  assign DO = 16'd0;
  assign DRDY = 1'b0;
  assign PSDONE = 1'b0;
endmodule
