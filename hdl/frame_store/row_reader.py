"""RowReader: rows of one camera's held frame, fetched on request into a ring of block-RAM row slots in the reader's
domain (``pix``), read a byte at a time (docs/frame_store.md, "Readers").

The consumer asks for rows (``fetch``: the row number); the n-th row asked for lands in slot ``n mod slots``, and
``landed`` pulses when its last word is in. It reads a landed row's pixel ``x`` of slot ``s`` on ``read``: the pixel
(``layout.pixel_bytes`` bytes) one clock after the address, as a frame buffer's read port gives it. The consumer decides which slots it may ask to
overwrite: a row asked for overwrites its slot when its words arrive.

Inside: the requests cross to ``mem`` in an :class:`amaranth.lib.fifo.AsyncFIFO`, a
:class:`~hdl.frame_store.row_fetcher.RowFetcher` reads the bursts of the camera's held buffer (credits: never more
words outstanding than the returning FIFO has room for), the words come back in a second AsyncFIFO, and the
filler writes each row's words (the padding words of the row's last burst dropped) into its slot.
"""

from amaranth import Cat, DomainRenamer, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.fifo import AsyncFIFO
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from hdl.signature import ParametricSignature
from spec.memory import MIG

from .layout import WORD_BYTES, FrameStoreLayout
from .mem_port import BurstReadSignature
from .row_fetcher import RowFetcher

__all__ = ["RowReader", "RowStreamSignature", "PIECE_BITS"]

#: The ring's width: a word from MIG is written into it in ``MIG.DATA_WIDTH // PIECE_BITS`` clocks, and a slot of
#: a 400-pixel row (100 pieces, 128 entries) x 4 slots fills one RAMB18 (512 x 36) instead of four.
PIECE_BITS = 32


class RowStreamSignature(ParametricSignature):
    """A row reader as its consumer sees it, all in the read domain: ``fetch`` (``row``, ``en`` out, ``rdy`` in: ask
    for a row), ``landed`` in (a one-clock pulse: the oldest row asked for and not landed is in its slot), ``read``
    (``slot``, ``x`` out, ``data`` in: the pixel, ``pixel_bits`` wide, one clock after its address)."""

    def __init__(self, height, width, slots, pixel_bits=8):
        super().__init__({
            "fetch": Out(wiring.Signature({"row": Out(range(height)), "en": Out(1), "rdy": In(1)})),
            "landed": In(1),
            "read": Out(wiring.Signature({"slot": Out(range(slots)), "x": Out(range(width)),
                                          "data": In(pixel_bits)})),
        }, height=height, width=width, slots=slots, pixel_bits=pixel_bits)


class RowReader(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    layout : :class:`hdl.frame_store.layout.FrameStoreLayout`
    camera : int
    slots : int
        Rows the ring holds.
    depth : int
        Words the returning FIFO holds (a power of two): the fetcher's credits.
    read_domain, mem_domain : str

    Attributes
    ----------
    stream : ``In(RowStreamSignature(layout.height, layout.width, slots, 8 * layout.pixel_bytes))``, ``read_domain``
    hold : ``In(...)``, ``mem_domain``
        ``valid``, ``buffer``: the held pair's buffer of this camera.
    mem : ``Out(BurstReadSignature())``, ``mem_domain``

    Latency: ``read.data`` one ``read_domain`` clock after ``read.slot``/``read.x``; a row lands some ``mem`` clocks
    (the arbiter's grants, MIG's latency) and a few clocks of each domain (the FIFOs) after it is asked for.

    Raises
    ------
    ValueError
        The fetcher's checks; ``slots`` below 1; ``depth`` not a power of two.
    """

    def __init__(self, layout=FrameStoreLayout(), camera=0, *, slots=4, depth=32, read_domain="pix",
                 mem_domain="mem"):
        if slots < 1:
            raise ValueError(f"slots must be at least 1, got {slots}")
        if depth < MIG.WORDS_PER_BURST or depth & (depth - 1):
            raise ValueError(f"depth must be a power of two of at least {MIG.WORDS_PER_BURST}, got {depth}")
        if not 0 <= camera < layout.cameras:
            raise ValueError(f"camera must be in 0..{layout.cameras - 1}, got {camera}")
        self.layout, self.camera, self.slots, self.depth = layout, camera, slots, depth
        self.read_domain, self.mem_domain = read_domain, mem_domain
        bits = max(1, (layout.buffers - 1).bit_length())
        super().__init__({
            "stream": In(RowStreamSignature(layout.height, layout.width, slots, 8 * layout.pixel_bytes)),
            "hold": In(wiring.Signature({"valid": Out(1), "buffer": Out(bits)})),
            "mem": Out(BurstReadSignature()),
        })

    @property
    def used_words(self):
        """Words of a row the ring keeps (the row's pixels; the last burst's padding words are dropped)."""
        return -(-self.layout.row_bytes // WORD_BYTES)

    def elaborate(self, platform):
        m = Module()
        lay = self.layout
        requests = AsyncFIFO(width=len(self.stream.fetch.row), depth=4, w_domain=self.read_domain, r_domain=self.mem_domain)
        words = AsyncFIFO(width=MIG.DATA_WIDTH, depth=self.depth, w_domain=self.mem_domain,
                          r_domain=self.read_domain)
        fetcher = RowFetcher(lay, self.camera, self.depth)
        m.submodules.requests = requests
        m.submodules.words = words
        m.submodules.fetcher = DomainRenamer(self.mem_domain)(fetcher)
        m.d.comb += [
            requests.w_data.eq(self.stream.fetch.row), requests.w_en.eq(self.stream.fetch.en), self.stream.fetch.rdy.eq(requests.w_rdy),
            fetcher.requests.row.eq(requests.r_data), fetcher.requests.rdy.eq(requests.r_rdy),
            requests.r_en.eq(fetcher.requests.en),
            words.w_data.eq(fetcher.words.data), words.w_en.eq(fetcher.words.en),
            fetcher.words.level.eq(words.w_level),
        ]
        wiring.connect(m, wiring.flipped(self.hold), fetcher.hold)
        wiring.connect(m, wiring.flipped(self.mem), fetcher.mem)
        self._fill(m, words)
        return m

    def _fill(self, m, words):
        """The filler and the ring, in ``read_domain``: each word taken from the FIFO into a register and written
        into the ring a piece (:data:`PIECE_BITS`) a clock, so the ring is a block RAM of one narrow port per side;
        a slot's pieces start at a power of two (the read address is the slot and the column's high bits).

        The FIFO's ``r_en`` is a register (``take``: no word held, or the held word's last piece, decided a clock
        ahead from the filler's next state), so nothing but the FIFO's own pointer compare lies before its read
        pointer's increment."""
        lay, used = self.layout, self.used_words
        pieces = MIG.DATA_WIDTH // PIECE_BITS
        piece_pixels = PIECE_BITS // (8 * lay.pixel_bytes)
        col_bits = max(1, (used * pieces - 1).bit_length())   # a slot's pieces: 2**col_bits entries
        rd = m.d[self.read_domain]
        m.submodules.ring = ring = Memory(shape=PIECE_BITS, depth=self.slots << col_bits, init=[])
        write = ring.write_port(domain=self.read_domain)
        read = ring.read_port(domain=self.read_domain)
        slot = Signal(range(self.slots))
        word = Signal(range(lay.words_per_row))
        held = Signal(MIG.DATA_WIDTH)                   # the word being written
        full = Signal()
        piece = Signal(range(pieces))

        def is_last(piece, word):
            return (piece == pieces - 1) | (word >= used)       # a padding word is dropped in one clock

        last_piece = is_last(piece, word)
        next_piece, next_word = Signal.like(piece), Signal.like(word)
        m.d.comb += [next_piece.eq(piece), next_word.eq(word)]
        with m.If(full):
            m.d.comb += next_piece.eq(piece + 1)
            with m.If(last_piece):
                m.d.comb += [next_piece.eq(0), next_word.eq(word + 1)]
                with m.If(word == lay.words_per_row - 1):
                    m.d.comb += next_word.eq(0)
                    rd += slot.eq(Mux(slot == self.slots - 1, 0, slot + 1))
                    m.d.comb += self.stream.landed.eq(1)
        rd += [piece.eq(next_piece), word.eq(next_word)]
        # ``take`` is this clock's ``~full | last_piece``, kept a clock ahead: its next value from the next piece
        # and word (registers only) and whether the FIFO gives a word in this clock.
        take = Signal(init=1)
        took = words.r_rdy & take
        full_next = took | (full & ~last_piece)
        rd += [full.eq(full_next), take.eq(~full_next | is_last(next_piece, next_word))]
        m.d.comb += [
            words.r_en.eq(take),
            write.addr.eq(Cat(piece, word, slot) if col_bits == len(piece) + len(word)
                          else (slot << col_bits) + word * pieces + piece),
            write.data.eq(held.word_select(piece, PIECE_BITS)),
            write.en.eq(full & (word < used)),
        ]
        with m.If(took):
            rd += held.eq(words.r_data)
        x = self.stream.read.x
        byte = Signal(range(piece_pixels))      # the pixel in the piece
        column = Signal(col_bits)
        rd += byte.eq(x[:len(byte)])
        m.d.comb += [column.eq(x[len(byte):]),
                     read.addr.eq(Cat(column, self.stream.read.slot)),
                     self.stream.read.data.eq(read.data.word_select(byte, 8 * lay.pixel_bytes))]
