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
//   has followed twice).
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
  output reg LOCKED,
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

  // index: 0 CLK0, 1 CLK90, 2 CLK180, 3 CLK270, 4 CLK2X, 5 CLK2X180, 6 CLKDV, 7 CLKFX, 8 CLKFX180
  function automatic real period_of(input integer n, input real t_in);
    case (n)
      0, 1, 2, 3: period_of = t_in;
      4, 5: period_of = t_in / 2.0;
      6: period_of = t_in * CLKDV_DIVIDE;
      default: period_of = t_in * CLKFX_DIVIDE / CLKFX_MULTIPLY;
    endcase
  endfunction
  function automatic real offset_of(input integer n, input real t_in);   // delay of the first rising edge
    case (n)
      1: offset_of = t_in / 4.0;
      2: offset_of = t_in / 2.0;
      3: offset_of = 3.0 * t_in / 4.0;
      5: offset_of = t_in / 4.0;
      8: offset_of = t_in * CLKFX_DIVIDE / CLKFX_MULTIPLY / 2.0;
      default: offset_of = 0.0;
    endcase
  endfunction

  real t_first, t_edge, period_in, t0, t_ready, shift;
  integer edges;
  integer epoch = 0;
  integer fb_edges = 0;
  reg running = 1'b0;

  initial LOCKED = 1'b0;

  initial begin : control
    forever begin
      running = 1'b0;
      LOCKED = 1'b0;
      epoch = epoch + 1;
      fb_edges = 0;
      while (RST !== 1'b0) @(RST);
      edges = 0;
      while (edges <= MEASURE_EDGES && RST === 1'b0) begin
        @(posedge CLKIN or posedge RST);
        if (RST === 1'b0) begin
          if (edges == 0) t_first = $realtime;
          t_edge = $realtime;
          edges = edges + 1;
        end
      end
      if (RST === 1'b0) begin
        period_in = (t_edge - t_first) / MEASURE_EDGES;
        if (period_in > 1.01 * CLKIN_PERIOD || period_in < 0.99 * CLKIN_PERIOD)
          $fatal(1, "DCM_ADV %m: CLKIN period %f ns, CLKIN_PERIOD says %f ns", period_in, CLKIN_PERIOD);
        shift = (CLKOUT_PHASE_SHIFT == "FIXED") ? period_in * PHASE_SHIFT / 256.0 : 0.0;
        t_ready = $realtime + SIM_LOCK_TIME_NS;
        while ($realtime < t_ready && RST === 1'b0) @(posedge CLKIN or posedge RST);
      end
      if (RST === 1'b0) begin
        t0 = $realtime + (shift < 0.0 ? shift + period_in : shift);
        running = 1'b1;
        while (FEEDBACK && fb_edges < 2 && RST === 1'b0) @(fb_edges or RST);
        if (RST === 1'b0) LOCKED = 1'b1;
        while (RST === 1'b0) @(RST);
      end
    end
  end

  wire [8:0] outs;
  genvar g;
  generate
    for (g = 0; g < 9; g = g + 1) begin : out
      reg q;
      reg enabled;                      // the DLL outputs run only with feedback
      real period, first, t_rise;
      integer my_epoch, k;
      initial enabled = (g >= 7) || FEEDBACK;
      always begin
        q = 1'b0;
        wait (running === 1'b1 && enabled === 1'b1);
        my_epoch = epoch;
        period = period_of(g, period_in);
        first = t0 + offset_of(g, period_in);
        k = 0;
        while (first + k * period < $realtime) k = k + 1;
        while (running === 1'b1 && epoch == my_epoch) begin
          t_rise = first + k * period;
          if (t_rise > $realtime) #(t_rise - $realtime);
          if (running === 1'b1 && epoch == my_epoch) q = 1'b1;
          if (t_rise + period / 2.0 > $realtime) #(t_rise + period / 2.0 - $realtime);
          q = 1'b0;
          k = k + 1;
        end
      end
      assign outs[g] = q & running;
    end
  endgenerate

  // feedback: CLKFB must follow CLK0 (1X) or CLK2X (2X)
  always @(posedge CLKFB)
    if (running === 1'b1 && (CLK_FEEDBACK == "2X" ? outs[4] : outs[0]) === 1'b1) fb_edges = fb_edges + 1;

  assign {CLKFX180, CLKFX, CLKDV, CLK2X180, CLK2X, CLK270, CLK180, CLK90, CLK0} = outs;
  assign DO = 16'd0;
  assign DRDY = 1'b0;
  assign PSDONE = 1'b0;
endmodule
