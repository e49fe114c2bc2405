// Behavioural simulation model of the Virtex-5 ODDR (output double-data-rate register in the IOB).
//
// Written from UG190 chapter 7 ("Output DDR Overview (ODDR)") and the Libraries Guide description of the same
// primitive (UG953 "ODDR": identical ports and attributes):
//
// * DDR_CLK_EDGE = "OPPOSITE_EDGE": D1 is sampled on every rising edge of C and appears on Q after it; D2 is
//   sampled on every falling edge of C and appears on Q after it.
// * DDR_CLK_EDGE = "SAME_EDGE": D1 and D2 are both sampled on the rising edge of C; Q shows that D1 after the
//   rising edge and that D2 (held in an extra register clocked by the falling edge) after the following falling
//   edge. So a pair presented together leaves as D1 in the high phase, D2 in the low phase of the same cycle.
// * CE = 0 holds every register. R (reset to 0) and S (set to 1) act on Q and the internal registers: at once
//   with SRTYPE = "ASYNC", at the next clock edge (either edge: Q is updated on both) with SRTYPE = "SYNC".
//   R and S must not be asserted together (the model stops with $fatal).
// * INIT is Q's value after configuration.
//
// Any other DDR_CLK_EDGE / SRTYPE value is an error at time 0. Zero clock-to-out delay.
module ODDR #(
  parameter DDR_CLK_EDGE = "OPPOSITE_EDGE",
  parameter [0:0] INIT = 1'b0,
  parameter SRTYPE = "SYNC"
) (
  output Q,
  input C,
  input CE,
  input D1,
  input D2,
  input R,
  input S
);
  localparam SAME = (DDR_CLK_EDGE == "SAME_EDGE");
  localparam ASYNC = (SRTYPE == "ASYNC");

  reg q;         // the output register
  reg d2_held;   // SAME_EDGE: D2 taken on the rising edge, shown after the falling edge

  initial begin
    q = INIT;
    d2_held = INIT;
    if (DDR_CLK_EDGE != "SAME_EDGE" && DDR_CLK_EDGE != "OPPOSITE_EDGE")
      $fatal(1, "ODDR %m: DDR_CLK_EDGE = %s is not SAME_EDGE or OPPOSITE_EDGE", DDR_CLK_EDGE);
    if (SRTYPE != "SYNC" && SRTYPE != "ASYNC")
      $fatal(1, "ODDR %m: SRTYPE = %s is not SYNC or ASYNC", SRTYPE);
  end

  always @(R or S)
    if (R === 1'b1 && S === 1'b1)
      $fatal(1, "ODDR %m: R and S asserted together at %t", $realtime);

  // One process per SRTYPE: Q and the SAME_EDGE holding register change on both clock edges (and, ASYNC, on
  // R / S); the level of C tells a rising edge from a falling one.
  task automatic edge_of_c;
    if (C) begin                        // rising edge: D1 to Q, D2 into the holding register
      if (CE) begin
        q <= D1;
        d2_held <= D2;
      end
    end else if (CE)                    // falling edge
      q <= SAME ? d2_held : D2;
  endtask

  generate
    if (ASYNC) begin : async_sr
      always @(posedge C or negedge C or posedge R or posedge S)
        if (R) begin
          q <= 1'b0;
          d2_held <= 1'b0;
        end else if (S) begin
          q <= 1'b1;
          d2_held <= 1'b1;
        end else
          edge_of_c;
    end else begin : sync_sr
      always @(posedge C or negedge C)
        if (R) begin
          q <= 1'b0;
          if (C) d2_held <= 1'b0;
        end else if (S) begin
          q <= 1'b1;
          if (C) d2_held <= 1'b1;
        end else
          edge_of_c;
    end
  endgenerate

  assign Q = q;
endmodule
