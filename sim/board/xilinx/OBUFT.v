// Behavioural simulation model of the Virtex-5 OBUFT (3-state output buffer; UG190 chapter 6): T = 1 puts the
// output in high impedance, T = 0 drives I onto O. Zero delay.
module OBUFT #(
  parameter CAPACITANCE = "DONT_CARE",
  parameter integer DRIVE = 12,
  parameter IOSTANDARD = "DEFAULT",
  parameter SLEW = "SLOW"
) (
  output O,
  input I,
  input T
);
  assign O = T ? 1'bz : I;
endmodule
