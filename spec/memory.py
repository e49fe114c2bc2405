"""The DDR2 memory behind Xilinx MIG 3.x for the Virtex-5 as the design relies on it (docs/memory.md; the facts and
their sources: the Genesys reference manual, the MIG 3.6.1 core of freecores/genesys_ddr2, Xilinx answer record
24146, UG190's FIFO flags).

Addresses count 64-bit memory words (``app_af_addr``); one user-interface word is 128 bits (the falling-edge 64
bits above the rising-edge 64 bits); a BL4 burst is 4 memory words = 2 user words = 32 bytes.
"""

__all__ = ["MIG"]


class MIG:
    """MIG 3.x DDR2 user interface on the Genesys (MT4HTF3264HY-667, 256 MB, 64-bit, BL4, CL3, 125 MHz)."""
    CLK0_HZ = 125_000_000          # clk0, the memory clock and the user interface's clock ("mem" domain)
    CLKDIV0_HZ = CLK0_HZ // 2      # clkdiv0: clk0 / 2, the PHY's calibration clock
    CLK200_HZ = 200_000_000        # clk200: the IDELAYCTRL reference (the core's u_ddr2_idelay_ctrl)
    DATA_WIDTH = 128               # APPDATA_WIDTH: one user word, {fall 64 bits, rise 64 bits}
    MASK_WIDTH = 16                # app_wdf_mask_data: one bit per byte of a user word, 1 masks the byte
    ADDR_WIDTH = 31                # app_af_addr: 64-bit memory words
    CMD_WIDTH = 3                  # app_af_cmd
    CMD_WRITE = 0b000
    CMD_READ = 0b001
    BURST_LENGTH = 4               # memory words per burst
    WORDS_PER_BURST = 2            # user words per BL4 burst (written and read)
    COL_BITS = 10                  # address [9:0]
    ROW_BITS = 13                  # address [22:10]
    BANK_BITS = 2                  # address [24:23]
    MEMORY_WORDS = 1 << (COL_BITS + ROW_BITS + BANK_BITS)   # 2**25 64-bit words = 256 MB
    BANKS = 1 << BANK_BITS         # each with a row of its own open (ddr2_ctrl.v's bank management)
    BANK_WORDS = 1 << (COL_BITS + ROW_BITS)                 # one bank: 2**23 words = 64 MB, at bank * BANK_WORDS
    AF_DEPTH = 1024                # address FIFO (FIFO36) entries
    WDF_DEPTH = 512                # write-data FIFO entries (user words)
    AFULL_OFFSET = 15              # app_af_afull / app_wdf_afull high when this many entries or fewer are free
    # app_wdf_afull's FIFO36 is multirate (EN_SYN FALSE: written on clk0, read on clk90): its ALMOSTFULL asserts
    # 1 write clock late and deasserts 3 late (UG190 table 4-16); the address FIFO is synchronous (EN_SYN TRUE):
    # no flag latency.
    WDF_AFULL_ASSERT_CLK = 1
    WDF_AFULL_DEASSERT_CLK = 3
    TREFI_CLK = 975                # refresh interval in clk0 (7.8 us at 125 MHz)
    TRFC_CLK = 14                  # refresh cycle time in clk0 (105 ns)
    # The controller's command spacings at 125 MHz: ddr2_ctrl.v's counters (TRP_CYC 3, TRCD_CYC 2, TWTR_CYC 6,
    # TRTW_CYC 6) plus the offsets its comments give (precharge -> command "- 2", activate -> read/write "- 3",
    # write -> read and read -> write "- 3").
    TRP_CLK = 5                    # precharge (all) -> next command
    TRCD_CLK = 5                   # activate -> read or write
    WTR_CLK = 9                    # write -> read turnaround
    RTW_CLK = 9                    # read -> write turnaround
    # block RAM the core itself uses without ECC (ECC_ENABLE = 0): the address FIFO (a FIFO36) and the write-data
    # FIFO (2 FIFO36_72: 128 data + 16 mask bits); its read data leave through registers, the two read FIFO36_72
    # exist only with ECC (MIG 3.6.1's ddr2_usr_addr_fifo.v, ddr2_usr_wr.v, ddr2_usr_rd.v, freecores/genesys_ddr2)
    FPGA_RAMB36 = 3
