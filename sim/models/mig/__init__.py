"""Xilinx MIG 3.x's DDR2 user interface (Virtex-5) with the memory behind it, as an Amaranth component for
simulation only (never built for the FPGA): the same model runs in Amaranth's simulator and, exported to
Verilog, under cocotb (Verilator, Icarus) and in the Verilator C++ testbench. docs/memory.md describes the
contract and what the model does.

==================  ==========================================================================================
module              what
==================  ==========================================================================================
``model``           ``MIGModel``: the model (FIFOs, controller, memory window, read return, checker)
``user_fifo``       ``UserFifo``: the address / write-data FIFO with its almost-full flag
``controller``      ``Controller``: one BL4 burst per command, in order
``bank_timing``     ``BankTiming``: open rows, turnarounds, refresh
``memory_window``   ``MemoryWindow``: the contents over a window of the part
``read_return``     ``ReadReturn``: read words on their due clocks, no backpressure
``checker``         ``ProtocolChecker``: the violations
``violations``      the violation codes, the one table of their messages, the harness's exception
``harness``         ``draw_latency``; the Amaranth testbench that stops on a violation
``mig_top``         ``mig_top_verilog``: the model behind the port names of MIG's generated top module
==================  ==========================================================================================
"""

from .harness import draw_latency, watch_violations
from .memory_window import STORAGE_MODULE, STORAGE_VERILOG
from .mig_top import LATENCY_PLUSARG, mig_top_verilog
from .model import (AF_SLACK, DATA_GRACE, DEFAULT_WINDOW_WORDS, INIT_CLOCKS, READ_LATENCY_RANGE, WDF_SLACK, MIGModel,
                    layout_window, memory_words)
from .violations import MESSAGES, MIGProtocolViolation, Violation, violation_message

__all__ = ["MIGModel", "memory_words", "layout_window", "READ_LATENCY_RANGE", "AF_SLACK", "WDF_SLACK", "INIT_CLOCKS",
           "DATA_GRACE", "DEFAULT_WINDOW_WORDS", "Violation", "MESSAGES", "STORAGE_MODULE", "STORAGE_VERILOG",
           "mig_top_verilog", "LATENCY_PLUSARG", "violation_message", "MIGProtocolViolation", "draw_latency",
           "watch_violations"]
