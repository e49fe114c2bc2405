"""ReversePath: the right-to-left aggregation path of a row and its sum with the row's other paths (docs/depth.md,
"Right to left" and "The third path in the RTL")."""

from amaranth import Module, Signal
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from spec.sensor import SENSOR
from hdl.depth.ports import token_layout
from hdl.depth.sgm_path import SgmPath

__all__ = ["ReversePath"]


class ReversePath(wiring.Component):
    """The right-to-left path L_rl of one row, added to the row's other paths: the forward pass stores, per pixel
    and group, the sum of the other paths (``carry``, in pixel order); the reverse pass brings the row's costs in
    descending x, each pixel's groups in ascending order, and gets back L_rl and the full sum S = carry + L_rl in
    that order.

    The row store is one memory of ``width`` x G words (G = D / ``lanes``) of ``lanes`` carries, word x G + g for
    group g of pixel x (docs/depth.md, "The third path in the RTL", scheme a'). The path itself is an
    :class:`hdl.depth.sgm_path.SgmPath` with its own feedback, started afresh at x = ``width`` - 1 (L_rl = C
    there), whatever the token's ``first`` says: the right-to-left path starts at the row's last column.

    Parameters
    ----------
    config : DepthConfig
        D, lanes, P1, P2 and the widths (``path_bits``, ``sum_bits``).
    width : int
        Image width W (the row store's pixels, the token's column range).
    other_paths : int
        The paths summed into ``carry`` (the forward pass's, 2: left to right and top to bottom); ``carry`` is
        ``other_paths`` x ``path_max`` at most.

    Ports
    -----
    store_token, carry : In
        Forward pass: a group of pixel x (``store_token.x``, ``.group``, written while ``.go``) and its ``lanes``
        carried sums. A word may be written over once the reverse pass has read it.
    token, cost : In
        Reverse pass: a group and its ``lanes`` costs C(d), d = group x lanes + k; pixels in descending x, a
        pixel's groups in consecutive clocks, pixels at least :meth:`loop_clocks` clocks apart (the path's loop).
        The group's carry must have been stored at least one clock before.
    l, carry_out, total, out_token : Out
        The group's L_rl, its stored carry and S = carry + L_rl (``sum_bits``), :data:`LATENCY` clocks after its
        input; ``out_token`` is the input token (``first`` set for x = W - 1).
    m, m_valid : Out
        The pixel's minimum of L_rl (``SgmPath``).

    Clock domain: ``sync``.

    The row store is read only for a token (``token.go``), written only for one (``store_token.go``): both
    addresses are then inside it; the token's other fields are ignored on other clocks.

    Pipeline (i = the group's input clock): i: row store read (address x G + g); i .. i + 2: the path
    (``SgmPath.LATENCY``), the carry delayed with it; i + 3: S = carry + L_rl registered: ``total`` at i + 4.

    Raises
    ------
    ValueError
        If ``lanes`` does not divide D, ``width`` is less than D or ``other_paths`` is not positive.
    """

    LATENCY = SgmPath.LATENCY + 1       # clocks from a group's input to ``total``

    def __init__(self, config=DEPTH, *, width=SENSOR.buf_width, other_paths=2):
        if config.disparities % config.lanes:
            raise ValueError(f"lanes ({config.lanes}) must divide D ({config.disparities})")
        if width < config.disparities:
            raise ValueError(f"the width ({width}) must be at least D ({config.disparities})")
        if other_paths < 1:
            raise ValueError(f"other_paths must be at least 1, not {other_paths}")
        self.config = config
        self.width = width
        self.groups = config.disparities // config.lanes
        self.carry_bits = (other_paths * config.path_max).bit_length()
        self.sum_bits = ((other_paths + 1) * config.path_max).bit_length()
        layout = token_layout(self.groups, width)
        lanes = config.lanes
        super().__init__({
            "store_token": In(layout),
            "carry": In(data.ArrayLayout(self.carry_bits, lanes)),
            "token": In(layout),
            "cost": In(data.ArrayLayout(config.cost_bits, lanes)),
            "l": Out(data.ArrayLayout(config.path_bits, lanes)),
            "carry_out": Out(data.ArrayLayout(self.carry_bits, lanes)),
            "total": Out(data.ArrayLayout(self.sum_bits, lanes)),
            "out_token": Out(layout),
            "m": Out(config.path_bits),
            "m_valid": Out(1),
        })

    @classmethod
    def loop_clocks(cls, config=DEPTH):
        """The fewest clocks between two pixels of the reverse pass (the path's loop, as left to right)."""
        return SgmPath.loop_clocks(config)

    @property
    def store_shape(self):
        """(depth, width) of the row store: W x G words of ``lanes`` x ``carry_bits``."""
        return self.width * self.groups, self.config.lanes * self.carry_bits

    def elaborate(self, platform):
        m = Module()
        cfg, lanes, groups = self.config, self.config.lanes, self.groups
        layout = token_layout(groups, self.width)
        depth, _ = self.store_shape

        m.submodules.row_store = store = Memory(shape=data.ArrayLayout(self.carry_bits, lanes), depth=depth,
                                                init=[])
        write, read = store.write_port(), store.read_port()
        m.d.comb += [
            write.addr.eq(self.store_token.x * groups + self.store_token.group),
            write.data.eq(self.carry),
            write.en.eq(self.store_token.go),
            # Read only for a token: on other clocks the engine's token column runs outside the row (the
            # forward pass's, the census lead's), and the address with it.
            read.addr.eq(self.token.x * groups + self.token.group),
            read.en.eq(self.token.go),
        ]

        # The path: the token with ``first`` at the row's last column.
        path = m.submodules.path = SgmPath(cfg, recurrent=True, width=self.width)
        start = Signal(layout)
        m.d.comb += [start.eq(self.token), start.first.eq(self.token.x == self.width - 1),
                     path.token.eq(start), path.cost.eq(self.cost)]

        # The carry beside the path: read at i (data at i + 1), delayed to i + 3 with ``l``.
        carry = read.data
        for s in range(SgmPath.LATENCY - 1):
            delayed = Signal(data.ArrayLayout(self.carry_bits, lanes), name=f"carry{s}", reset_less=True)
            m.d.sync += delayed.eq(carry)
            carry = delayed

        m.d.sync += [self.out_token.eq(path.l_token), self.l.eq(path.l), self.carry_out.eq(carry)]
        for k in range(lanes):
            m.d.sync += self.total[k].eq(path.l[k] + carry[k])
        m.d.comb += [self.m.eq(path.m), self.m_valid.eq(path.m_valid)]
        return m
