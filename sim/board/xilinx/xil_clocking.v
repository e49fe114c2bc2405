// Shared by the DCM_ADV and PLL_ADV models (sim/board/xilinx): their lock sequence. Not a Xilinx primitive.
//
// RST = 1 (asynchronous): running and locked low. After RST falls: measure the reference's period over
// MEASURE_EDGES rising edges, check it against EXPECTED_NS (more than 1 % apart stops the simulation: the
// primitive's CLKIN period attribute must give the real input period), wait LOCK_TIME_NS, then start the
// outputs at a rising edge of the reference (t0, delayed by START_FRACTION of the input period), and raise
// ``locked`` -- once ``fb`` has followed the feedback output ``fb_out`` twice when FEEDBACK = 1. The measured
// period and t0 go to the output generators as 64-bit images of reals ($realtobits). ``epoch`` changes at
// every reset, so a generator left waiting from before a reset never drives its output again.
module xil_clock_lock #(
  parameter integer MEASURE_EDGES = 16,
  parameter real LOCK_TIME_NS = 10000.0,
  parameter real EXPECTED_NS = 0.0,       // 0: not checked
  parameter real START_FRACTION = 0.0,
  parameter FEEDBACK = 1'b1
) (
  input clkin,
  input rst,
  input fb,
  input fb_out,
  output reg running,
  output reg locked,
  output reg [31:0] epoch,
  output reg [63:0] period_bits,
  output reg [63:0] t0_bits
);
  real t_first, t_edge, period, t_ready;
  integer edges;
  integer fb_edges;

  initial begin
    running = 1'b0;
    locked = 1'b0;
    epoch = 0;
    fb_edges = 0;
    period_bits = $realtobits(1.0);
    t0_bits = $realtobits(0.0);
  end

  always @(posedge fb)
    if (running === 1'b1 && fb_out === 1'b1) fb_edges = fb_edges + 1;

  initial begin : control
    forever begin
      running = 1'b0;
      locked = 1'b0;
      epoch = epoch + 1;
      fb_edges = 0;
      while (rst !== 1'b0) @(rst);
      edges = 0;
      while (edges <= MEASURE_EDGES && rst === 1'b0) begin
        @(posedge clkin or posedge rst);
        if (rst === 1'b0) begin
          if (edges == 0) t_first = $realtime;
          t_edge = $realtime;
          edges = edges + 1;
        end
      end
      if (rst === 1'b0) begin
        period = (t_edge - t_first) / MEASURE_EDGES;
        if (EXPECTED_NS > 0.0 && (period > 1.01 * EXPECTED_NS || period < 0.99 * EXPECTED_NS))
          $fatal(1, "%m: input period %f ns, the CLKIN period attribute says %f ns", period, EXPECTED_NS);
        period_bits = $realtobits(period);
        t_ready = $realtime + LOCK_TIME_NS;
        while ($realtime < t_ready && rst === 1'b0) @(posedge clkin or posedge rst);
      end
      if (rst === 1'b0) begin
        t0_bits = $realtobits($realtime + START_FRACTION * period);
        running = 1'b1;
        while (FEEDBACK && fb_edges < 2 && rst === 1'b0) @(fb_edges or rst);
        if (rst === 1'b0) locked = 1'b1;
        while (rst === 1'b0) @(rst);
      end
    end
  end
endmodule


// One clock output of the DCM_ADV / PLL_ADV models: period RATIO x the measured input period, first rising edge
// PHASE (a fraction of its own period, 0 <= PHASE < 1) after t0, high for DUTY of the period. Edge times are
// computed from t0 (t0 + PHASE x T + k x T), so the output never drifts from the input; each edge is within the
// simulator's 1 ps precision of its ideal time. Low while not running.
module xil_clock_out #(
  parameter real RATIO = 1.0,
  parameter real PHASE = 0.0,
  parameter real DUTY = 0.5
) (
  input running,
  input [31:0] epoch,
  input [63:0] period_bits,
  input [63:0] t0_bits,
  output out
);
  reg q;
  real period, high, first, t_rise;
  integer my_epoch, k;

  always begin
    q = 1'b0;
    /* verilator lint_off WAITCONST */   // an output that never runs (a DLL output without feedback)
    wait (running === 1'b1);
    /* verilator lint_on WAITCONST */
    my_epoch = epoch;
    period = $bitstoreal(period_bits) * RATIO;
    high = period * DUTY;
    first = $bitstoreal(t0_bits) + period * PHASE;
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

  assign out = q & running;
endmodule
