// Behavioural simulation model of the Virtex-5 IBUFG (global-clock input buffer; UG190 chapter 1, global clock
// inputs): O follows I, zero delay.
module IBUFG #(
  parameter CAPACITANCE = "DONT_CARE",
  parameter IBUF_DELAY_VALUE = "0",
  parameter IOSTANDARD = "DEFAULT"
) (
  output O,
  input I
);
  assign O = I;
endmodule
