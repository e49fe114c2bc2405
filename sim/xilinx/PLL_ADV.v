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
// * RST = 1 (asynchronous): every output low, LOCKED low. After RST falls the model measures the period of the
//   selected input (CLKINSEL = 1: CLKIN1, 0: CLKIN2) over MEASURE_EDGES rising edges, checks it against
//   CLKINn_PERIOD (more than 1 % apart is an error: UG190 asks for the real input period there), waits the lock
//   time, and starts every output at a rising edge of the input (t0): CLKOUTn rises at
//   t0 + CLKOUTn_PHASE / 360 x T_n + k x T_n and stays high CLKOUTn_DUTY_CYCLE x T_n. Edge times are computed
//   from t0, so the outputs do not drift from the input over a long run (each edge is within the simulator's
//   1 ps precision of its ideal time). Outputs with phase 0 are therefore aligned to the input's rising edges
//   every time the two periods meet (UG190: the feedback path aligns CLKFBOUT, and with it the zero-phase
//   outputs, to CLKIN).
// * LOCKED rises once the outputs run and CLKFBIN has shown two rising edges that coincide with CLKFBOUT's
//   (the feedback loop is closed); it stays low for ever if the feedback is not connected.
// * CLKOUTDCMn and CLKFBDCM are copies of CLKOUTn and CLKFBOUT (the DCM-facing outputs).
// * Not modelled ($fatal if used): the dynamic reconfiguration port (DEN), REL, switching CLKINSEL while
//   running, jitter, the BANDWIDTH and COMPENSATION settings (accepted: they change jitter and insertion delay,
//   not the frequencies or phases a logic simulation sees), loss of lock on a changing input.
//
// The lock time is a model parameter (SIM_LOCK_TIME_NS, default `XIL_PLL_LOCK_TIME_NS` or 10 us): DS202's
// maximum lock time could not be read from a stored copy here, so the default is not the data sheet's figure.
// Time unit: 1 ns, precision 1 ps (sim/xilinx/__init__.py).
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
  output reg LOCKED,
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

  // ---- output n parameters --------------------------------------------------------------------------------
  // index 0..5: CLKOUT0..5, 6: CLKFBOUT
  function automatic integer divide_of(input integer n);
    case (n)
      0: divide_of = CLKOUT0_DIVIDE; 1: divide_of = CLKOUT1_DIVIDE; 2: divide_of = CLKOUT2_DIVIDE;
      3: divide_of = CLKOUT3_DIVIDE; 4: divide_of = CLKOUT4_DIVIDE; 5: divide_of = CLKOUT5_DIVIDE;
      default: divide_of = CLKFBOUT_MULT;
    endcase
  endfunction
  function automatic real phase_of(input integer n);
    case (n)
      0: phase_of = CLKOUT0_PHASE; 1: phase_of = CLKOUT1_PHASE; 2: phase_of = CLKOUT2_PHASE;
      3: phase_of = CLKOUT3_PHASE; 4: phase_of = CLKOUT4_PHASE; 5: phase_of = CLKOUT5_PHASE;
      default: phase_of = CLKFBOUT_PHASE;
    endcase
  endfunction
  function automatic real duty_of(input integer n);
    case (n)
      0: duty_of = CLKOUT0_DUTY_CYCLE; 1: duty_of = CLKOUT1_DUTY_CYCLE; 2: duty_of = CLKOUT2_DUTY_CYCLE;
      3: duty_of = CLKOUT3_DUTY_CYCLE; 4: duty_of = CLKOUT4_DUTY_CYCLE; 5: duty_of = CLKOUT5_DUTY_CYCLE;
      default: duty_of = 0.5;
    endcase
  endfunction

  // ---- lock control -----------------------------------------------------------------------------------------
  wire clkin = CLKINSEL ? CLKIN1 : CLKIN2;
  real expected_period;
  real t_first, t_edge, period_in, vco_period, t0, t_ready;
  integer edges;
  integer epoch = 0;           // bumped at every reset: stale output processes stop
  reg running = 1'b0;
  integer fb_edges = 0;

  initial LOCKED = 1'b0;

  always @(DEN) if (DEN === 1'b1) $fatal(1, "PLL_ADV %m: the dynamic reconfiguration port (DEN) is not modelled");
  always @(REL) if (REL === 1'b1) $fatal(1, "PLL_ADV %m: REL is not modelled");
  always @(CLKINSEL) if (running === 1'b1) $fatal(1, "PLL_ADV %m: CLKINSEL switched while running is not modelled");

  initial begin : control
    forever begin
      running = 1'b0;
      LOCKED = 1'b0;
      epoch = epoch + 1;
      fb_edges = 0;
      while (RST !== 1'b0) @(RST);
      expected_period = CLKINSEL ? CLKIN1_PERIOD : CLKIN2_PERIOD;
      // measure the input period over MEASURE_EDGES rising edges
      edges = 0;
      while (edges <= MEASURE_EDGES && RST === 1'b0) begin
        @(posedge clkin or posedge RST);
        if (RST === 1'b0) begin
          if (edges == 0) t_first = $realtime;
          t_edge = $realtime;
          edges = edges + 1;
        end
      end
      if (RST === 1'b0) begin
        period_in = (t_edge - t_first) / MEASURE_EDGES;
        if (expected_period > 0.0 && (period_in > 1.01 * expected_period || period_in < 0.99 * expected_period))
          $fatal(1, "PLL_ADV %m: input period %f ns, CLKIN%0d_PERIOD says %f ns", period_in, CLKINSEL ? 1 : 2,
                 expected_period);
        vco_period = period_in * DIVCLK_DIVIDE / CLKFBOUT_MULT;
        t_ready = $realtime + SIM_LOCK_TIME_NS;
        while ($realtime < t_ready && RST === 1'b0) @(posedge clkin or posedge RST);
      end
      if (RST === 1'b0) begin
        t0 = $realtime;           // a rising edge of the input
        running = 1'b1;
        while (fb_edges < 2 && RST === 1'b0) @(fb_edges or RST);
        if (RST === 1'b0) LOCKED = 1'b1;
        while (RST === 1'b0) @(RST);
      end
    end
  end

  // ---- output generators --------------------------------------------------------------------------------------
  // index 0..5: CLKOUT0..5, 6: CLKFBOUT. An output is forced low while the PLL is not running (reset).
  wire [6:0] outs;

  genvar g;
  generate
    for (g = 0; g < 7; g = g + 1) begin : out
      reg q;
      real period, high, first, t_rise;
      integer my_epoch, k;
      always begin
        q = 1'b0;
        wait (running === 1'b1);
        my_epoch = epoch;
        period = vco_period * divide_of(g);
        high = period * duty_of(g);
        first = t0 + period * phase_of(g) / 360.0;
        while (first < t0) first = first + period;
        k = 0;
        while (first + k * period < $realtime) k = k + 1;   // a late start never makes an early or short edge
        while (running === 1'b1 && epoch == my_epoch) begin
          t_rise = first + k * period;
          if (t_rise > $realtime) #(t_rise - $realtime);
          if (running === 1'b1 && epoch == my_epoch) q = 1'b1;
          if (t_rise + high > $realtime) #(t_rise + high - $realtime);
          q = 1'b0;
          k = k + 1;
        end
      end
      assign outs[g] = q & running;
    end
  endgenerate

  // the feedback loop: CLKFBIN must follow CLKFBOUT
  always @(posedge CLKFBIN)
    if (running === 1'b1 && outs[6] === 1'b1) fb_edges = fb_edges + 1;

  assign {CLKFBOUT, CLKOUT5, CLKOUT4, CLKOUT3, CLKOUT2, CLKOUT1, CLKOUT0} = outs;
  assign {CLKFBDCM, CLKOUTDCM5, CLKOUTDCM4, CLKOUTDCM3, CLKOUTDCM2, CLKOUTDCM1, CLKOUTDCM0} = outs;
  assign DO = 16'd0;
  assign DRDY = 1'b0;
endmodule
