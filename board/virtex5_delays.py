"""The Virtex-5 -1 delay model of the static timing estimate (``board/timing.py``, ``stereodepth timing``).

Every constant names the data-sheet symbol it stands for and the table that defines that symbol: the CLB,
block RAM, DSP48E and IOB switching-characteristics tables of DS202 ("Virtex-5 FPGA Data Sheet: DC and Switching
Characteristics"), whose parameters UG190 (Virtex-5 FPGA User Guide: chapter 4 "Block RAM Timing Model", table
4-11; chapter 5 "CLB / Slice Timing Models") and UG193 (XtremeDSP, DSP48E timing) define. DS202's figures
themselves could not be read here (no stored copy of its tables was found), so every *value* is an assumption: an
estimate for the -1 speed grade, marked as such in :data:`MODEL` and in docs/board.md, cross-checked only
against a second-hand model (FloPoCo's Virtex-5 target, a -3 device: LUT 0.086 ns, MUXCY S->O 0.305 ns, CIN->O
0.023 ns per bit, XORCY 0.300 ns, block RAM 1.75 ns, DSP multiplier 2.39 ns): the -1 grade is the slowest, so
each value here is at or above those.

The routing delay is one figure per net (``net_ns``, default 0.5 ns: the timing goal is stated at that figure),
except on the connections the slice and the DSP/RAM columns make without general routing (UG190 chapter 5: a
LUT's O6/O5 into its own slice's carry chain and F7 multiplexer, F7 into F8, carry-out into the next slice's
carry-in): those cost nothing beyond the cell delay. A LUT has one such place; ``board/timing.py`` routes the rest
(a net, and TILO for the route-through LUT a carry select or F7 input needs).
"""

from dataclasses import dataclass

__all__ = ["Constant", "MODEL", "NET_NS", "ASSUMED", "UG190_BRAM", "UG190_CLB", "NOT_READ"]

#: How each value below is sourced.
ASSUMED = "assumption: DS202 -1 figure not readable here"

#: The default routing delay per net (ns).
NET_NS = 0.5


#: Where a symbol's name and meaning were read (stored copies of UG190 v5.0, found with the search tool).
UG190_BRAM = "read: UG190 v5.0 table 4-11"
UG190_CLB = "read: UG190 v5.0 ch. 5 (LUT and distributed RAM timing)"
NOT_READ = "not read here: DS202's name, from memory"


@dataclass(frozen=True)
class Constant:
    """One delay of the model: ``ns`` for the -1 speed grade; ``symbol`` the DS202 parameter it stands for,
    ``table`` where that symbol is defined, ``named_in`` whether that name was read in a source here,
    ``source`` where the value comes from."""
    ns: float
    symbol: str
    what: str
    table: str
    named_in: str = NOT_READ
    source: str = ASSUMED


_CLB = "DS202 CLB switching characteristics; UG190 ch. 5 'CLB / Slice Timing Models'"
_BRAM = "DS202 block RAM switching characteristics; UG190 table 4-11 'Block RAM Timing Parameters'"
_DSP = "DS202 DSP48E switching characteristics; UG193 ch. 2 DSP48E timing"
_IOB = "DS202 input/output logic switching characteristics (ILOGIC/OLOGIC); UG190 ch. 7"

#: key -> :class:`Constant`. The keys are what ``board/timing.py`` looks up.
MODEL = {
    # CLB: LUTs, flip-flops, wide multiplexers, carry logic
    "lut": Constant(0.10, "TILO", "LUT1..LUT6 / INV, any input to its output", _CLB, UG190_CLB),
    "ff_cko": Constant(0.47, "TCKO", "slice flip-flop, clock to Q", _CLB),
    "ff_d": Constant(0.40, "TDICK", "slice flip-flop D setup (AX..DX bypass input)", _CLB),
    "ff_ce": Constant(0.30, "TCECK", "slice flip-flop CE setup", _CLB),
    "ff_sr": Constant(0.50, "TSRCK", "slice flip-flop R/S setup; also used for CLR/PRE recovery", _CLB),
    "muxf7": Constant(0.30, "F7AMUX/F7BMUX", "MUXF7, I0/I1/S to O", _CLB),
    "muxf8": Constant(0.30, "F8MUX", "MUXF8, I0/I1/S to O", _CLB),
    "carry_in": Constant(0.40, "TOPCYA..D / TAXCY (less TILO)",
                         "CARRY4 S/DI/CYINIT into the chain, to any CO/O of the same CARRY4", _CLB),
    "carry_ci": Constant(0.10, "TBYP", "CARRY4 CI to CO (through one CARRY4)", _CLB),
    "carry_ci_o": Constant(0.35, "TCINA..D", "CARRY4 CI to the sum outputs O", _CLB),
    "muxcy_s": Constant(0.37, "MUXCY S/DI->O", "MUXCY, S or DI to O", _CLB),
    "muxcy_ci": Constant(0.03, "MUXCY CI->O", "MUXCY, CI to O (one bit of the carry chain)", _CLB),
    "xorcy": Constant(0.30, "XORCY LI/CI->O", "XORCY, LI or CI to O", _CLB),
    # block RAM
    "bram_cko": Constant(2.45, "TRCKO_DO", "block RAM clock to DO/DOP, no output register (DO_REG = 0)", _BRAM,
                         UG190_BRAM),
    "bram_cko_reg": Constant(0.90, "TRCKO_DO (DO_REG = 1)", "block RAM clock to DO/DOP with the output register",
                             _BRAM),
    "bram_cascade": Constant(0.30, "cascade (CASCADEINLAT -> DO)",
                             "extra clock-to-out of the upper block of a cascaded 64K x 1 pair", _BRAM),
    "bram_addr": Constant(0.55, "TRCCK_ADDR", "block RAM ADDR setup", _BRAM, UG190_BRAM),
    "bram_di": Constant(0.45, "TRDCK_DI", "block RAM DI/DIP setup", _BRAM, UG190_BRAM),
    "bram_en": Constant(0.60, "TRCCK_EN", "block RAM EN (RDEN/WREN) setup", _BRAM, UG190_BRAM),
    "bram_we": Constant(0.70, "TRCCK_WE", "block RAM WE setup", _BRAM, UG190_BRAM),
    "bram_ssr": Constant(0.45, "TRCCK_SSR", "block RAM SSR setup", _BRAM, UG190_BRAM),
    "bram_regce": Constant(0.35, "TRCCK_REGCE", "block RAM REGCE setup", _BRAM, UG190_BRAM),
    # DSP48E
    "dsp_ab_p": Constant(4.30, "TDSPDO_{A,B}_P", "DSP48E A/B (ACIN/BCIN) to P through the multiplier, no registers",
                         _DSP),
    "dsp_c_p": Constant(2.20, "TDSPDO_{C,PCIN,CARRYIN}_P", "DSP48E C/PCIN/CARRYIN to P through the ALU", _DSP),
    "dsp_ctrl_p": Constant(2.60, "TDSPDO_{OPMODE,ALUMODE,CARRYINSEL}_P", "DSP48E control inputs to P", _DSP),
    "dsp_cko_preg": Constant(0.60, "TDSPCKO_P_PREG", "DSP48E clock to P from the P register", _DSP),
    "dsp_cko_mreg": Constant(2.60, "TDSPCKO_P_MREG", "DSP48E clock to P from the M register (PREG = 0)", _DSP),
    "dsp_cko_inreg": Constant(4.50, "TDSPCKO_P_{A,B}REG", "DSP48E clock to P from the A/B input registers "
                              "(MREG = PREG = 0)", _DSP),
    "dsp_setup_inreg": Constant(0.35, "TDSPDCK_{A,B,C}_{A,B,C}REG", "DSP48E setup into its input registers", _DSP),
    "dsp_setup_mreg": Constant(3.10, "TDSPDCK_{A,B}_MREG", "DSP48E A/B setup into the M register", _DSP),
    "dsp_setup_preg_ab": Constant(4.20, "TDSPDCK_{A,B}_PREG", "DSP48E A/B setup into the P register (MREG = 0)",
                                  _DSP),
    "dsp_setup_preg_c": Constant(2.10, "TDSPDCK_{C,OPMODE,...}_PREG", "DSP48E C/control setup into the P register",
                                 _DSP),
    # distributed (LUT) RAM: Yosys maps small memories to RAM64M / RAM32M / RAMnnX1D
    "lutram_read": Constant(0.10, "TILO (as a LUT)", "distributed RAM read address to DO, as a LUT", _CLB, UG190_CLB),
    "lutram_cko": Constant(1.20, "TSHCKO", "distributed RAM write clock to DO (the written word appearing)", _CLB),
    "lutram_setup": Constant(0.50, "TDS / TAS / TWS", "distributed RAM data, address and WE setup before WCLK",
                             _CLB),
    # shift registers in LUTs: Yosys maps reset-less delay lines to SRL16E / SRLC32E
    "srl_cko": Constant(1.50, "TREG", "SRL16E / SRLC32E clock to Q (the addressed tap)", _CLB),
    "srl_setup": Constant(0.50, "TDS / TCECK (SRL)", "SRL16E / SRLC32E D and CE setup before CLK", _CLB),
    # IOB flip-flops and ODDR
    "iob_in_cko": Constant(0.55, "TICKQ", "input flip-flop in the IOB (IOB = TRUE), clock to Q into the fabric",
                           _IOB),
    "iob_out_setup": Constant(0.55, "TODCK", "output flip-flop in the IOB, D setup from the fabric", _IOB),
    "oddr_setup": Constant(0.55, "TODCK / TOOCECK / TOSRCK", "ODDR D1/D2/CE/R/S setup", _IOB),
}
