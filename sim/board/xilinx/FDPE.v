// Behavioural simulation model of the Xilinx FDPE (D flip-flop, clock enable, asynchronous preset; UG190
// chapter 5 storage element): PRE = 1 sets Q at once; otherwise Q takes D on the rising edge of C when CE = 1.
// INIT is Q's value after configuration (time 0).
module FDPE #(
  parameter [0:0] INIT = 1'b1
) (
  output reg Q,
  input C,
  input CE,
  input PRE,
  input D
);
  initial Q = INIT;
  always @(posedge C or posedge PRE)
    if (PRE)
      Q <= 1'b1;
    else if (CE)
      Q <= D;
endmodule
