"""``delayed(m, signal, clocks, name)``: a signal through a chain of registers (pipeline alignment)."""

from amaranth import Signal

__all__ = ["delayed"]


def delayed(m, signal, clocks, name):
    """``signal`` through ``clocks`` registers in ``m``'s ``sync`` domain, named ``<name>_d1``, ``<name>_d2``, ...
    (``signal`` itself for 0 clocks)."""
    for i in range(clocks):
        nxt = Signal.like(signal, name=f"{name}_d{i + 1}")
        m.d.sync += nxt.eq(signal)
        signal = nxt
    return signal
