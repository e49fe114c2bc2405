# amaranth: UnusedElaboratable=no
"""SwitchControl: the disparity and rectification registers change only in the clock after ``frame_start``.

The switches and ``frame_start`` are free: any value on any clock (the switches are asynchronous; whatever
``frame_start`` does, the registers must only move with it). A reference model written from the docstring (SW7
selects the register, a ``stages``-flop synchroniser, pending registers loaded into the outputs at
``frame_start``) gives the value each register must hold.
"""

from amaranth import Signal, signed

from hdl.switches import SWITCH_VALUE_BITS, SwitchControl
from sim.formal.runner import FormalHarness


class SwitchControlHarness(FormalHarness):
    name = "switches"
    block = "SwitchControl"

    def __init__(self, stages=2):
        super().__init__()
        self.stages = stages

    def dut(self):
        return SwitchControl(stages=self.stages)

    def connect(self, m, dut, sw, frame_start):
        """The block's ports (the one place to adapt when the signature changes)."""
        m.d.comb += [dut.sw.eq(sw), dut.frame_start.eq(frame_start)]
        return dut.settings.disparity, dut.settings.rectification

    def build(self, m):
        sw = self.free("sw", SWITCH_VALUE_BITS + 1)
        frame_start = self.free("frame_start")
        m.submodules.dut = dut = self.dut()
        disparity, rectification = self.connect(m, dut, sw, frame_start)

        # Reference: the switches seen `stages` clocks later (a synchroniser is not reset), SW7 picks the pending
        # register; the rectification's seven bits are two's complement (hdl/switches.py).
        seen = self.past(m, sw, self.stages, name="sw_synchronised", reset_less=True)
        pending = {"disparity": Signal(SWITCH_VALUE_BITS, name="ref_disparity_pending"),
                   "rectification": Signal(signed(SWITCH_VALUE_BITS), name="ref_rectification_pending")}
        with m.If(seen[SWITCH_VALUE_BITS]):
            m.d.sync += pending["disparity"].eq(seen[:SWITCH_VALUE_BITS])
        with m.Else():
            m.d.sync += pending["rectification"].eq(seen[:SWITCH_VALUE_BITS])

        pv = self.past_valid(m)
        was_frame_start = self.past(m, frame_start, name="past_frame_start")
        for name, register in (("disparity", disparity), ("rectification", rectification)):
            before = self.past(m, register, name=f"past_{name}")
            expected = self.past(m, pending[name], name=f"past_ref_{name}_pending")
            changed = pv & (register != before)
            self.prove(m, f"{name}_changes_only_after_frame_start", ~changed | was_frame_start)
            self.prove(m, f"{name}_loads_switch_value_at_frame_start", ~(pv & was_frame_start) |
                       (register == expected))
            self.prove(m, f"{name}_zero_after_reset", pv | (register == 0))
            self.cover(m, f"{name}_changes", changed)
        self.cover(m, "both_change_in_one_frame_start", pv & (disparity != self.past(m, disparity)) &
                   (rectification != self.past(m, rectification)))
