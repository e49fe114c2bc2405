"""RectificationSelect: the rectification in use, by hand (the switches) or found by the estimator
(docs/rectification.md)."""

from amaranth import Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.rectification_text import RectificationModeSignature
from hdl.switches import RECTIFICATION_RANGE, SettingsSignature
from spec.rectification import RECTIFICATION

__all__ = ["RectificationSelect", "AUTO_CODE", "SEGMENT_CODE", "MANUAL_RANGE"]

#: The switch value that selects the automatic mode: SW7 = 0, SW6..SW0 = 1000000 (-64 in two's complement, the
#: one rectification the switches give up: a misalignment of 64 buffer rows leaves no common image).
AUTO_CODE = RECTIFICATION_RANGE.start
#: The switch value that selects the automatic mode with the segmentation view (docs/display.md, "Segmentation"):
#: SW7 = 0, SW6..SW0 = 1000001 (-63: the next rectification given up, a misalignment of 63 buffer rows).
SEGMENT_CODE = AUTO_CODE + 1
#: The rectifications the switches set by hand: -62..63.
MANUAL_RANGE = range(SEGMENT_CODE + 1, RECTIFICATION_RANGE.stop)


class RectificationSelect(wiring.Component):
    """``settings`` = the switches' ``manual`` settings, except that in automatic mode (the manual rectification
    is :data:`AUTO_CODE` or :data:`SEGMENT_CODE`) the rectification is the estimator's offset, sampled at
    ``frame_start``; :data:`SEGMENT_CODE` also turns the segmentation view on (``segment``).

    Parameters
    ----------
    config : RectificationConfig
        The estimator's search range (its offset is -R..R).

    Ports
    -----
    manual : In(SettingsSignature)
        The switch registers (they change only in the clock after ``frame_start``).
    estimate : In(range(-R, R + 1))
        The estimator's offset in use (changes at any time).
    frame_start : In(1)
    settings : Out(SettingsSignature)
        What the subtractor and the depth engine use. It changes only in the clock after ``frame_start``: the
        manual registers load at that edge and the sampled estimate too.
    auto : Out(1)
        The automatic mode is selected.
    segment : Out(1)
        The segmentation view is selected (changes with the switch registers).
    estimate_held : In(1)
        The estimator's verdict: its last search had no clear minimum (changes with ``estimate``).
    mode : Out(RectificationModeSignature)
        For the screen: ``auto``, and ``held``: the verdict sampled with the estimate in use (0 in manual mode).

    Clock domain: ``sync`` (the system places it in ``pix``). Latency: the estimate is in use from the frame
    after the frame start that sampled it; a mode change takes effect with the switch registers.
    """

    def __init__(self, config=RECTIFICATION):
        self.config = config
        r = config.search_rows
        super().__init__({
            "manual": In(SettingsSignature),
            "estimate": In(range(-r, r + 1)),
            "frame_start": In(1),
            "settings": Out(SettingsSignature),
            "auto": Out(1),
            "segment": Out(1),
            "estimate_held": In(1),
            "mode": Out(RectificationModeSignature),
        })

    def elaborate(self, platform):
        m = Module()
        sampled, sampled_held = Signal.like(self.estimate), Signal()
        with m.If(self.frame_start):
            m.d.sync += [sampled.eq(self.estimate), sampled_held.eq(self.estimate_held)]
        m.d.comb += [
            self.segment.eq(self.manual.rectification == SEGMENT_CODE),
            self.auto.eq((self.manual.rectification == AUTO_CODE) | self.segment),
            self.settings.disparity.eq(self.manual.disparity),
            self.settings.rectification.eq(Mux(self.auto, sampled, self.manual.rectification)),
            self.mode.auto.eq(self.auto),
            self.mode.held.eq(self.auto & sampled_held),
        ]
        return m
