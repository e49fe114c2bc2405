"""Slide-switch controls of the disparity map generator (thesis 4.3, figures 4.5 and 4.6).

The eight slide switches SW7..SW0 set two 7-bit registers: with SW7 = 1 the value on SW6..SW0 is the
**disparity** (horizontal shift of the left image), with SW7 = 0 it is the **rectification** (vertical shift).
Each register keeps its value while the other one is selected, so the user sets one, flips SW7 and sets the
other. Both start at 0 after reset (the thesis's figure 4.13).

Signed rectification: SW6..SW0 are the rectification in two's complement, -64..63 buffer rows.
0..63 (SW6 = 0) mean what they mean in the thesis (the left image read that many rows lower: its figures use
3, 4 and 5); SW6 = 1 gives -64..-1 (the left image read rows higher: a left camera mounted lower than the
right one), e.g. 1111111 = -1, 1110000 = -16, 1000000 = -64. The disparity stays unsigned, 0..127.

Clock domain: ``domain`` (default ``sync``; the top level passes ``domain="pix"`` or uses ``DomainRenamer``).
``sw`` is asynchronous (mechanical switches): every bit goes through an :class:`amaranth.lib.cdc.FFSynchronizer`
of ``stages`` flip-flops before any logic looks at it.

No tearing: the synchronised value is first copied into a *pending* register (the one selected by SW7); the
outputs ``settings.disparity`` and ``settings.rectification`` load the pending registers only on the clock edge
that ends the ``frame_start`` cycle, so the datapath sees one value for the whole frame.

Latency: call edge 0 the first clock edge after the switches change. Edge 0 samples them into the first
synchroniser stage (metastability may resolve to the old value and delay everything below by one edge); the
pending register holds the new value after edge ``stages``; the outputs load it on the first edge at or after
edge ``stages + 1`` that ends a ``frame_start`` cycle. They then hold it from raster position (1, 0) of that
frame until position (0, 0) of the next one inclusive. A user moving a switch during a frame therefore sees the
change from the next frame on, never within a frame (a change in the last ``stages + 1`` clocks before
``frame_start`` waits one more frame).

No debouncing: a bouncing switch or bits changing at slightly different times can leave a transient value in
the pending register; only the value present at the frame_start edge is shown, and the settled value
overwrites any transient ``stages + 1`` clocks later, so at worst one frame shows an intermediate value.
"""

from amaranth import Module, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.cdc import FFSynchronizer
from amaranth.lib.wiring import In, Out

__all__ = ["SWITCH_VALUE_BITS", "RECTIFICATION_RANGE", "SettingsSignature", "SwitchControl"]

#: Width of the disparity and rectification registers: the value switches SW6..SW0.
SWITCH_VALUE_BITS = 7

#: The rectification values the switches give: ``SWITCH_VALUE_BITS`` bits of two's complement.
RECTIFICATION_RANGE = range(-2 ** (SWITCH_VALUE_BITS - 1), 2 ** (SWITCH_VALUE_BITS - 1))

#: The two registers the switches set, as their source drives them: ``disparity`` (horizontal shift of the left
#: image, unsigned) and ``rectification`` (vertical shift, signed: the left row read is y + rectification), each
#: ``SWITCH_VALUE_BITS`` wide.
SettingsSignature = wiring.Signature({
    "disparity": Out(SWITCH_VALUE_BITS),
    "rectification": Out(signed(SWITCH_VALUE_BITS)),
})


class SwitchControl(wiring.Component):
    """``sw[8]`` (asynchronous) -> ``settings.disparity`` (SW7 = 1) and ``settings.rectification`` (SW7 = 0),
    updated only when ``frame_start`` is high. See the module docstring for the latency.

    Parameters
    ----------
    domain : str
        Clock domain of everything after the synchroniser.
    stages : int
        Synchroniser flip-flops per switch (at least 2).

    Raises
    ------
    ValueError
        ``stages`` below 2.
    """

    sw: In(SWITCH_VALUE_BITS + 1)
    frame_start: In(1)
    settings: Out(SettingsSignature)

    def __init__(self, *, domain="sync", stages=2):
        if stages < 2:
            raise ValueError(f"a synchroniser needs at least 2 stages, not {stages}")
        self.domain = domain
        self.stages = stages
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        sw_sync = Signal.like(self.sw, name="sw_sync")
        m.submodules.sw_synchroniser = FFSynchronizer(self.sw, sw_sync, o_domain=self.domain,
                                                      stages=self.stages)
        select_disparity = sw_sync[SWITCH_VALUE_BITS]
        value = sw_sync[:SWITCH_VALUE_BITS]

        disparity_pending = Signal(SWITCH_VALUE_BITS)
        rectification_pending = Signal(SWITCH_VALUE_BITS)
        with m.If(select_disparity):
            m.d[self.domain] += disparity_pending.eq(value)
        with m.Else():
            m.d[self.domain] += rectification_pending.eq(value)

        with m.If(self.frame_start):
            m.d[self.domain] += [
                self.settings.disparity.eq(disparity_pending),
                self.settings.rectification.eq(rectification_pending),
            ]
        return m
