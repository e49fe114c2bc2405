// Behavioural simulation model of the Virtex-5 IBUF (single-ended input buffer), for the board-top simulation.
// Written from the Virtex-5 Libraries Guide for HDL Designs (UG621, "IBUF") and UG190 chapter 6 (SelectIO):
// O follows I; the attributes only select the electrical standard and input delay, which a logic simulation
// does not see. Zero delay. Time unit of every model in sim/xilinx: 1 ns (see sim/xilinx/__init__.py).
module IBUF #(
  parameter CAPACITANCE = "DONT_CARE",
  parameter IBUF_DELAY_VALUE = "0",
  parameter IFD_DELAY_VALUE = "AUTO",
  parameter IOSTANDARD = "DEFAULT"
) (
  output O,
  input I
);
  assign O = I;
endmodule
