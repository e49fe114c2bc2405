"""``ReadReturn``: MIG's read data path as the user sees it -- words in command order, each on its due clock."""

from amaranth.hdl import Cat, Module
from amaranth.lib import wiring
from amaranth.lib.fifo import SyncFIFO
from amaranth.lib.wiring import In, Out

from spec.memory import MIG

__all__ = ["ReadReturn"]


class ReadReturn(wiring.Component):
    """A FIFO of read words with the clock each is due: the head word goes out (``valid``) on the clock ``now``
    equals its ``due``, whether or not anyone takes it (MIG has no backpressure). Words enter in order with
    increasing ``due`` times, at least one clock after they enter; ``data`` is 0 when ``valid`` is low.

    Parameters
    ----------
    data_width : int
        A user word.
    depth : int
        Words in flight (at least the longest latency + 2).

    Members
    -------
    now : In(32)
        The model's clock counter.
    push : In(Signature)
        ``data``, ``due``, ``en``: a word entering.
    data, valid : Out
        ``rd_data_fifo_out``, ``rd_data_valid``.

    Clock domain ``sync`` (clk0).
    """

    def __init__(self, *, data_width=MIG.DATA_WIDTH, depth=64):
        self._data_width, self._depth = data_width, depth
        super().__init__({
            "now": In(32),
            "push": In(wiring.Signature({"data": Out(data_width), "due": Out(32), "en": Out(1)})),
            "data": Out(data_width), "valid": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.fifo = fifo = SyncFIFO(width=self._data_width + 32, depth=self._depth)
        dw = self._data_width
        due_now = fifo.r_rdy & (fifo.r_data[dw:] == self.now)
        m.d.comb += [
            fifo.w_data.eq(Cat(self.push.data, self.push.due)), fifo.w_en.eq(self.push.en),
            fifo.r_en.eq(due_now), self.valid.eq(due_now),
            self.data.eq(fifo.r_data[:dw] & due_now.replicate(dw)),
        ]
        return m
