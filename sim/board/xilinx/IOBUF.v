// Behavioural simulation model of the Virtex-5 IOBUF (bidirectional buffer; UG190 chapter 6): T = 1 releases
// the pad (high impedance) and T = 0 drives I onto it; O always reads the pad. Zero delay.
module IOBUF #(
  parameter CAPACITANCE = "DONT_CARE",
  parameter integer DRIVE = 12,
  parameter IBUF_DELAY_VALUE = "0",
  parameter IFD_DELAY_VALUE = "AUTO",
  parameter IOSTANDARD = "DEFAULT",
  parameter SLEW = "SLOW"
) (
  output O,
  inout IO,
  input I,
  input T
);
  assign IO = T ? 1'bz : I;
  assign O = IO;
endmodule
