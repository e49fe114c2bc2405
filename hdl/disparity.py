"""Disparity subtractor: |left(x + disparity, y + rectification) - right(x, y)|, quantised (thesis 4.3, fig. 4.7).

For each input pixel (buffer coordinates ``x``, ``y`` of the right image) the block reads the right buffer at
``A = y * buf_width + x`` and the left buffer at the shifted position ``(x + disparity, y + rectification)``,
takes the absolute difference of the two grey values and quantises it through a threshold table:
``level`` = the number of thresholds ``t`` with ``|L - R| >= t`` (default ``spec.display.DIFF_THRESHOLDS``,
2/4/8/16 -> levels 0..4; the order of the table does not matter, a repeated threshold makes a level
unreachable).

``rectification`` is signed (hdl/switches.py): a negative value reads the left image higher.

No data, never wrapping: where ``x + disparity >= buf_width``, ``y + rectification >= buf_height`` or
``y + rectification < 0`` the shifted pixel is outside the left image. The thesis's address arithmetic (figure 4.7) would wrap into the next
row or past the end of the buffer there; this block instead raises ``no_data`` (``level`` is then 0) and drives
``left.addr`` to 0, so the left port is never given an address outside the image. On clocks without a valid
pixel both ``left.addr`` and ``right.addr`` are 0, so neither port ever reads outside its buffer.

No multiplier per pixel: the caller supplies the right pixel's address ``addr`` (= ``y * buf_width + x``) from
a running counter along with ``x`` and ``y``; the left address is ``addr + offset`` with the per-frame constant
``offset = rectification * buf_width + disparity`` (modulo ``2**addr_bits``: the sum is the true address
whenever the shifted pixel is inside the image), computed in two registered steps from the (quasi-static)
``disparity`` and ``rectification`` inputs.

Clock domain: ``sync`` (single domain; the parent places it in ``pix``).

Pipeline and latency (one pixel per clock, any pattern of ``valid``):

=======  ================================================================================================
clock    what happens
=======  ================================================================================================
n        inputs ``valid``, ``x``, ``y``, ``addr``
n + 1    ``left.addr``, ``right.addr`` registered (to the frame buffers' read ports)
n + 2    ``left.data``, ``right.data`` expected here (the frame buffers' one-clock read latency)
n + 3    their signed difference ``L - R`` registered (one carry chain after the read)
n + 4    ``level``, ``no_data``, ``out_valid`` registered: **latency 4 clocks** from the inputs
=======  ================================================================================================

``next_no_data`` and ``next_valid`` are ``no_data`` and ``out_valid`` one clock ahead (registers, at n + 3), for a
consumer that decides what to show a clock before the level arrives.

``settings`` (``disparity``, ``rectification``) must be stable for :data:`SETTLE_CLOCKS` clocks before the first
input pixel that uses them (the compositor guarantees this: the switch registers change only at ``frame_start``, at
least a line before the first disparity pixel).
"""

from amaranth import Cat, Module, Mux, Signal, signed
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.frame_buffer import FrameBufferReadSignature
from spec.display import DIFF_THRESHOLDS
from spec.sensor import SENSOR
from hdl.switches import SettingsSignature
from hdl.shift_add import times

__all__ = ["DisparitySubtractor", "check_thresholds", "LATENCY", "SETTLE_CLOCKS"]

#: Clocks from the inputs to ``level``/``no_data``/``out_valid``.
LATENCY = 4
#: Clocks ``settings`` must be stable before an input pixel that uses them.
SETTLE_CLOCKS = 2


def check_thresholds(thresholds, grey_bits):
    """The threshold table as a tuple of ints; ``ValueError`` unless every entry is in 0 .. 2**grey_bits
    (a threshold of 2**grey_bits is never reached by a difference of grey_bits-bit values)."""
    try:
        table = tuple(int(t) for t in thresholds)
    except (TypeError, ValueError):
        raise ValueError(f"threshold table must be a sequence of integers, not {thresholds!r}") from None
    if any(t != t_in for t, t_in in zip(table, thresholds)):
        raise ValueError(f"threshold table must hold integers, not {thresholds!r}")
    limit = 2 ** grey_bits
    if not table or any(t < 0 or t > limit for t in table):
        raise ValueError(f"threshold table {table!r} must be non-empty with entries in 0..{limit}")
    return table


class DisparitySubtractor(wiring.Component):
    """Quantised ``|L(x + disparity, y + rectification) - R(x, y)|`` with no-data marking; latency 4 clocks.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
        Buffer size and grey depth.
    thresholds : sequence of int
        The threshold table (:func:`check_thresholds`).

    Attributes
    ----------
    valid, x, y, addr : In
        The right-image pixel (``addr = y * buf_width + x``).
    settings : ``In(SettingsSignature)``
    left, right : ``Out(FrameBufferReadSignature(geometry))``
    level, no_data, out_valid : Out
        The quantised difference of the pixel given :data:`LATENCY` clocks earlier.
    next_no_data, next_valid : Out
        ``no_data`` and ``out_valid`` one clock ahead (registered: of the pixel given ``LATENCY - 1`` clocks
        earlier).

    Raises
    ------
    ValueError
        A bad threshold table.
    """

    def __init__(self, geometry=SENSOR, thresholds=DIFF_THRESHOLDS):
        self.geometry = geometry
        self.thresholds = check_thresholds(thresholds, geometry.grey_bits)
        g = geometry
        super().__init__({
            "valid": In(1),
            "x": In(range(g.buf_width)),
            "y": In(range(g.buf_height)),
            "addr": In(g.addr_bits),
            "settings": In(SettingsSignature),
            "left": Out(FrameBufferReadSignature(g)),
            "right": Out(FrameBufferReadSignature(g)),
            "level": Out(range(len(self.thresholds) + 1)),
            "no_data": Out(1),
            "out_valid": Out(1),
            "next_no_data": Out(1),
            "next_valid": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        g = self.geometry
        w, h = g.buf_width, g.buf_height

        # Per-frame constants (quasi-static inputs), two registered steps: SETTLE_CLOCKS = 2.
        row_offset = Signal(g.addr_bits)            # rectification * buf_width (mod 2**addr_bits)
        disparity_q = Signal(len(self.settings.disparity))
        offset = Signal(g.addr_bits)                # rectification * buf_width + disparity (mod 2**addr_bits)
        # x + disparity >= w  <=>  x >= x_limit, with x_limit = max(w - disparity, 0); the same for y below;
        # y + rectification < 0  <=>  y < y_first, with y_first = min(max(-rectification, 0), h).
        r = self.settings.rectification
        x_limit = Signal(range(w + 1))
        y_limit = Signal(range(h + 1))
        y_first = Signal(range(h + 1))
        m.d.sync += [
            row_offset.eq(times(r, w)),
            disparity_q.eq(self.settings.disparity),
            offset.eq(row_offset + disparity_q),
            x_limit.eq(Mux(self.settings.disparity >= w, 0, w - self.settings.disparity)),
            y_limit.eq(Mux(r >= h, 0, Mux(r > 0, h - r, h))),
            y_first.eq(Mux(r <= -h, h, Mux(r < 0, -r, 0))),
        ]

        # Clock n -> n + 1: addresses and the no-data flag.
        no_data_1 = Signal()
        valid_1 = Signal()
        outside = (self.x >= x_limit) | (self.y >= y_limit) | (self.y < y_first)
        m.d.sync += [
            valid_1.eq(self.valid),
            no_data_1.eq(outside),
            # Between valid pixels both ports idle at address 0: the per-frame offset may still be settling
            # and the caller's address counter may sit past the buffer's end (sim/formal/harnesses/disparity.py).
            self.right.addr.eq(Mux(self.valid, self.addr, 0)),
            self.left.addr.eq(Mux(outside | ~self.valid, 0, self.addr + offset)),
        ]

        # Clock n + 1 -> n + 2: the frame buffers read; only the flags travel along.
        no_data_2 = Signal()
        valid_2 = Signal()
        m.d.sync += [no_data_2.eq(no_data_1), valid_2.eq(valid_1)]

        # Clock n + 2 -> n + 3: the signed difference L - R of the read data (thesis: subtract the smaller from the
        # larger, then compare with each threshold), registered: one carry chain after the read.
        diff = Signal(signed(g.grey_bits + 1))
        no_data_3 = Signal()
        valid_3 = Signal()
        m.d.sync += [
            diff.eq(self.left.data - self.right.data),
            no_data_3.eq(no_data_2),
            valid_3.eq(valid_2),
        ]
        m.d.comb += [self.next_no_data.eq(no_data_3), self.next_valid.eq(valid_3)]

        # Clock n + 3 -> n + 4: the level of |L - R| from the registered difference: its one's-complement magnitude
        # (|L - R| for L >= R, |L - R| - 1 below: an XOR with the sign, no carry chain), each threshold's comparison
        # with it side by side, and the number of comparisons met as a table of their bits (one LUT a level bit),
        # not an adder: the comparisons and one LUT, whatever the grey width.
        sign = diff[-1]
        mag = Signal(g.grey_bits)
        m.d.comb += mag.eq(diff[:-1] ^ sign.replicate(g.grey_bits))
        met = Signal(len(self.thresholds))
        m.d.comb += met.eq(Cat(Mux(sign, mag >= t - 1, mag >= t) for t in self.thresholds))
        count = Signal.like(self.level)
        with m.Switch(met):
            for bits in range(2 ** len(self.thresholds)):
                with m.Case(bits):
                    m.d.comb += count.eq(bin(bits).count("1"))
        m.d.sync += [
            self.level.eq(Mux(no_data_3, 0, count)),
            self.no_data.eq(no_data_3),
            self.out_valid.eq(valid_3),
        ]
        return m
