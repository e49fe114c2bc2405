"""The violations the MIG model reports, the ONE table of their messages, and how a harness turns one into a stop.

The model (:class:`sim.models.mig.MIGModel`) drives ``violation.code`` (a :class:`Violation`), ``violation.addr``
(the offending ``app_af_addr``, 0 where no address is involved) and ``violation.cycle`` (clk0 cycles since the
model's reset) and holds the first violation it saw until reset. Every harness -- an Amaranth testbench, a cocotb
module, the Verilator C++ testbench -- watches ``code`` and stops with :func:`violation_message`'s one line.
"""

from amaranth.lib import enum
from amaranth.lib.wiring import Out, Signature

from spec.memory import MIG

__all__ = ["Violation", "MESSAGES", "ViolationSignature", "violation_message", "MIGProtocolViolation"]


class Violation(enum.Enum, shape=4):
    """The code of a violation of MIG's user-interface contract (docs/memory.md); 0: none."""
    NONE = 0
    COMMAND_BEFORE_INIT = 1
    DATA_BEFORE_INIT = 2
    UNKNOWN_COMMAND = 3
    UNALIGNED_ADDRESS = 4
    ADDRESS_OUTSIDE_PART = 5
    ADDRESS_OUTSIDE_WINDOW = 6
    COMMAND_AFULL = 7
    DATA_AFULL = 8
    COMMAND_BEFORE_DATA = 9
    WRITE_DATA_MISSING = 10
    READ_NOT_TAKEN = 11
    LATENCY_OUT_OF_RANGE = 12


#: code -> message (the one table; every harness prints these).
MESSAGES = {
    Violation.COMMAND_BEFORE_INIT: "command written before phy_init_done",
    Violation.DATA_BEFORE_INIT: "write-data word written before phy_init_done",
    Violation.UNKNOWN_COMMAND: "unknown app_af_cmd (only 000 write and 001 read exist)",
    Violation.UNALIGNED_ADDRESS: "address not burst-aligned (BL4: app_af_addr[1:0] must be 0)",
    Violation.ADDRESS_OUTSIDE_PART: f"address beyond the {MIG.MEMORY_WORDS * 8 >> 20} MB part",
    Violation.ADDRESS_OUTSIDE_WINDOW: "address outside the model's memory window",
    Violation.COMMAND_AFULL: "command written after app_af_afull had been high longer than the allowed slack",
    Violation.DATA_AFULL: "write-data word written after app_wdf_afull had been high longer than the allowed slack",
    Violation.COMMAND_BEFORE_DATA: "write command written before its burst's first data word (AR 24146)",
    Violation.WRITE_DATA_MISSING: "write burst's second data word missing when the controller needs it",
    Violation.READ_NOT_TAKEN: "read word returned while the design was not ready to take it (no backpressure)",
    Violation.LATENCY_OUT_OF_RANGE: "the model's read latency input is outside its range (harness set-up)",
}


class ViolationSignature(Signature):
    """The model's report, as the model drives it: ``code`` (:class:`Violation`), ``addr`` (``app_af_addr``
    width), ``cycle`` (32 bits, clk0 cycles since reset). Held from the first violation until reset."""

    def __init__(self, addr_width=MIG.ADDR_WIDTH):
        super().__init__({"code": Out(Violation), "addr": Out(addr_width), "cycle": Out(32)})


class MIGProtocolViolation(AssertionError):
    """A harness's stop on a model violation; ``str()`` is the one-line message."""

    def __init__(self, code, addr, cycle):
        self.code, self.addr, self.cycle = Violation(_number(code)), int(addr), int(cycle)
        super().__init__(violation_message(code, addr, cycle))


def violation_message(code, addr, cycle):
    """The one-line message of violation ``code`` (an int or :class:`Violation`) at ``addr`` in clk0 ``cycle``."""
    try:
        violation = Violation(_number(code))
    except ValueError:
        return f"MIG model: unknown violation code {_number(code)} at clk0 cycle {int(cycle)}"
    text = MESSAGES.get(violation, "no violation")
    return f"MIG model: {text}: app_af_addr 0x{int(addr):08x}, clk0 cycle {int(cycle)} ({violation.name})"


def _number(code):
    return code.value if isinstance(code, Violation) else int(code)
