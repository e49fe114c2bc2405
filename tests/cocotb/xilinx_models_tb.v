// Test bench top for the primitive models in board/simulation/xilinx (tests/test_xilinx_models.py, cocotb_xilinx.py).
// Every primitive is instantiated with the attributes under test; cocotb drives the inputs and measures.
module xilinx_models_tb (
  // IO buffers
  input buf_i, input buf_t, input pad_drive, input pad_value,
  output ibuf_o, output ibufg_o, output bufg_o, output obuf_o, output obuft_o, output iobuf_o, inout pad,
  // flip-flops
  input ff_c, input ff_ce, input ff_clr, input ff_pre, input ff_d,
  output fdce_q, output fdpe_q,
  // ODDR: four instances, every DDR_CLK_EDGE x SRTYPE (INIT 1 on the SYNC ones)
  input oddr_c, input oddr_ce, input oddr_d1, input oddr_d2, input oddr_r, input oddr_s,
  output oddr_same_async, output oddr_same_sync, output oddr_opp_async, output oddr_opp_sync,
  // DCM_ADV: the board's frequency synthesis (no feedback), a DLL with 1X feedback and a fixed phase shift,
  // and a DLL whose feedback is not connected
  input dcm_clkin, input dcm_rst,
  output dcm_fx, output dcm_fx180, output dcm_fx_locked,
  output dcm_clk0, output dcm_clk90, output dcm_clk180, output dcm_clk270, output dcm_clk2x, output dcm_clkdv,
  output dcm_dll_locked, output dcm_nofb_locked, output dcm_nofb_clk0,
  // PLL_ADV: the board's camera PLL (100 MHz -> 24 MHz), a PLL with the pixel PLL's ratios plus a
  // 25 % duty / 180 degree output, and one whose feedback is not connected
  input pll_clkin, input pll_rst, input pix_clkin, input pix_rst,
  output pll_cam_out, output pll_cam_locked,
  output pll_pix_out0, output pll_pix_out1, output pll_pix_out2, output pll_pix_fb, output pll_pix_locked,
  output pll_nofb_locked, output pll_nofb_out0,
  // PLL_BASE: the board's MIG clocks (100 MHz x 10 = 1 GHz VCO; / 8, / 8 at 90 degrees, / 16, / 5)
  input mem_clkin, input mem_rst,
  output mem_clk0, output mem_clk90, output mem_clkdiv0, output mem_clk200, output mem_locked
);
  IBUF ibuf (.I(buf_i), .O(ibuf_o));
  IBUFG ibufg (.I(buf_i), .O(ibufg_o));
  BUFG bufg (.I(buf_i), .O(bufg_o));
  OBUF obuf (.I(buf_i), .O(obuf_o));
  OBUFT obuft (.I(buf_i), .T(buf_t), .O(obuft_o));
  pullup (obuft_o);
  IOBUF iobuf (.I(buf_i), .T(buf_t), .IO(pad), .O(iobuf_o));
  assign pad = pad_drive ? pad_value : 1'bz;
  pullup (pad);

  FDCE #(.INIT(1'b1)) fdce (.C(ff_c), .CE(ff_ce), .CLR(ff_clr), .D(ff_d), .Q(fdce_q));
  FDPE #(.INIT(1'b0)) fdpe (.C(ff_c), .CE(ff_ce), .PRE(ff_pre), .D(ff_d), .Q(fdpe_q));

  ODDR #(.DDR_CLK_EDGE("SAME_EDGE"), .INIT(1'b0), .SRTYPE("ASYNC")) oddr0 (
    .C(oddr_c), .CE(oddr_ce), .D1(oddr_d1), .D2(oddr_d2), .R(oddr_r), .S(oddr_s), .Q(oddr_same_async));
  ODDR #(.DDR_CLK_EDGE("SAME_EDGE"), .INIT(1'b1), .SRTYPE("SYNC")) oddr1 (
    .C(oddr_c), .CE(oddr_ce), .D1(oddr_d1), .D2(oddr_d2), .R(oddr_r), .S(oddr_s), .Q(oddr_same_sync));
  ODDR #(.DDR_CLK_EDGE("OPPOSITE_EDGE"), .INIT(1'b0), .SRTYPE("ASYNC")) oddr2 (
    .C(oddr_c), .CE(oddr_ce), .D1(oddr_d1), .D2(oddr_d2), .R(oddr_r), .S(oddr_s), .Q(oddr_opp_async));
  ODDR #(.DDR_CLK_EDGE("OPPOSITE_EDGE"), .INIT(1'b1), .SRTYPE("SYNC")) oddr3 (
    .C(oddr_c), .CE(oddr_ce), .D1(oddr_d1), .D2(oddr_d2), .R(oddr_r), .S(oddr_s), .Q(oddr_opp_sync));

  DCM_ADV #(.CLKFX_MULTIPLY(11), .CLKFX_DIVIDE(10), .CLKIN_PERIOD(10.0), .CLK_FEEDBACK("NONE"),
            .SIM_LOCK_TIME_NS(1000.0)) dcm_fx_inst (
    .CLKIN(dcm_clkin), .CLKFB(1'b0), .RST(dcm_rst), .PSCLK(1'b0), .PSEN(1'b0), .PSINCDEC(1'b0),
    .DCLK(1'b0), .DEN(1'b0), .DWE(1'b0), .DADDR(7'd0), .DI(16'd0),
    .CLKFX(dcm_fx), .CLKFX180(dcm_fx180), .LOCKED(dcm_fx_locked));
  wire dll_fb;
  DCM_ADV #(.CLKFX_MULTIPLY(2), .CLKFX_DIVIDE(1), .CLKIN_PERIOD(10.0), .CLK_FEEDBACK("1X"),
            .CLKDV_DIVIDE(4.0), .CLKOUT_PHASE_SHIFT("FIXED"), .PHASE_SHIFT(32), .SIM_LOCK_TIME_NS(1000.0)) dcm_dll (
    .CLKIN(dcm_clkin), .CLKFB(dll_fb), .RST(dcm_rst), .PSCLK(1'b0), .PSEN(1'b0), .PSINCDEC(1'b0),
    .DCLK(1'b0), .DEN(1'b0), .DWE(1'b0), .DADDR(7'd0), .DI(16'd0),
    .CLK0(dcm_clk0), .CLK90(dcm_clk90), .CLK180(dcm_clk180), .CLK270(dcm_clk270), .CLK2X(dcm_clk2x),
    .CLKDV(dcm_clkdv), .LOCKED(dcm_dll_locked));
  BUFG dll_fb_buf (.I(dcm_clk0), .O(dll_fb));
  DCM_ADV #(.CLK_FEEDBACK("1X"), .CLKIN_PERIOD(10.0), .SIM_LOCK_TIME_NS(1000.0)) dcm_nofb (
    .CLKIN(dcm_clkin), .CLKFB(1'b0), .RST(dcm_rst), .PSCLK(1'b0), .PSEN(1'b0), .PSINCDEC(1'b0),
    .DCLK(1'b0), .DEN(1'b0), .DWE(1'b0), .DADDR(7'd0), .DI(16'd0),
    .CLK0(dcm_nofb_clk0), .LOCKED(dcm_nofb_locked));

  wire cam_fb;
  PLL_ADV #(.CLKIN1_PERIOD(10.0), .DIVCLK_DIVIDE(1), .CLKFBOUT_MULT(6), .CLKOUT0_DIVIDE(25),
            .COMPENSATION("INTERNAL"), .SIM_LOCK_TIME_NS(2000.0)) pll_cam (
    .CLKIN1(pll_clkin), .CLKIN2(1'b0), .CLKINSEL(1'b1), .CLKFBIN(cam_fb), .CLKFBOUT(cam_fb), .RST(pll_rst),
    .REL(1'b0), .DCLK(1'b0), .DEN(1'b0), .DWE(1'b0), .DADDR(5'd0), .DI(16'd0),
    .CLKOUT0(pll_cam_out), .LOCKED(pll_cam_locked));
  PLL_ADV #(.CLKIN1_PERIOD(9.09), .DIVCLK_DIVIDE(5), .CLKFBOUT_MULT(27), .CLKOUT0_DIVIDE(4),
            .CLKOUT1_DIVIDE(4), .CLKOUT1_PHASE(90.0), .CLKOUT2_DIVIDE(8), .CLKOUT2_PHASE(180.0),
            .CLKOUT2_DUTY_CYCLE(0.25), .COMPENSATION("DCM2PLL"), .SIM_LOCK_TIME_NS(2000.0)) pll_pix (
    .CLKIN1(pix_clkin), .CLKIN2(1'b0), .CLKINSEL(1'b1), .CLKFBIN(pll_pix_fb), .CLKFBOUT(pll_pix_fb),
    .RST(pix_rst), .REL(1'b0), .DCLK(1'b0), .DEN(1'b0), .DWE(1'b0), .DADDR(5'd0), .DI(16'd0),
    .CLKOUT0(pll_pix_out0), .CLKOUT1(pll_pix_out1), .CLKOUT2(pll_pix_out2), .LOCKED(pll_pix_locked));
  PLL_ADV #(.CLKIN1_PERIOD(10.0), .CLKFBOUT_MULT(6), .CLKOUT0_DIVIDE(25), .SIM_LOCK_TIME_NS(2000.0)) pll_nofb (
    .CLKIN1(pll_clkin), .CLKIN2(1'b0), .CLKINSEL(1'b1), .CLKFBIN(1'b0), .RST(pll_rst),
    .REL(1'b0), .DCLK(1'b0), .DEN(1'b0), .DWE(1'b0), .DADDR(5'd0), .DI(16'd0),
    .CLKOUT0(pll_nofb_out0), .LOCKED(pll_nofb_locked));

  wire mem_fb;
  PLL_BASE #(.CLKIN_PERIOD(10.0), .DIVCLK_DIVIDE(1), .CLKFBOUT_MULT(10), .CLKOUT0_DIVIDE(8), .CLKOUT1_DIVIDE(8),
             .CLKOUT1_PHASE(90.0), .CLKOUT2_DIVIDE(16), .CLKOUT3_DIVIDE(5), .SIM_LOCK_TIME_NS(2000.0)) pll_mem (
    .CLKIN(mem_clkin), .CLKFBIN(mem_fb), .CLKFBOUT(mem_fb), .RST(mem_rst),
    .CLKOUT0(mem_clk0), .CLKOUT1(mem_clk90), .CLKOUT2(mem_clkdiv0), .CLKOUT3(mem_clk200), .LOCKED(mem_locked));
endmodule
