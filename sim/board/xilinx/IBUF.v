// Behavioural simulation model of the Virtex-5 IBUF (single-ended input buffer), for the board-top simulation.
// Its logic function (UG190 chapter 6, "SelectIO Resources"): O follows I. The attributes select the electrical
// standard and input delay, which a logic simulation does not see. Zero delay. Time unit of every model in
// sim/board/xilinx: 1 ns (see sim/board/xilinx/__init__.py).
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
