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

from amaranth import Module, Mux, Signal, signed
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
    request (the address compared with the window's start and the landed rows' end: two carry chains side by side,
    then a LUT); ``port.data`` one clock after a granted address; rows asked for from the clock after ``restart``,
    nothing granted in it.

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
        counted = Signal(count_bits)                    # the request number of the window's next row to land
        first_slot = Signal(range(n))                   # the slot of the window's first row
        # bounds[k] = (first + k) * width: where the window's k-th row starts, set in the clock after a restart
        # (``settling``: nothing is granted in it) and moved a row at a time.
        bounds = [Signal(g.addr_bits + 1, name=f"bound_{k}") for k in range(n)]
        settling = Signal()
        # limit = (first + rows of the window landed) * width: the landed rows' addresses end there.
        limit = Signal(g.addr_bits + 1)
        next_row = Signal(range(h + n + 1))             # the row asked for next
        next_slot = Signal(range(n))                    # the slot it lands in (request number mod n)
        # Registers, so that no comparison lies between them and the stream's request FIFO: ``free`` = the window's
        # first row + slots - next_row (rows that may still be asked for), ``more`` = next_row < height.
        free = Signal(range(n + 1), init=n)
        more = Signal(init=1)

        fetch = self.stream.fetch
        ask = ~self.restart & fetch.rdy & more & (free != 0)
        m.d.comb += [fetch.row.eq(next_row), fetch.en.eq(ask)]
        m.d.sync += [asked.eq(asked + ask), landed.eq(landed + self.stream.landed)]
        with m.If(ask):
            m.d.sync += [next_row.eq(next_row + 1), next_slot.eq(Mux(next_slot == n - 1, 0, next_slot + 1)),
                         more.eq(next_row != h - 1)]

        # The read: the address against every row's start at once (at or after bounds[k]: ge[k]), its row in the
        # window (j: the last k with ge[k]), its column (the difference to that row's start); granted inside the
        # window's landed rows (from bounds[0] up to limit).
        consumer = self.consumer
        diffs = [Signal(signed(g.addr_bits + 2), name=f"offset_{k}") for k in range(n)]
        m.d.comb += [d.eq(consumer.port.addr - b) for d, b in zip(diffs, bounds)]
        ge = [~d[-1] for d in diffs]
        j = Signal(range(n))
        for k in range(1, n):
            with m.If(ge[k]):
                m.d.comb += j.eq(k)
        x = Signal(range(w))
        with m.Switch(j):
            for k in range(n):
                with m.Case(k):
                    m.d.comb += x.eq(diffs[k])
        below_limit = Signal()
        m.d.comb += below_limit.eq(consumer.port.addr < limit)
        grant = consumer.request & ge[0] & below_limit & ~settling
        slot = Signal(range(n))
        m.d.comb += [
            slot.eq(Mux(first_slot + j >= n, first_slot + j - n, first_slot + j)),
            consumer.grant.eq(grant),
            self.missed.eq(consumer.request & ~grant),
            self.below.eq(~ge[0]),
            self.stream.read.slot.eq(slot),
            self.stream.read.x.eq(x),
            consumer.port.data.eq(self.stream.read.data[:g.grey_bits]),
        ]
        # A landing counts for this window once the rows asked before its restart have all landed (a negative
        # difference: rows of an earlier window pending); each one counted moves ``counted`` on with ``landed``,
        # so the difference stays between -slots and 0 however many rows the window reads.
        pending = Signal(count_bits)
        m.d.comb += pending.eq(landed - counted)
        m.d.sync += settling.eq(0)
        with m.If(self.restart):
            start = times(self.first_row, w)
            m.d.sync += [next_row.eq(self.first_row), bounds[0].eq(start), free.eq(n), more.eq(1),
                         limit.eq(start), settling.eq(1), counted.eq(asked), first_slot.eq(next_slot)]
        with m.Else():
            advance = ~settling & grant & ge[1]         # the window moves on by a row
            m.d.sync += free.eq(free + advance - ask)
            with m.If(self.stream.landed & ~pending[-1]):
                m.d.sync += [limit.eq(limit + w), counted.eq(counted + 1)]
            with m.If(settling):
                m.d.sync += [bounds[k].eq(bounds[0] + k * w) for k in range(1, n)]
            with m.Elif(grant & ge[1]):
                m.d.sync += first_slot.eq(Mux(first_slot == n - 1, 0, first_slot + 1))
                m.d.sync += [bounds[k].eq(bounds[k + 1]) for k in range(n - 1)]
                m.d.sync += bounds[n - 1].eq(bounds[n - 1] + w)
        return m
