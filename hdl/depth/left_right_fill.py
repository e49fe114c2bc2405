"""LeftRightFill: the left-right check and the background fill of a row of codes (docs/depth.md, "left-right
check")."""

from amaranth import Cat, Module, Mux, Signal
from amaranth.lib import data, wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from spec.depth import DEPTH
from spec.sensor import SENSOR

__all__ = ["LeftRightFill"]


class LeftRightFill(wiring.Component):
    """A row's codes checked against the left view's winners and filled from the background, replayed in
    ascending x (docs/depth.md, "left-right check").

    While a row is computed, its right pixels' codes and integer winners d* (any order) and its left pixels' d_L
    (any order) are written into two row stores. ``start`` runs a backward scan, x = W - 1 .. 0, one pixel a
    clock: right pixel x is kept iff its code is valid and |d_L(min(x + d*, W - 1)) - d*| <= 1; the nearest
    kept code to its right (the invalid code if none) is written back beside its code and keep flag. ``replay``
    then sends the row, x = 0 .. W - 1, a pixel every other clock (the median's rate), then the end token (x = W):
    a kept pixel's code, else the smaller of the nearest kept codes to its left (carried along) and to its right
    (stored); the invalid code sorts above every code, so where a side has none the other's is taken, and where
    neither has one the code is invalid. The next row's codes and d_L may be written from the end of the scan on
    (during the replay: a code at x only after the replay has read x).

    Parameters
    ----------
    config : DepthConfig
        D, ``code_bits``, ``invalid``.
    width : int
        Image width W.

    Ports
    -----
    code_valid, code_x, code, code_d : In
        One right pixel's code (after the validity and row rules) and d*; not during the scan.
    left_valid, left_x, left_d : In
        One left pixel's d_L (``hdl.depth.left_winner.LeftWinner``); not during the scan.
    start : In(1)
        The row is written (every code and d_L of it): scan it (a row scanned and not replayed is dropped).
    replay : In(1)
        Replay the scanned row (:meth:`scan_clocks` clocks after ``start`` or later; ignored before).
    stop : In(1)
        Abandon the scan or the replay (a new map): back to taking writes in the next clock.
    valid, x, out_code : Out
        The replay into the median: x = 0 .. W - 1 with its code, then the end token x = W; ``valid`` every other
        clock, the end token :meth:`replay_clocks` clocks after ``replay``.
    busy : Out(1)
        Scanning (from the clock after ``start``, :meth:`scan_clocks` clocks) or replaying (from the clock after
        ``replay`` to the end token's).

    Clock domain: ``sync``. Latency: the scan W + 3 clocks (a read of the codes, a read of d_L at the clamped
    target, d_L registered, the check and the write-back); the replay's end token 2 (W + 1) clocks after
    ``replay``.
    """

    @staticmethod
    def scan_clocks(width):
        """Clocks from ``start`` to the first clock that takes ``replay`` (the scan's W + 3, and one)."""
        return width + 4

    @staticmethod
    def replay_clocks(width):
        """Clocks from ``replay`` to the end token's ``valid``."""
        return 2 * (width + 1)

    def __init__(self, config=DEPTH, width=SENSOR.buf_width):
        self.config, self.width = config, width
        super().__init__({
            "code_valid": In(1),
            "code_x": In(range(width)),
            "code": In(config.code_bits),
            "code_d": In(range(config.disparities)),
            "left_valid": In(1),
            "left_x": In(range(width)),
            "left_d": In(range(config.disparities)),
            "start": In(1),
            "replay": In(1),
            "stop": In(1),
            "valid": Out(1),
            "x": Out(range(width + 1)),
            "out_code": Out(config.code_bits),
            "busy": Out(1),
        })

    def elaborate(self, platform):
        m = Module()
        cfg, w = self.config, self.width
        bits = cfg.code_bits
        # A row word: the code and d* while the row is computed; the code, its keep flag and the nearest kept code
        # to its right after the scan.
        word = data.StructLayout({"code": bits, "tail": max((cfg.disparities - 1).bit_length(), bits + 1)})
        m.submodules.codes = codes = Memory(shape=word, depth=w, init=[])
        m.submodules.left = left = Memory(shape=range(cfg.disparities), depth=w, init=[])
        code_read, code_write = codes.read_port(), codes.write_port()
        left_read, left_write = left.read_port(), left.write_port()
        m.d.comb += [left_write.addr.eq(self.left_x), left_write.data.eq(self.left_d),
                     left_write.en.eq(self.left_valid)]

        scan_x = Signal(range(w + 3))           # clocks of the scan: x = W - 1 - scan_x is read
        replay_x = Signal(range(w + 1))
        odd = Signal()
        at1 = Signal(range(w), reset_less=True)
        live = [Signal(name=f"live{k}") for k in (1, 2, 3)]     # a scan read in flight at stage 1, 2, 3
        right_kept = Signal(bits, reset_less=True)              # nearest kept code to the right of x
        left_kept = Signal(bits, reset_less=True)               # replay: nearest kept code to the left
        live1, _, live3 = live
        room1 = Signal(range(w), reset_less=True)               # W - 1 - at1 (= scan_x of the read; live only)
        at3, code3, keep, scan_data = self._scan_pipeline(m, (code_read, left_read), (at1, room1), live, right_kept,
                                                          word)

        writes = [code_write.addr.eq(self.code_x), code_write.data.code.eq(self.code),
                  code_write.data.tail.eq(self.code_d), code_write.en.eq(self.code_valid)]
        with m.FSM(name="fill"):
            # IDLE: nothing to replay; READY: a scanned row to replay. Both take the next row's writes.
            for state in ("IDLE", "READY"):
                with m.State(state):
                    m.d.comb += writes
                    m.d.sync += [flag.eq(0) for flag in live]   # no scan read in flight (after a stop too)
                    if state == "READY":
                        with m.If(self.replay):
                            m.d.sync += [replay_x.eq(0), odd.eq(0), left_kept.eq(cfg.invalid)]
                            m.next = "REPLAY"
                    with m.If(self.start):
                        m.d.sync += [scan_x.eq(0), right_kept.eq(cfg.invalid)]
                        m.next = "SCAN"
                    with m.If(self.stop):
                        m.next = "IDLE"
            with m.State("SCAN"):
                m.d.comb += [self.busy.eq(1), code_read.addr.eq(w - 1 - scan_x),
                             code_write.addr.eq(at3), code_write.data.eq(scan_data), code_write.en.eq(live3)]
                m.d.sync += [scan_x.eq(scan_x + 1), at1.eq(w - 1 - scan_x), room1.eq(scan_x), live1.eq(scan_x < w)]
                with m.If(live3 & keep):
                    m.d.sync += right_kept.eq(code3)
                with m.If(scan_x == w + 2):
                    m.next = "READY"
                with m.If(self.stop):
                    m.d.sync += [flag.eq(0) for flag in live]
                    m.next = "IDLE"
            with m.State("REPLAY"):
                stored = code_read.data
                kept, right = stored.tail[bits], stored.tail[:bits]
                filled = Mux(kept, stored.code, Mux(right < left_kept, right, left_kept))
                m.d.comb += writes
                m.d.comb += [self.busy.eq(1), code_read.addr.eq(replay_x),
                             self.valid.eq(odd), self.x.eq(replay_x),
                             self.out_code.eq(filled)]
                m.d.sync += odd.eq(~odd)
                with m.If(odd):
                    m.d.sync += replay_x.eq(replay_x + 1)
                    with m.If(kept):
                        m.d.sync += left_kept.eq(stored.code)
                    with m.If(replay_x == w):
                        m.next = "IDLE"
                with m.If(self.stop):
                    m.next = "IDLE"
        return m

    def _scan_pipeline(self, m, reads, at, live, right_kept, word):
        """The scan's stages after the read of word x (``at``: its address ``at1`` and W - 1 - x, ``room1``;
        ``live``: in flight at stage 1, 2, 3): 1 read d_L at min(x + d*, W - 1) (d* > W - 1 - x compared beside
        the sum, not after it); 2 d_L registered (nothing after the memory's output); 3 the check. Returns (x, code,
        keep, the word written back) of stage 3."""
        cfg, w, bits = self.config, self.width, self.config.code_bits
        code_read, left_read = reads
        at1, room1 = at
        d_bits = (cfg.disparities - 1).bit_length()
        first = code_read.data
        d1 = first.tail[:d_bits]
        target = Signal(range(2 * w))
        m.d.comb += target.eq(at1 + d1)
        m.d.comb += left_read.addr.eq(Mux(d1 > room1, w - 1, target))
        # |d_L - d*| <= 1: d_L equals d* - 1, d* or d* + 1, each registered with d* one bit wider than d_L (d* - 1
        # wraps to all ones for d* = 0 and d* + 1 = D: neither matches a d_L), and the code's validity registered.
        live1, live2, live3 = live
        at2 = Signal(range(w), reset_less=True)
        code2, d2 = Signal(bits, reset_less=True), Signal(d_bits, reset_less=True)
        below2, above2 = Signal(d_bits + 1, reset_less=True), Signal(d_bits + 1, reset_less=True)
        valid2 = Signal(reset_less=True)
        m.d.sync += [at2.eq(at1), code2.eq(first.code), d2.eq(d1), live2.eq(live1), below2.eq(d1 - 1),
                     above2.eq(d1 + 1), valid2.eq(first.code != cfg.invalid)]
        at3 = Signal(range(w), reset_less=True)
        code3, d3 = Signal(bits, reset_less=True), Signal(d_bits, reset_less=True)
        below3, above3 = Signal(d_bits + 1, reset_less=True), Signal(d_bits + 1, reset_less=True)
        valid3, dl = Signal(reset_less=True), Signal(d_bits, reset_less=True)
        m.d.sync += [at3.eq(at2), code3.eq(code2), d3.eq(d2), live3.eq(live2), below3.eq(below2),
                     above3.eq(above2), valid3.eq(valid2), dl.eq(left_read.data)]
        keep = valid3 & ((dl == d3) | (dl == below3) | (dl == above3))
        scan_data = Signal(word)
        m.d.comb += [scan_data.code.eq(code3), scan_data.tail.eq(Cat(right_kept, keep))]
        return at3, code3, keep, scan_data
