"""LeftWinner: the left view's winner d_L from the summed costs the winner sees (docs/depth.md, "left-right
check")."""

from amaranth import Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from spec.sensor import SENSOR
from hdl.depth.ports import token_layout

__all__ = ["LeftWinner"]


class LeftWinner(wiring.Component):
    """d_L(x') = the smallest d with the smallest S(d, x' - d), d = 0 .. min(D - 1, x'), from the right pixels'
    sums in ascending x, a group of ``lanes`` disparities at a time.

    Right pixel x offers S(d, x) to left pixel x + d. A running minimum (S, d) is kept for the D left pixels x ..
    x + D - 1 (entry j: left pixel x + j), as G = D / lanes words of ``lanes`` entries in small memories with an
    asynchronous read (LUT RAM). Group g of pixel x reads word g, keeps per lane the offer where its sum is at
    most the entry's (the later offers to a left pixel come from larger x, so smaller d: ties go to them) and
    writes the word back one lane down: entry j of pixel x becomes entry j - 1 of pixel x + 1. Entry 0 after
    group 0 (offer d = 0) is final: left pixel x's d_L. At x = 0 (``token.first``) every entry takes its offer,
    as does entry D - 1 (left pixel x + D - 1, offered to first by pixel x) at every pixel.

    Parameters
    ----------
    config : DepthConfig
        D, lanes, ``sum_bits``.
    width : int
        Image width (the token's column range).

    Ports
    -----
    token, sums : In
        A group's token and its ``lanes`` sums S(g lanes + k, x) (``hdl.depth.winner.Winner``'s ``sums_token``
        and ``sums``); a pixel's groups in consecutive clocks, in ascending g; pixels in ascending x, from x = 0,
        at least G + 1 clocks apart.
    valid, x, d : Out
        Left pixel x's d_L; ``valid`` pulses one clock after the pixel's group 0.

    Clock domain: ``sync``. Latency 1 clock (from group 0 to ``valid``).
    """

    def __init__(self, config=DEPTH, width=SENSOR.buf_width):
        self.config, self.width = config, width
        self.groups = config.disparities // config.lanes
        super().__init__({
            "token": In(token_layout(self.groups, width)),
            "sums": In(data.ArrayLayout(config.sum_bits, config.lanes)),
            "valid": Out(1),
            "x": Out(range(width)),
            "d": Out(range(config.disparities)),
        })

    def elaborate(self, platform):
        m = Module()
        cfg, lanes, G = self.config, self.config.lanes, self.groups
        entry = data.StructLayout({"s": cfg.sum_bits, "d": range(cfg.disparities)})
        word = data.ArrayLayout(entry, lanes)
        # Entry j of word g: lanes 0 .. lanes - 2 in one memory, lane ``lanes`` - 1 in another (written a clock
        # apart: no register holds a word).
        tok = self.token
        stored = []
        if lanes > 1:
            m.submodules.entries = entries = Memory(shape=data.ArrayLayout(entry, lanes - 1), depth=G, init=[])
            low_read, low_write = entries.read_port(domain="comb"), entries.write_port()
            m.d.comb += low_read.addr.eq(tok.group)
            stored = [low_read.data[k] for k in range(lanes - 1)]
        m.submodules.last_lanes = last_lanes = Memory(shape=entry, depth=G, init=[])
        last_read, last_write = last_lanes.read_port(domain="comb"), last_lanes.write_port()
        m.d.comb += last_read.addr.eq(tok.group)
        stored.append(last_read.data)

        # An entry without an offer yet (every entry at x = 0; the last word's last lane, left pixel x + D - 1,
        # always) takes the offer: its stored value is not read.
        updated = Signal(word)
        for k in range(lanes):
            fresh = tok.first | (tok.group == G - 1) if k == lanes - 1 else tok.first
            offer = Signal(entry, name=f"offer{k}")
            m.d.comb += [offer.s.eq(self.sums[k]), offer.d.eq(tok.group * lanes + k)]
            m.d.comb += updated[k].eq(Mux(fresh | (offer.s <= stored[k].s), offer, stored[k]))

        # Written back one lane down: group g's lanes 1 .. lanes - 1 into word g's lanes 0 .. lanes - 2 (read in this
        # clock, written at its end), its lane 0 into word g - 1's last lane.
        if lanes > 1:
            m.d.comb += [low_write.addr.eq(tok.group), low_write.data.eq(updated.as_value()[entry.size:]),
                         low_write.en.eq(tok.go)]
        m.d.comb += [last_write.addr.eq(tok.group - 1), last_write.data.eq(updated[0]),
                     last_write.en.eq(tok.go & (tok.group != 0))]

        m.d.sync += [self.valid.eq(tok.go & (tok.group == 0)), self.x.eq(tok.x), self.d.eq(updated[0].d)]
        return m
