"""The board clocking's simulation model: :class:`SimClocking` (the DCM/PLL lock as a counter, the same reset tree,
clocks from the simulator)."""

from amaranth import ClockDomain, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.reset_tree import add_reset_tree

__all__ = ["SimClocking"]


class SimClocking(wiring.Component):
    """Simulation model of :class:`board.clocking.GenesysClocking`: same domains (minus the output-only ``pix90``/``mclk``),
    same reset tree, clocks from the simulator.

    The testbench (or the cocotb driver of the exported Verilog: ports ``clk``, ``pix_clk``, ``<cam>_clk``) runs
    each domain at its real frequency.

    Parameters
    ----------
    cam_domains : tuple of str
    lock_cycles : int
        ``sync`` clocks from the button's release to ``locked`` (a reset-less counter standing in for the DCM/PLL
        lock time; the board's is about 100 us, the model's default is short so simulations do not idle).

    Attributes
    ----------
    button : ``In(1)``
        The reset button, active high.
    locked : ``Out(1)``
        Rises ``lock_cycles`` ``sync`` clocks after ``button`` falls and falls again while ``button`` is high, as a
        DCM/PLL held in reset does.
    domains : list of ClockDomain
        ``sync``, ``pix`` and the camera domains: the parent adds them.

    Clock domain of the counter: ``sync`` (reset-less).

    Raises
    ------
    ValueError
        ``lock_cycles`` below 1.
    """

    button: In(1)
    locked: Out(1)

    def __init__(self, *, cam_domains=("cam_a", "cam_b"), lock_cycles=16):
        if lock_cycles < 1:
            raise ValueError("lock_cycles must be at least 1")
        self.cam_domains = tuple(cam_domains)
        self.lock_cycles = lock_cycles
        super().__init__()
        self.domain_names = ("sync", "pix", *self.cam_domains)
        #: The clock domains this block drives; the parent adds them: ``m.domains += clocking.domains``.
        self.domains = [ClockDomain(name) for name in self.domain_names]

    def elaborate(self, platform):
        m = Module()
        count = Signal(range(self.lock_cycles + 1), reset_less=True)
        with m.If(self.button):
            m.d.sync += count.eq(0)
        with m.Elif(count != self.lock_cycles):
            m.d.sync += count.eq(count + 1)
        m.d.comb += self.locked.eq((count == self.lock_cycles) & ~self.button)
        add_reset_tree(m, self.domain_names, self.button | ~self.locked)
        return m
