"""RowWindow: a frame buffer's read port (``SharedReadSignature``: a linear address ``y * width + x``, the grey value
a clock later, ``request``/``grant``) served from a read stream of the frame store, for a consumer that reads every
``step``-th row in order from a first row it names at its start (docs/frame_store.md, "Readers").

At ``restart`` the window starts at ``first_row`` with ``row_step`` (the step: 1 reads every row, 2 every second
row, as a half-size panel does): it asks the stream for rows ``first_row``, ``first_row + step``, ... -- only
those -- while they are fewer than ``slots`` of them ahead of the window's first row (and inside the image). A read
is granted when its address falls in one of the window's rows (the first row's address ``first * width``, then
every ``step * width`` on, ``width`` addresses each, up to ``slots`` rows) and that row has landed; the address is
then the row's slot and column in the stream's ring. A read of a row the step skips is refused. A granted read of a
row after the window's first moves the window on by a row, so the slot of the row left behind is asked for the
next: the consumer reads a row any number of times (a panel shows a buffer row on ``scale`` lines; a clamped row
offset repeats the first and the last row), then the next, and never goes back before its next ``restart``.

A read outside the window, of a skipped row, or of a row not yet landed, is not granted (``missed`` pulses): the
depth engine waits for its grant; the display, always granted from the block-RAM buffer, must have asked early
enough that it never misses (the window holds the row shown and the next ones: docs/frame_store.md,
"Arbitration").

The restart, its first row and step are registered as they come in (they change once a frame or a map): the window
starts in the clock after ``restart`` (*restarting*: nothing granted, nothing asked), sets its rows' starts from the
first's in the clock after that (*settling*: nothing landed yet, so nothing granted), and asks for rows from then on.
So nothing but a register lies between the consumer's start and the window's counters; likewise the slot a move
leaves is counted free (may be asked for again) a clock after the move, so no address comparison lies before that
count's adder.
"""

from amaranth import Cat, Const, Module, Mux, Signal, signed
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
    max_step : int
        The largest ``row_step``; 1: the window reads every row and has no ``row_step`` port (nor the skipped
        rows' comparisons).

    Attributes
    ----------
    consumer : ``In(SharedReadSignature(geometry))``
    restart : ``In(1)``
        The consumer's start (a frame, a map); ``first_row`` and ``row_step`` are sampled with it.
    first_row : ``In(range(buf_height))``
    row_step : ``In(range(1, max_step + 1))``
        Only with ``max_step`` above 1: the step, 1 to ``max_step`` (0 is not a step).
    stream : ``Out(RowStreamSignature(buf_height, buf_width, slots))``
    missed : ``Out(1)``
        A request not granted in this clock.
    below : ``Out(1)``
        The request's address lies before the window's first row (a read this window will never grant).

    Clock domain: ``sync`` (the parent renames it to the read domain). Latency: ``grant`` combinational from the
    request (the address's high bits compared with the window's start and the landed rows' end: two carry chains
    side by side, then a LUT; with ``max_step`` above 1 also each row's end in its low bits, side by side: a short
    carry chain's top sum bit, and a second LUT); ``port.data`` one clock after a granted address; rows asked for from the second clock after ``restart``, nothing granted in
    the first.

    Raises
    ------
    ValueError
        ``slots`` below 2, ``grey_bits`` above 8, ``max_step`` below 1.
    """

    def __init__(self, geometry=SENSOR, slots=4, max_step=1):
        if slots < 2:
            raise ValueError(f"a window needs at least 2 slots, got {slots}")
        if geometry.grey_bits > 8:
            raise ValueError(f"the stream's bytes hold at most 8 bits of grey, got {geometry.grey_bits}")
        if not isinstance(max_step, int) or max_step < 1:
            raise ValueError(f"the largest row step must be a positive integer, got {max_step!r}")
        self.geometry, self.slots, self.max_step = geometry, slots, max_step
        h, w = geometry.buf_height, geometry.buf_width
        step = {"row_step": In(range(1, max_step + 1), init=1)} if max_step > 1 else {}
        super().__init__({
            "consumer": In(SharedReadSignature(geometry)),
            "restart": In(1),
            "first_row": In(range(h)),
            **step,
            "stream": Out(RowStreamSignature(h, w, slots)),
            "missed": Out(1),
            "below": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        g, n, s = self.geometry, self.slots, self.max_step
        h, w = g.buf_height, g.buf_width
        count_bits = (4 * n).bit_length() + 1          # request and landing counts, compared modulo 2**count_bits
        asked, landed = Signal(count_bits), Signal(count_bits)
        counted = Signal(count_bits)                    # the request number of the window's next row to land
        first_slot = Signal(range(n))                   # the slot of the window's first row

        # The restart, the first row and the step, registered: the window starts in ``restarting`` and sets its
        # rows' starts in ``settling``.
        restarting, settling = Signal(), Signal()
        first = Signal(range(h))
        m.d.sync += [restarting.eq(self.restart), settling.eq(restarting)]
        with m.If(self.restart):
            m.d.sync += first.eq(self.first_row)
        step, offsets = self._step(m)
        stride = offsets[1]

        # Every row start and row end is a multiple of the width, so of ``unit`` = 2**tz (the width's trailing zero
        # bits): they are kept and compared in units (an address at or past a multiple of the unit is so in its
        # high bits alone); ``wu`` is the width in units.
        tz, wu = self._unit()
        # bounds[k] = (first + k * step) * wu: where the window's k-th row starts, in units, bounds[0] set in
        # ``restarting``, the others in ``settling`` (nothing is granted in either), all moved a row at a time.
        span = (h + n * s) * wu                         # above every row start the window reaches
        bounds = [Signal(range(span + 1), name=f"bound_{k}") for k in range(n)]
        # limit = the end of the window's last landed row (its first row's start while none has landed), in units;
        # it moves by ``limit_step``: ``wu`` at the first landing, a row's ``stride`` at the others.
        limit = Signal(range(span + 1))
        limit_step = Signal(range(s * wu + 1)) if s > 1 else Const(wu)
        next_row = Signal(range(h + 2 * s))             # the row asked for next
        after = Signal(range(h + 2 * s))                # the one after it (next_row + step)
        next_slot = Signal(range(n))                    # the slot it lands in (request number mod n)
        # Registers, so that no comparison lies between them and the stream's request FIFO: ``free`` = rows that may
        # still be asked for (slots less the rows asked beyond the window's first, the window's last move counted a
        # clock late), ``more`` = next_row < height.
        free = Signal(range(n + 1), init=n)
        more = Signal(init=1)

        fetch = self.stream.fetch
        ask = ~restarting & fetch.rdy & more & (free != 0)
        m.d.comb += [fetch.row.eq(next_row), fetch.en.eq(ask)]
        m.d.sync += [asked.eq(asked + ask), landed.eq(landed + self.stream.landed)]
        with m.If(ask):
            m.d.sync += [next_row.eq(after), after.eq(after + step), more.eq(after < h),
                         next_slot.eq(Mux(next_slot == n - 1, 0, next_slot + 1))]

        tails = self._tails() if s > 1 else None
        grant, ge = self._read(m, bounds, limit, tails, restarting, first_slot)
        # A landing counts for this window once the rows asked before its restart have all landed (a negative
        # difference: rows of an earlier window pending); each one counted moves ``counted`` on with ``landed``,
        # so the difference stays between -slots and 0 however many rows the window reads.
        pending = Signal(count_bits)
        m.d.comb += pending.eq(landed - counted)
        advance, advanced = Signal(), Signal()
        m.d.comb += advance.eq(grant & ge[1])
        m.d.sync += advanced.eq(advance)
        with m.If(restarting):
            start = times(first, wu)
            m.d.sync += [next_row.eq(first), after.eq(first + step), bounds[0].eq(start), free.eq(n), more.eq(1),
                         limit.eq(start), counted.eq(asked), first_slot.eq(next_slot)]
            if s > 1:
                m.d.sync += limit_step.eq(wu)
        with m.Else():
            # The window moves on by a row (``advance``); the slot it leaves is counted free a clock later
            # (``advanced``), so no comparison of the address lies before the count's adder.
            m.d.sync += free.eq(free + advanced - ask)
            with m.If(self.stream.landed & ~pending[-1]):
                m.d.sync += [limit.eq(limit + limit_step), counted.eq(counted + 1)]
                if s > 1:
                    m.d.sync += limit_step.eq(stride)
            self._move(m, bounds, tails, offsets, stride, settling, advance)
            with m.If(~settling & advance):
                m.d.sync += first_slot.eq(Mux(first_slot == n - 1, 0, first_slot + 1))
        return m

    def _move(self, m, bounds, tails, offsets, stride, settling, advance):
        """The rows' starts after ``settling`` (bounds[0] + offsets[k]) or a move (bounds[k + 1]; the last
        bounds[n - 1] + stride): for k >= 1 one sum whose operands are picked (no multiplexer after the adder); with
        a step, ``tails`` with them."""
        n = self.slots
        _, wu = self._unit()
        moved = [bounds[1]] + [Mux(settling, bounds[0], bounds[k + 1] if k < n - 1 else bounds[k])
                               + Mux(settling, offsets[k], 0 if k < n - 1 else stride) for k in range(1, n)]
        if tails is not None:
            # tails[k]: the low bits of the k-th row's end (bounds[k] + wu), set with the row's start.
            ends = [Mux(settling, bounds[0], bounds[1]) + wu] + [moved[k] + wu for k in range(1, n - 1)]
            with m.If(settling | advance):
                m.d.sync += [t.eq(e) for t, e in zip(tails, ends)]
        with m.If(settling):
            m.d.sync += [bounds[k].eq(moved[k]) for k in range(1, n)]
        with m.Elif(advance):
            m.d.sync += [bounds[k].eq(moved[k]) for k in range(n)]

    def _unit(self):
        """``(tz, wu)``: the width's trailing zero bits and the width in units of ``2**tz`` addresses."""
        w = self.geometry.buf_width
        tz = (w & -w).bit_length() - 1
        return tz, w >> tz

    def _step(self, m):
        """The step taken with the restart and offsets[k] = k * step * wu, the window's k-th row's start from its
        first's in units (registered from the step); constants with ``max_step`` 1."""
        n, s = self.slots, self.max_step
        _, wu = self._unit()
        if s == 1:
            return Const(1), [Const(k * wu) for k in range(n)]
        step = Signal(range(1, s + 1), init=1)
        with m.If(self.restart):
            m.d.sync += step.eq(self.row_step)
        offsets = [Const(0)] + [Signal(range((n - 1) * s * wu + 1), name=f"offset_{k}") for k in range(1, n)]
        m.d.sync += [offsets[k].eq(times(step, k * wu)) for k in range(1, n)]
        return step, offsets

    def _tails(self):
        """With a step above 1: tails[k] (k < n - 1), the low ``c`` bits of the k-th row's end in units
        (bounds[k] + wu), ``2**(c - 1)`` at least both the width and the widest skipped gap (``(step - 1) * wu``):
        for an address at or after bounds[k] and before bounds[k + 1], ``units - tails[k]`` modulo ``2**c`` is below
        ``2**(c - 1)`` exactly when the address is a width or more past the row's start (in a skipped row)."""
        n, s = self.slots, self.max_step
        _, wu = self._unit()
        c = (max(1, s - 1) * wu - 1).bit_length() + 1
        return [Signal(c, name=f"tail_{k}") for k in range(n - 1)]

    def _read(self, m, bounds, limit, tails, restarting, first_slot):
        """The consumer's read against the window's rows; returns ``(grant, ge)``."""
        g, n, s = self.geometry, self.slots, self.max_step
        w = g.buf_width
        tz, wu = self._unit()
        # The read: the address against every row's start at once (at or after bounds[k]: ge[k]), its row in the
        # window (j: the last k with ge[k]), its column (the difference to that row's start); granted inside the
        # window's landed rows (from bounds[0] up to limit) and, with a step above 1, not in a skipped row. The
        # address's low ``tz`` bits are the column's (every start is a multiple of the unit); its high bits
        # (``units``) are compared with the starts and the limit.
        consumer = self.consumer
        addr = consumer.port.addr
        units = addr[tz:]
        diff_bits = max(len(units), len(bounds[0])) + 1
        diffs = [Signal(signed(diff_bits), name=f"column_{k}") for k in range(n)]
        m.d.comb += [d.eq(units - b) for d, b in zip(diffs, bounds)]
        ge = [~d[-1] for d in diffs]
        j = Signal(range(n))
        for k in range(1, n):
            with m.If(ge[k]):
                m.d.comb += j.eq(k)
        x = Signal(range(w))
        with m.Switch(j):
            for k in range(n):
                with m.Case(k):
                    m.d.comb += x.eq(Cat(addr[:tz], diffs[k]))
        below_limit = Signal()
        m.d.comb += below_limit.eq(units < limit)
        in_rows = ge[0] & below_limit
        if s > 1:
            # An address at or past bounds[k] and before bounds[k + 1] (k < n - 1) lies in the rows the step
            # skips when it is a width or more past bounds[k] (past the last row the limit ends the window): the
            # top bit of its low bits less the row's tail is clear (``_tails``), a carry chain's sum bit, side by
            # side with the starts' comparisons.
            c = len(tails[0])
            past_end = [Signal(c, name=f"past_end_{k}") for k in range(n - 1)]
            m.d.comb += [p.eq(units[:c] - t) for p, t in zip(past_end, tails)]
            skipped = Signal()
            m.d.comb += skipped.eq(0)
            for k in range(n - 1):
                with m.If(ge[k] & ~ge[k + 1] & ~past_end[k][-1]):
                    m.d.comb += skipped.eq(1)
            in_rows = in_rows & ~skipped
        grant = consumer.request & in_rows & ~restarting
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
        return grant, ge
