// Behavioural simulation model of the Xilinx FDCE (D flip-flop, clock enable, asynchronous clear; the
// storage element of UG190 chapter 5, as an IOB register here): CLR = 1 clears Q at once, whatever the clock;
// otherwise Q takes D on the rising edge of C when CE = 1. INIT is Q's value after configuration (time 0).
module FDCE #(
  parameter [0:0] INIT = 1'b0
) (
  output reg Q,
  input C,
  input CE,
  input CLR,
  input D
);
  initial Q = INIT;
  always @(posedge C or posedge CLR)
    if (CLR)
      Q <= 1'b0;
    else if (CE)
      Q <= D;
endmodule
