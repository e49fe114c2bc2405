// Behavioural simulation model of the Virtex-5 BUFG (global clock buffer). UG190 chapter 1 ("BUFG"): a
// clock buffer with one input and one output, O follows I; zero delay here (clock-tree insertion delay is
// not modelled, so every BUFG output edge coincides with its input edge).
module BUFG (
  output O,
  input I
);
  assign O = I;
endmodule
