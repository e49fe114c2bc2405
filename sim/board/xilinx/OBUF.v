// Behavioural simulation model of the Virtex-5 OBUF (single-ended output buffer; UG190 chapter 6): O follows I;
// DRIVE / SLEW / IOSTANDARD are electrical, invisible to a logic simulation. Zero delay.
module OBUF #(
  parameter CAPACITANCE = "DONT_CARE",
  parameter integer DRIVE = 12,
  parameter IOSTANDARD = "DEFAULT",
  parameter SLEW = "SLOW"
) (
  output O,
  input I
);
  assign O = I;
endmodule
