"""MemoryArbiter: the frame store's writers and readers sharing MIG's user interface, in the ``mem`` domain.

One burst a grant, by fixed priority: the *urgent* readers first (the display's: a display line cannot wait), then
the camera writers (a camera cannot be held back either, but its FIFO absorbs a wait of several bursts), then the
other readers (the depth engine's, which waits; docs/frame_store.md, "Arbitration", has the worst case).

* Nothing is granted before ``phy_init_done``, nor while MIG's address or write-data FIFO was almost full in the
  clock before (``afull``: 15 or fewer entries free; the flags are registered here, as MIG drives them straight
  from its FIFO36s; from the clock a flag rises, the arbiter writes at most 3 more data words and 3 more commands,
  so it never overfills them).
* A write burst takes two clocks: its first data word in the clock after the grant, its second with the write
  command in the next (data before command, AR 24146). No grant in the first of them.
* A read burst's command goes out in the clock after the grant; the reader's number goes into a FIFO of
  ``read_tags`` entries in that clock too, from a register (so the FIFO's level is not on the grant's path; MIG's
  words come many clocks after the command), a read being granted only when there is room (a register set in the
  clock before from the FIFO's level and the tag on its way in), and the two words MIG returns for it, in command
  order, are handed to that reader (``valid`` for one clock each: no backpressure).

Outputs to MIG are registered. The arbiter does not count a reader's credits: a reader requests a burst only when
it has room for its words (:class:`~hdl.frame_store.row_fetcher.RowFetcher`).
"""

import operator
from functools import reduce

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.fifo import SyncFIFO
from amaranth.lib.wiring import In, Out

from hdl.mig_user import MIGUserSignature
from spec.memory import MIG

from .mem_port import BurstReadSignature, BurstWriteSignature

__all__ = ["MemoryArbiter"]


class MemoryArbiter(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    writers : int
        Burst writers (the cameras').
    readers : int
        Burst readers.
    urgent : int
        The first ``urgent`` readers come before the writers; the rest after them.
    last_writers : int
        The last ``last_writers`` writers come after every reader (a writer that waits when it must: the depth maps'
        writer, whose engine then waits too).
    read_tags : int
        Read bursts in flight at most (the tag FIFO's depth).

    Attributes
    ----------
    writers : ``In(BurstWriteSignature()).array(writers)``
    readers : ``In(BurstReadSignature()).array(readers)``
    mig : ``Out(MIGUserSignature())``

    Clock domain: ``sync`` (the frame store renames it to ``mem``, MIG's ``clk0``). Latency: a granted command
    reaches MIG one clock (read) or two clocks (write, with its second word) after its grant; a read's words reach
    their reader in the clock MIG returns them.

    Raises
    ------
    ValueError
        No client, ``urgent`` above ``readers``, ``last_writers`` above ``writers``, ``read_tags`` below 1.
    """

    def __init__(self, writers=2, readers=2, urgent=1, read_tags=32, last_writers=0):
        if writers + readers < 1 or writers < 0 or readers < 0:
            raise ValueError(f"the arbiter needs a client, got {writers} writers and {readers} readers")
        if not 0 <= urgent <= readers:
            raise ValueError(f"urgent must be in 0..{readers}, got {urgent}")
        if read_tags < 1:
            raise ValueError(f"read_tags must be at least 1, got {read_tags}")
        if not 0 <= last_writers <= writers:
            raise ValueError(f"last_writers must be in 0..{writers}, got {last_writers}")
        self.n_writers, self.n_readers, self.urgent, self.read_tags = writers, readers, urgent, read_tags
        self.last_writers = last_writers
        super().__init__({
            "writers": In(BurstWriteSignature()).array(writers),
            "readers": In(BurstReadSignature()).array(readers),
            "mig": Out(MIGUserSignature()),
        })

    def _order(self):
        """The clients by priority: ``("read", i)`` / ``("write", i)``."""
        early = self.n_writers - self.last_writers
        return ([("read", i) for i in range(self.urgent)] + [("write", i) for i in range(early)] +
                [("read", i) for i in range(self.urgent, self.n_readers)] +
                [("write", i) for i in range(early, self.n_writers)])

    def elaborate(self, platform):
        m = Module()
        mig = self.mig
        tag_bits = max(1, (self.n_readers - 1).bit_length())
        m.submodules.tags = tags = SyncFIFO(width=tag_bits, depth=self.read_tags)

        second = Signal()                       # the second clock of a write burst
        word1, mask1 = Signal(MIG.DATA_WIDTH), Signal(MIG.MASK_WIDTH)
        write_addr = Signal(MIG.ADDR_WIDTH)
        ready = Signal()
        afull = Signal()                        # either almost-full flag, a clock late
        m.d.sync += afull.eq(mig.command.afull | mig.write.afull)
        m.d.comb += ready.eq(mig.phy_init_done & ~afull & ~second)

        # Registered outputs, idle unless set below.
        m.d.sync += [mig.command.wren.eq(0), mig.write.wren.eq(0)]
        with m.If(second):
            m.d.sync += [second.eq(0), mig.write.data.eq(word1), mig.write.mask.eq(mask1), mig.write.wren.eq(1),
                         mig.command.cmd.eq(MIG.CMD_WRITE), mig.command.addr.eq(write_addr),
                         mig.command.wren.eq(1)]

        # A won read's tag enters the FIFO in the next clock, from a register (``push``, ``push_tag``). Room for a read's
        # tag, a register: the tags held or on their way in at the next clock (the FIFO's level and the tag pushed in
        # this clock, less the tag popped in this clock, plus one for a read won in this clock) below ``read_tags``,
        # the comparison made for both outcomes of the win so that only a multiplexer follows it.
        push, push_tag = Signal(), Signal(tag_bits)
        m.d.comb += [tags.w_en.eq(push), tags.w_data.eq(push_tag)]
        tag_room = Signal(init=1)
        read_won = Signal()
        after_pop = tags.level + push - (tags.r_en & tags.r_rdy)
        m.d.sync += tag_room.eq(Mux(read_won, after_pop < self.read_tags - 1, after_pop < self.read_tags))

        # The winner: each client's request against the OR of those before it, side by side (not a chain), and
        # what goes to MIG as an AND-OR of the clients' values under their one-hot wins.
        wins, requests = [], []
        for kind, i in self._order():
            request = self.writers[i].request if kind == "write" else self.readers[i].request & tag_room
            win = Signal(name=f"win_{kind}_{i}")
            m.d.comb += win.eq(ready & request & ~Cat(*requests).any() if requests else ready & request)
            wins.append((kind, i, win))
            requests.append(request)

        def pick(kind, value):
            return reduce(operator.or_, [Mux(win, value(i), 0) for k, i, win in wins if k == kind])

        read_wins = [win for kind, _, win in wins if kind == "read"]
        write_wins = [win for kind, _, win in wins if kind == "write"]
        for kind, i, win in wins:
            m.d.comb += (self.writers[i] if kind == "write" else self.readers[i]).grant.eq(win)
        if write_wins:
            with m.If(Cat(*write_wins).any()):
                w = self.writers
                m.d.sync += [second.eq(1), write_addr.eq(pick("write", lambda i: w[i].addr)),
                             mig.write.data.eq(pick("write", lambda i: w[i].data[:MIG.DATA_WIDTH])),
                             mig.write.mask.eq(pick("write", lambda i: w[i].mask[:MIG.MASK_WIDTH])),
                             mig.write.wren.eq(1),
                             word1.eq(pick("write", lambda i: w[i].data[MIG.DATA_WIDTH:])),
                             mask1.eq(pick("write", lambda i: w[i].mask[MIG.MASK_WIDTH:]))]
        if read_wins:
            m.d.comb += read_won.eq(Cat(*read_wins).any())
            m.d.sync += [push.eq(read_won), push_tag.eq(pick("read", lambda i: i))]
            with m.If(Cat(*read_wins).any()):
                m.d.sync += [mig.command.cmd.eq(MIG.CMD_READ),
                             mig.command.addr.eq(pick("read", lambda i: self.readers[i].addr)),
                             mig.command.wren.eq(1)]

        # Read data to the reader whose command it answers: two words a tag.
        second_word = Signal()
        with m.If(mig.read.valid & tags.r_rdy):
            m.d.sync += second_word.eq(~second_word)
            m.d.comb += tags.r_en.eq(second_word)
        for i, client in enumerate(self.readers):
            m.d.comb += [client.data.eq(mig.read.data),
                         client.valid.eq(mig.read.valid & tags.r_rdy & (tags.r_data == i))]
        return m
