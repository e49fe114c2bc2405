"""Subpixel: the winner's code, its fraction from the equiangular fit, and the validity rule (docs/depth.md,
"winner" and "sub-pixel")."""

from amaranth import Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from spec.sensor import SENSOR

__all__ = ["Subpixel"]


class Subpixel(wiring.Component):
    """The code of one pixel from its winner d* and the summed costs a = S(d* - 1), b = S(d*), c = S(d* + 1):
    2**F d* + q with q = floor((2**F (a - c) + e) / (2 e)), e = max(a, c) - b (the equiangular fit rounded half
    up, -2**(F - 1) <= q <= 2**(F - 1)); q = 0 for d* = 0; the invalid code D 2**F when b > ``max_cost``,
    d* = D - 1 or ``ambiguous``. The quotient is found by restoring division, one quotient bit per clock (no long
    combinational divider): Q = q + 2**(F - 1) = floor((2**F (n + e) + e) / (2 e)), n = a - c, bits F..0.

    Parameters
    ----------
    config : DepthConfig
        D, ``max_cost``, ``fraction_bits`` (F; 0: whole pixels, no fit).
    width : int
        Image width (the column's range).

    Ports
    -----
    valid, x, d, below, best, above : In
        One pixel: its column, d*, S(d* - 1) (ignored for d* = 0), S(d*), S(d* + 1) (ignored for d* = D - 1).
        The fit needs b < a (ties go to the smaller d) and b <= c, as the winner guarantees.
    ambiguous : In(1)
        The confidence rule failed (64 S* > ``uniqueness`` S2): the code is invalid.
    out_valid, out_x, out_d, code : Out
        The pixel's column, d* and code, :meth:`latency` clocks after ``valid``.

    Clock domain: ``sync``. A pixel may enter every clock. Latency F + 6 clocks (1 for F = 0): max(a, c) and
    a - c; e and (a - c) + max(a, c); n + e; the numerator 2**F (n + e) + e; F + 1 division steps; the code.
    """

    def __init__(self, config=DEPTH, width=SENSOR.buf_width):
        self.config, self.width = config, width
        super().__init__({
            "valid": In(1),
            "x": In(range(width)),
            "d": In(range(config.disparities)),
            "below": In(config.sum_bits),
            "best": In(config.sum_bits),
            "above": In(config.sum_bits),
            "ambiguous": In(1),
            "out_valid": Out(1),
            "out_x": Out(range(width)),
            "out_d": Out(range(config.disparities)),
            "code": Out(config.code_bits),
        })

    @classmethod
    def latency(cls, config=DEPTH):
        return 1 if config.fraction_bits == 0 else config.fraction_bits + 6

    def elaborate(self, platform):
        m = Module()
        cfg, F = self.config, self.config.fraction_bits
        invalid = (self.best > cfg.max_cost) | (self.d == cfg.disparities - 1) | self.ambiguous
        if F == 0:
            m.d.sync += [self.out_valid.eq(self.valid), self.out_x.eq(self.x), self.out_d.eq(self.d),
                         self.code.eq(Mux(invalid, cfg.invalid, self.d))]
            return m

        sb = cfg.sum_bits
        # Carried along: valid, x, d*, whether the code is invalid or the fraction zero (d* = 0), and 2**F d*.
        state = {"valid": (self.valid, 1), "x": (self.x, range(self.width)),
                 "d": (self.d, range(cfg.disparities)), "invalid": (invalid, 1),
                 "edge": (self.d == 0, 1), "base": (self.d * cfg.fraction, cfg.code_bits)}
        regs = {}

        def carry(stage):
            nonlocal regs
            new = {}
            for key, (value, shape) in state.items():
                reg = Signal(shape, name=f"sub{stage}_{key}")
                m.d.sync += reg.eq(regs[key] if regs else value)
                new[key] = reg
            regs = new

        # 1: hi = max(a, c), n = a - c.
        carry(1)
        hi, n, b1 = Signal(sb), Signal(signed(sb + 1)), Signal(sb)
        m.d.sync += [hi.eq(Mux(self.above > self.below, self.above, self.below)),
                     n.eq(self.below - self.above), b1.eq(self.best)]
        # 2: e = hi - b, nh = n + hi.
        carry(2)
        e, nh, b2 = Signal(sb), Signal(signed(sb + 2)), Signal(sb)
        m.d.sync += [e.eq(hi - b1), nh.eq(n + hi), b2.eq(b1)]
        # 3: t = n + e = nh - b (0 <= t <= 2 e).
        carry(3)
        t, e3 = Signal(sb + 1), Signal(sb)
        m.d.sync += [t.eq(nh - b2), e3.eq(e)]
        # 4: the numerator 2**F t + e; the divisor is 2 e.
        carry(4)
        num_bits = (((2 << F) + 1) * (2 * cfg.path_max)).bit_length()
        rem, e4 = Signal(num_bits), Signal(sb)
        m.d.sync += [rem.eq((t << F) + e3), e4.eq(e3)]
        # 5 .. F + 5: restoring division, quotient bit k = F .. 0.
        quotient = Signal(F + 1)
        for k in range(F, -1, -1):
            carry(5 + F - k)
            step = Signal(num_bits + 1, name=f"sub_step{k}")
            new_rem, new_q, new_e = (Signal(num_bits, name=f"sub_rem{k}"), Signal(F + 1, name=f"sub_q{k}"),
                                     Signal(sb, name=f"sub_e{k}"))
            m.d.comb += step.eq(rem - (e4 << (k + 1)))
            fits = ~step[-1]
            m.d.sync += [new_rem.eq(Mux(fits, step[:num_bits], rem)),
                         new_q.eq(quotient | (fits << k)), new_e.eq(e4)]
            rem, quotient, e4 = new_rem, new_q, new_e
        # The code (stage F + 6): 2**F d* + Q - 2**(F - 1), 0 for d* = 0 (and between pixels), or invalid. Q is
        # at most 2**F whenever the inputs keep the contract; clamped anyway, so that no input can make a code
        # outside its range (sim/formal/harnesses/depth_codes.py).
        fraction = Mux(quotient > cfg.fraction, cfg.fraction, quotient)
        m.d.sync += [
            self.out_valid.eq(regs["valid"]),
            self.out_x.eq(regs["x"]),
            self.out_d.eq(regs["d"]),
            self.code.eq(Mux(regs["invalid"], cfg.invalid,
                             Mux(regs["edge"] | ~regs["valid"], 0,
                                 regs["base"] + fraction - (1 << (F - 1))))),
        ]
        return m
