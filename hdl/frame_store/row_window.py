"""RowWindow: a frame buffer's read port (``SharedReadSignature``: a linear address ``y * width + x``, the grey value
a clock later, ``request``/``grant``) served from a read stream of the frame store, for a consumer that reads its
rows in order from a first row it names at its start (docs/frame_store.md, "Readers").

At ``restart`` the window starts at ``first_row``: it asks the stream for rows ``first_row``, ``first_row + 1``, ...
while they are fewer than ``slots`` rows ahead of the window's first row (and inside the image). A read is
granted when its address falls in the window (the first row's address ``first * width`` up to ``slots`` rows on)
and its row has landed; the address is then the row's slot and column in the stream's ring. A granted read of a
row after the window's first moves the window on by a row, so the slot of the row left behind is asked for the
next row: the consumer reads a row any number of times (a panel shows a buffer row on ``scale`` lines; a clamped
row offset repeats the first and the last row), then the next, and never goes back before its next ``restart``.

A read outside the window, or of a row not yet landed, is not granted (``missed`` pulses): the depth engine waits
for its grant; the display, always granted from the block-RAM buffer, must have asked early enough that it never
misses (the window holds the row shown and the next ones: docs/frame_store.md, "Arbitration").
"""

from amaranth import Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.depth.ports import SharedReadSignature
from hdl.shift_add import times
from spec.sensor import SENSOR

from .row_reader import RowStreamSignature

__all__ = ["RowWindow"]


class RowWindow(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
        ``buf_width`` x ``buf_height``, ``grey_bits`` (the stream's byte's low bits).
    slots : int
        The stream's ring slots: rows in the window.

    Attributes
    ----------
    consumer : ``In(SharedReadSignature(geometry))``
    restart : ``In(1)``
        The consumer's start (a frame, a map); ``first_row`` is sampled with it.
    first_row : ``In(range(buf_height))``
    stream : ``Out(RowStreamSignature(buf_height, buf_width, slots))``
    missed : ``Out(1)``
        A request not granted in this clock.
    below : ``Out(1)``
        The request's address lies before the window's first row (a read this window will never grant).

    Clock domain: ``sync`` (the parent renames it to the read domain). Latency: ``grant`` combinational from the
    request; ``port.data`` one clock after a granted address; rows asked for from the clock after ``restart``.

    Raises
    ------
    ValueError
        ``slots`` below 2, ``grey_bits`` above 8.
    """

    def __init__(self, geometry=SENSOR, slots=4):
        if slots < 2:
            raise ValueError(f"a window needs at least 2 slots, got {slots}")
        if geometry.grey_bits > 8:
            raise ValueError(f"the stream's bytes hold at most 8 bits of grey, got {geometry.grey_bits}")
        self.geometry, self.slots = geometry, slots
        h, w = geometry.buf_height, geometry.buf_width
        super().__init__({
            "consumer": In(SharedReadSignature(geometry)),
            "restart": In(1),
            "first_row": In(range(h)),
            "stream": Out(RowStreamSignature(h, w, slots)),
            "missed": Out(1),
            "below": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        g, n = self.geometry, self.slots
        h, w = g.buf_height, g.buf_width
        count_bits = (4 * n).bit_length() + 1          # request and landing counts, compared modulo 2**count_bits
        asked, landed = Signal(count_bits), Signal(count_bits)
        first = Signal(range(h + n))                    # the window's first row
        first_index = Signal(count_bits)                # its request number
        first_slot = Signal(range(n))                   # its slot
        base = Signal(g.addr_bits + 1)                  # first * width
        next_row = Signal(range(h + n + 1))             # the row asked for next
        next_slot = Signal(range(n))                    # the slot it lands in (request number mod n)

        fetch = self.stream.fetch
        ask = ~self.restart & fetch.rdy & (next_row < h) & (next_row < first + n)
        m.d.comb += [fetch.row.eq(next_row), fetch.en.eq(ask)]
        m.d.sync += [asked.eq(asked + ask), landed.eq(landed + self.stream.landed)]
        with m.If(ask):
            m.d.sync += [next_row.eq(next_row + 1), next_slot.eq(Mux(next_slot == n - 1, 0, next_slot + 1))]

        # The read: its row in the window (j), its column, whether it has landed.
        consumer = self.consumer
        offset = Signal(g.addr_bits + 1)
        m.d.comb += offset.eq(consumer.port.addr - base)
        j = Signal(range(n))
        for k in range(1, n):
            with m.If(offset >= k * w):
                m.d.comb += j.eq(k)
        x = Signal(range(w))
        m.d.comb += x.eq(offset - times(j, w))
        in_window = offset < n * w
        ready = Signal(count_bits)                      # rows of the window landed (mod 2**count_bits)
        m.d.comb += ready.eq(landed - first_index)
        landed_ok = ~ready[-1] & (ready > j)            # a negative difference: rows of an earlier window pending
        grant = consumer.request & in_window & landed_ok
        slot = Signal(range(n))
        m.d.comb += [
            slot.eq(Mux(first_slot + j >= n, first_slot + j - n, first_slot + j)),
            consumer.grant.eq(grant),
            self.missed.eq(consumer.request & ~grant),
            self.below.eq(consumer.port.addr < base),
            self.stream.read.slot.eq(slot),
            self.stream.read.x.eq(x),
            consumer.port.data.eq(self.stream.read.data[:g.grey_bits]),
        ]
        with m.If(self.restart):
            m.d.sync += [first.eq(self.first_row), next_row.eq(self.first_row), base.eq(times(self.first_row, w)),
                         first_index.eq(asked), first_slot.eq(next_slot)]
        with m.Elif(grant & (j != 0)):
            m.d.sync += [first.eq(first + 1), base.eq(base + w), first_index.eq(first_index + 1),
                         first_slot.eq(Mux(first_slot == n - 1, 0, first_slot + 1))]
        return m
