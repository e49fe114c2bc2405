"""``times(value, k)``: ``value * k`` for a constant ``k >= 0`` as a sum of shifted copies of ``value``.

Synthesis maps a ``*`` between a signal and a constant to a DSP48E without its input or output registers;
the few shifted terms of a small constant (``buf_width`` = 400 is three: ``2**8 + 2**7 + 2**4``)
are adders in the fabric instead. The result has the shape Amaranth gives the sum (wide enough for every
value, signed if ``value`` is).
"""

from amaranth.hdl import Const, Value

__all__ = ["times"]


def times(value, k):
    """``value * k`` as shift-adds; ``k`` a non-negative integer."""
    if not isinstance(k, int) or k < 0:
        raise ValueError(f"the constant factor must be a non-negative integer, not {k!r}")
    value = Value.cast(value)
    terms = [value.shift_left(i) for i in range(k.bit_length()) if k >> i & 1]
    if not terms:
        return Const(0, 1)
    total = terms[0]
    for term in terms[1:]:
        total = total + term
    return total
