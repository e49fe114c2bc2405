"""MapWindow: the depth map held in the frame store given to the compositor as the engine's ring of result rows
(docs/frame_store.md, "Depth maps in the store").

The compositor reads the map as it reads the engine's ring (:class:`hdl.depth.ports.ResultReadSignature`): ``addr``
= (row mod ``slots``) * W + x, the code one clock later, rows ``0 .. rows_ready - 1`` there, ``rows_released`` the
rows it no longer needs (its depth panel releases a row after the row's last line; it resets the count in vertical
blanking). The window serves it from a read stream of the store's map buffers (:class:`~hdl.frame_store.row_reader.
RowReader`, ``slots`` row slots):

* at ``take`` (the display frame's start, when the store takes the latest whole map) ``rows_ready`` drops to 0 and
  the window stops asking for rows; at ``taken`` (the map is held) it asks for the map's rows from row 0 while they
  are fewer than ``slots`` ahead of ``rows_released`` (row r goes to slot ``(first + r) mod slots``, ``first`` the
  stream's slot for the first row asked after ``taken``), at most every other clock, decided from registers (the
  released count a clock late: it only grows within a frame);
* ``rows_ready`` counts the rows landed since ``taken`` -- rows asked before it (the last map's, still arriving)
  are not counted -- and is 0 while no map is held (``valid`` low: before the first whole map the depth panel and
  the segmentation view show every row as not ready);
* a read of ring row ``k`` (``addr`` compared with the constants ``j * W``: no divider) goes to slot
  ``(first + k) mod slots``, column ``addr - k * W``.

So the compositor's rows come from the held map only, and a slot is asked for again only once its row is released.
"""

from amaranth import Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.depth.ports import ResultReadSignature
from hdl.frame_store.row_reader import RowStreamSignature

__all__ = ["MapWindow"]


class MapWindow(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
        The map's size (the buffers').
    code_bits : int
        A code's bits.
    slots : int
        The stream's row slots: the compositor's ``out_rows``.
    pixel_bits : int
        The stream's pixel width (8 per byte of a stored code).

    Attributes
    ----------
    result : ``In(ResultReadSignature((slots * W - 1).bit_length(), code_bits, H))``
        The compositor's ``depth`` port.
    stream : ``Out(RowStreamSignature(H, W, slots, pixel_bits))``
        To the store's map read stream.
    take, taken : ``In(1)``
        The store's map hold: asked for (the display frame's start), held.
    valid : ``In(1)``
        A map is held (before the first whole map: none).

    Clock domain: ``sync`` (the parent renames it to ``pix``). Latency: the code one clock after ``addr`` (the
    stream's); ``rows_ready`` a clock after a row's ``landed``; the first row asked for two clocks after ``taken``.

    Raises
    ------
    ValueError
        ``slots`` below 2, ``code_bits`` above ``pixel_bits``.
    """

    def __init__(self, geometry, code_bits, *, slots=4, pixel_bits=8):
        if slots < 2 or code_bits > pixel_bits:
            raise ValueError(f"slots must be at least 2 and codes ({code_bits} bits) fit the stream's pixels "
                             f"({pixel_bits} bits), got {slots} slots")
        self.geometry, self.code_bits, self.slots = geometry, code_bits, slots
        w, h = geometry.buf_width, geometry.buf_height
        super().__init__({
            "result": In(ResultReadSignature((slots * w - 1).bit_length(), code_bits, h)),
            "stream": Out(RowStreamSignature(h, w, slots, pixel_bits)),
            "take": In(1),
            "taken": In(1),
            "valid": In(1),
        })

    def elaborate(self, platform):
        m = Module()
        w, h, n = self.geometry.buf_width, self.geometry.buf_height, self.slots
        result, fetch, read = self.result, self.stream.fetch, self.stream.read

        def wrap(value):
            return Mux(value >= n, value - n, value)

        active = Signal()                           # between ``taken`` and the next ``take``
        asked = Signal(range(h + 1))                # rows of this map asked for
        landed = Signal(range(h + 1))               # rows of this map landed
        next_slot = Signal(range(n))                # the stream's slot for the next row asked
        first = Signal(range(n))                    # the slot of this map's row 0
        outstanding = Signal(range(2 * n + 1))      # rows asked (any map) and not landed: the last map's and this one's
        skip = Signal(range(n + 1))                 # landings still due for rows asked before ``taken``

        # Whether a row may be asked for, from registers (``rows_released`` + slots a register too: the released
        # count only grows within a frame, so a late one is a safe one); a clock after an ask it is not yet
        # up to date, so no ask then.
        ask, may, asked_last = Signal(), Signal(), Signal()
        limit = Signal(range(h + n + 1))
        m.d.sync += [limit.eq(result.rows_released + n), may.eq(active & (asked < h) & (asked < limit)),
                     asked_last.eq(ask)]
        m.d.comb += [
            ask.eq(may & ~asked_last & active & ~self.take & fetch.rdy),
            fetch.row.eq(asked), fetch.en.eq(ask),
            result.rows_ready.eq(Mux(active & self.valid, landed, 0)),
        ]
        m.d.sync += outstanding.eq(outstanding + ask - self.stream.landed)
        with m.If(ask):
            m.d.sync += [asked.eq(asked + 1), next_slot.eq(wrap(next_slot + 1))]
        with m.If(self.stream.landed):
            with m.If(skip != 0):
                m.d.sync += skip.eq(skip - 1)
            with m.Elif(active):
                m.d.sync += landed.eq(landed + 1)
        with m.If(self.take):
            m.d.sync += [active.eq(0), asked.eq(0), landed.eq(0)]
        with m.Elif(self.taken):
            m.d.sync += [active.eq(1), asked.eq(0), landed.eq(0), first.eq(next_slot),
                         skip.eq(outstanding - self.stream.landed)]

        # The compositor's read: ring row k (addr >= k W), its column and slot.
        k, start = Signal(range(n)), Signal(range(n * w))
        for j in range(1, n):
            with m.If(result.addr >= j * w):
                m.d.comb += [k.eq(j), start.eq(j * w)]
        m.d.comb += [read.slot.eq(wrap(first + k)), read.x.eq(result.addr - start),
                     result.data.eq(read.data)]
        return m
