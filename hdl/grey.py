"""RGB565 -> 5-bit grey: ``grey5 = (R5 + (G6 >> 1) + B5) // 3``, exact (spec "Camera driver", thesis 4.2.1).

The sum ``s = R5 + (G6 >> 1) + B5`` is at most 31 + 31 + 31 = 93. The division by 3 is done as
``(s * 43) >> 7``, which equals ``s // 3`` for every ``s < 128``: ``43 / 128 = 1/3 + 1/384``, so
``s * 43 / 128 = s/3 + s/384`` and the extra ``s/384 < 1/3`` never carries past the next integer (the
fractional part of ``s/3`` is at most 2/3). ``tests/test_downscaler.py`` also checks the RTL against the
golden ``//`` for all 2^16 inputs.

Clock domain: none (combinational). Latency: 0.
"""

from amaranth import Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.shift_add import times

__all__ = ["Grey"]


class Grey(wiring.Component):
    """RGB565 ``pixel`` (R in bits 15:11, G 10:5, B 4:0) to its 5-bit ``grey``; see the module docstring.

    Attributes
    ----------
    pixel : ``In(16)``
    grey : ``Out(5)``
    """

    pixel: In(16)
    grey: Out(5)

    def elaborate(self, platform):
        m = Module()
        r5 = self.pixel[11:16]
        g6 = self.pixel[5:11]
        b5 = self.pixel[0:5]
        total = Signal(7)
        m.d.comb += [
            total.eq(r5 + g6[1:] + b5),
            self.grey.eq(times(total, 43) >> 7),
        ]
        return m
