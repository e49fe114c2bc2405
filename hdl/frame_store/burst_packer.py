"""BurstPacker: a camera's captured grey pixels packed into the frame store's 64-bit memory words (a quarter of a BL4
burst each), in the camera's domain.

The capture (:class:`hdl.capture.CameraCapture`) writes its kept pixels in raster order between ``row_start`` and
``row_end`` strobes, framed by ``frame_start`` and ``frame_done`` (with ``frame_ok``). The packer counts them itself
-- the column from the row's start, the row from the frame's start, both saturating at the layout's size -- and
places each pixel's value, ``layout.pixel_bytes`` bytes (zero-extended, low byte first), at its column in a word
register of 8 bytes (a memory word: a burst is four, :class:`~hdl.frame_store.burst_writer.BurstWriter` joins
them; a word, not a burst, an entry of the clock-crossing FIFO makes its LUT RAM a quarter as wide). It sends one
entry per event (:data:`ENTRY_KINDS`):

* ``BURST``: a word's 8 bytes with its row, its index in the row and its byte mask (a 1 masks a byte no pixel
  was written to, as MIG's mask does), when the word's last pixel is written or the row ends;
* ``START``: a frame starts (a word in progress is dropped);
* ``END``: a frame ends; ``ok`` = the capture's ``frame_ok`` and no entry of the frame was lost (also when the
  next frame starts before the ``END`` could be sent).

Entries are ``Out`` on ``entry`` (a FIFO's write side: ``en`` when ``rdy``). The packer never waits: a word it
cannot send (the FIFO is full, or a ``START``/``END`` is still waiting to be sent before it) is dropped and its frame
ends not ``ok``; a ``START``/``END`` waits in its own flag until it is sent, ahead of later words. Pixels beyond
the layout's width and rows beyond its height are dropped, and their frame ends not ``ok``; so does a frame with a
row that ends short of the width (its words may all be there, the last one masked short, so the writer's count
of words alone would not see it).
"""

from amaranth import Cat, Const, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.wiring import In, Out

from hdl.capture import CaptureStatusSignature
from hdl.frame_buffer import FrameBufferWriteSignature
from spec.sensor import SENSOR

from spec.memory import MIG

from .layout import BURST_BYTES, FrameStoreLayout

__all__ = ["BurstPacker", "burst_entry_layout", "check_grey", "ENTRY_KINDS", "WORD_BYTES"]

#: The entry kinds: a word of pixels (a quarter of a burst), a frame's start, a frame's end.
ENTRY_KINDS = {"BURST": 0, "START": 1, "END": 2}
#: Bytes of an entry's pixels: one 64-bit memory word, a quarter of a burst.
WORD_BYTES = BURST_BYTES // MIG.BURST_LENGTH


def check_grey(geometry, pixel_bytes=1):
    """``ValueError`` unless a pixel's value fits its bytes (``geometry.grey_bits`` at most 8 ``pixel_bytes``)."""
    if geometry.grey_bits > 8 * pixel_bytes:
        raise ValueError(f"{pixel_bytes} byte(s) a pixel hold at most {8 * pixel_bytes} bits, got "
                         f"{geometry.grey_bits}")


def burst_entry_layout(layout):
    """The entry's fields: ``kind`` (:data:`ENTRY_KINDS`), ``ok`` (an END's verdict), ``row``, ``word`` (its index
    in the row: word ``word mod 4`` of burst ``word // 4``), ``data`` (8 bytes, byte ``k`` of the pixel at column
    ``8 * word + k`` with one byte a pixel; bytes ``2 j``, ``2 j + 1`` of the pixel at column ``4 * word + j`` with
    two), ``mask`` (a 1 per byte not written)."""
    return data.StructLayout({
        "kind": 2, "ok": 1,
        "row": range(layout.height), "word": range(layout.bursts_per_row * MIG.BURST_LENGTH),
        "data": 8 * WORD_BYTES, "mask": WORD_BYTES,
    })


class BurstPacker(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    layout : :class:`hdl.frame_store.layout.FrameStoreLayout`
        ``width`` x ``height`` pixels a frame, ``pixel_bytes`` bytes a pixel.
    geometry : :class:`spec.sensor.SensorGeometry`
        The capture's write port (``grey_bits`` of grey, at most 8 ``layout.pixel_bytes``).

    Attributes
    ----------
    write : ``In(FrameBufferWriteSignature(geometry))``
        The capture's pixel writes (``addr`` is not used: the packer counts).
    status : ``In(CaptureStatusSignature)``
        The capture's strobes.
    entry : ``Out(...)``
        ``data`` (:func:`burst_entry_layout`), ``en`` out; ``rdy`` in (room in the FIFO).

    Clock domain: ``sync`` (the writer renames it to the camera's). Latency: a word's entry is sent in the clock
    after the write that fills it or after ``row_end``; ``START`` / ``END`` in the clock after their strobe when
    nothing else is sent then.

    Raises
    ------
    ValueError
        ``geometry.grey_bits`` above 8 ``layout.pixel_bytes``.
    """

    def __init__(self, layout=FrameStoreLayout(), geometry=SENSOR):
        check_grey(geometry, layout.pixel_bytes)
        self.layout, self.geometry = layout, geometry
        super().__init__({
            "write": In(FrameBufferWriteSignature(geometry)),
            "status": In(CaptureStatusSignature),
            "entry": Out(wiring.Signature({"data": Out(burst_entry_layout(layout)), "en": Out(1), "rdy": In(1)})),
        })

    def elaborate(self, platform):
        m = Module()
        lay = self.layout
        width, height = lay.width, lay.height
        status, write, entry = self.status, self.write, self.entry

        column = Signal(range(width + 1))       # saturating at width: no pixel
        row = Signal(range(height + 1))         # saturating at height: no row
        # column < width and row < height, registered where column and row change (both count up by one from 0
        # and stop at their limit, so the next value's comparison is the current value's with limit - 1).
        column_in, row_in = Signal(init=1, name="column_in"), Signal(init=1, name="row_in")
        last_column = Signal(init=width == 1)   # column == width - 1
        in_row = Signal()
        word_data = Signal(8 * WORD_BYTES)
        per_word, pixel_bits = WORD_BYTES // lay.pixel_bytes, 8 * lay.pixel_bytes
        in_word = (per_word - 1).bit_length()
        written = Signal(per_word)              # pixels of the word register written in this word
        lost = Signal()                         # an entry of this frame could not be sent
        start_waiting, end_waiting, end_ok = Signal(), Signal(), Signal()

        # The pixel: its byte in the word register; a full word or the row's end sends it.
        offset = column[:in_word]               # the pixel in the word
        keep = write.en & in_row & column_in & row_in
        # The word register is sent in the clock after it is filled, before a later pixel can change it (a
        # write lands at the end of its clock), so the entry's data is the register itself (its unwritten bytes
        # masked), with no copy.
        filled = Signal()                       # the word register holds a word to send (registered)
        full_row = Signal(range(height), name="full_row")
        full_word = Signal(range(lay.bursts_per_row * MIG.BURST_LENGTH), name="full_word")
        full_mask = Signal(WORD_BYTES)

        def column_zero():                      # the column counter and its flags back at column 0
            return [column.eq(0), column_in.eq(1), last_column.eq(width == 1)]

        def byte_mask(pixels):                  # a 1 per byte of a pixel not written
            return Cat(*(~pixels[i // lay.pixel_bytes] for i in range(WORD_BYTES)))
        m.d.sync += filled.eq(0)
        with m.If(keep):
            m.d.sync += [column.eq(column + 1), column_in.eq(~last_column), last_column.eq(column == width - 2)]
            pixel = Cat(write.data, Const(0, pixel_bits - len(write.data)))
            new_written = Signal.like(written)
            m.d.comb += [new_written.eq(written), new_written.bit_select(offset, 1).eq(1)]
            m.d.sync += word_data.word_select(offset, pixel_bits).eq(pixel)
            with m.If((offset == per_word - 1) | last_column):
                m.d.sync += [filled.eq(1), full_row.eq(row), full_word.eq(column[in_word:]),
                             full_mask.eq(byte_mask(new_written)), written.eq(0)]
            with m.Else():
                m.d.sync += written.eq(new_written)
        with m.If(write.en & in_row & ~keep):   # a pixel beyond the width or a row beyond the height
            m.d.sync += lost.eq(1)
        with m.If(status.row_end & in_row):
            m.d.sync += [in_row.eq(0), *column_zero()]
            with m.If(Mux(keep, ~last_column, column_in)):    # column + keep != width: a short row (its last
                m.d.sync += lost.eq(1)                          # word is sent, masked)
            with m.If(row_in):
                m.d.sync += [row.eq(row + 1), row_in.eq(row != height - 1)]
            with m.If(written.any() & ~keep):      # a short row's last, partly written word
                m.d.sync += [filled.eq(1), full_row.eq(row), full_word.eq(column[in_word:]),
                             full_mask.eq(byte_mask(written)), written.eq(0)]
        with m.If(status.row_start):
            m.d.sync += [in_row.eq(1), *column_zero(), written.eq(0)]
        with m.If(status.frame_start):
            m.d.sync += [row.eq(0), row_in.eq(1), *column_zero(), in_row.eq(0), written.eq(0), filled.eq(0),
                         start_waiting.eq(1), lost.eq(0)]
            with m.If(end_waiting):             # the last frame's END not sent yet: its verdict keeps its losses
                m.d.sync += end_ok.eq(end_ok & ~lost & ~filled)
        with m.If(status.frame_done):
            m.d.sync += [end_waiting.eq(1), end_ok.eq(status.frame_ok)]

        self._send(m, filled, full_row, full_word, word_data, full_mask, start_waiting, end_waiting, end_ok, lost)
        return m

    def _send(self, m, filled, full_row, full_word, full_data, full_mask, start_waiting, end_waiting, end_ok, lost):
        """One entry a clock: a filled word (unless an END or START waits before it), else the END, else the
        START. The flags are set by this clock's strobes after (so over) what is sent here. A word's fields
        are driven whatever the kind (a ``START`` / ``END`` carries them unused): no gate per data bit. The entry
        is one assignment of its whole value (``kind`` and ``ok`` from the branches), so the exported Verilog
        computes it from time 0 on every simulator (a field assigned alone is an ``always @*`` of its own, which
        Icarus first runs when its source first changes)."""
        entry = self.entry
        kinds = ENTRY_KINDS
        kind, ok = Signal(2), Signal()
        m.d.comb += entry.data.as_value().eq(Cat(kind, ok, full_row, full_word, full_data, full_mask))
        with m.If(filled & ~start_waiting & ~end_waiting):
            m.d.comb += [kind.eq(kinds["BURST"]), entry.en.eq(entry.rdy)]
            with m.If(~entry.rdy):
                m.d.sync += lost.eq(1)
        with m.Elif(end_waiting):
            m.d.comb += [kind.eq(kinds["END"]), ok.eq(end_ok & ~lost & ~filled), entry.en.eq(entry.rdy)]
            with m.If(entry.rdy):
                m.d.sync += end_waiting.eq(0)
        with m.Elif(start_waiting):
            m.d.comb += [kind.eq(kinds["START"]), entry.en.eq(entry.rdy)]
            with m.If(entry.rdy):
                m.d.sync += start_waiting.eq(0)
            with m.If(filled):
                m.d.sync += lost.eq(1)
