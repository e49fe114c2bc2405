"""VerticalOffsetEstimator: finds the vertical offset between the two cameras from row profiles
(docs/rectification.md, the automatic mode)."""

from amaranth import Module, Mux, Signal, signed, unsigned
from amaranth.lib import wiring
from amaranth.lib.cdc import PulseSynchronizer
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from hdl.signature import ParametricSignature
from spec.rectification import RECTIFICATION
from spec.sensor import SENSOR

#: Registered stages between a row read and its cost (the read data, the row differences, the terms, the sum).
SWEEP_STAGES = 3

__all__ = ["CaptureWatchSignature", "VerticalOffsetEstimator", "FRAME_DONE_CLOCKS"]

#: Clocks of the estimator's domain from the later camera's ``frame_done`` to the search's start.
FRAME_DONE_CLOCKS = 4


class CaptureWatchSignature(ParametricSignature):
    """What the estimator watches of one camera, as the capture drives it: its frame-buffer write port (``addr``,
    ``data``, ``en``; pixels in raster order, address 0 starts a frame) and its ``frame_done`` strobe."""

    def __init__(self, geometry):
        super().__init__({
            "addr": Out(geometry.addr_bits),
            "data": Out(geometry.grey_bits),
            "en": Out(1),
            "frame_done": Out(1),
        }, geometry=geometry)


class VerticalOffsetEstimator(wiring.Component):
    """Row-profile search for the vertical offset r (left row y + r matches right row y), -R..R buffer rows, and
    the decision over frames of docs/rectification.md. ``golden.vertical_offset`` is the same computation.

    Parameters
    ----------
    geometry : SensorGeometry
        Buffer size and grey width.
    config : RectificationConfig
        R, the confidence and hysteresis constants, ``stable_frames``.
    left_domain, right_domain : str
        The domains of the two cameras' write ports (``cam_a``, ``cam_b`` in the system).

    Ports
    -----
    left, right : In(CaptureWatchSignature)
        The two captures' writes, in ``left_domain`` / ``right_domain``: each write adds its grey value to its
        row's sum (row and column counted from address 0, W writes a row); the sum is stored at the row's last
        column. ``frame_done`` of each camera is brought into ``sync`` (a pulse synchroniser); when both have
        come (and no search runs) a search starts, :data:`FRAME_DONE_CLOCKS` after the later one. A camera that
        writes the first rows of its next frame during the search changes those rows' sums under it (the cameras
        are not synchronised; on a still scene the sums are the same).
    busy : Out(1)
        A search is running.
    done : Out(1)
        One clock: the outputs below hold the result of the search just finished.
    offset : Out(range(-R, R + 1))
        The offset in use (0 after reset).
    confident, held, locked : Out(1)
        The last search had a clear minimum; it had none (the offset was kept); the best offset is in use.
    best, cost_best, cost_second, texture : Out
        The last search's o1, c1, c2 and T (for tests and the benchmark).
    profile_addr_left, profile_addr_right, cost_addr : Out
        The read addresses of the profile and cost memories (for the formal harness).

    Clock domains: ``sync`` (the search; the system renames it to ``pix``), ``left_domain`` and ``right_domain``
    (the row sums and the profile memories' write ports). Latency: ``done`` rises ``search_clocks`` clocks after
    the search starts.

    Raises
    ------
    ValueError
        The configuration does not fit the buffers (``RectificationConfig.check``).
    """

    def __init__(self, geometry=SENSOR, config=RECTIFICATION, *, left_domain="sync", right_domain="sync"):
        config.check(geometry.buf_height)
        self.geometry, self.config = geometry, config
        self.domains = {"left": left_domain, "right": right_domain}
        w, h, r = geometry.buf_width, geometry.buf_height, config.search_rows
        self.rows = len(config.window(h))
        self.profile_max = w * (2 ** geometry.grey_bits - 1)
        self.cost_max = 2 * self.profile_max * self.rows
        self.texture_min = (w * self.rows) >> config.texture_shift
        #: Clocks from ``search`` to ``done``: the start, the sweep, its last result, the second pass and its last
        #: read, the decision's comparisons, the decision.
        self.search_clocks = 1 + (2 * r + 1) * (self.rows + 1) + 1 + SWEEP_STAGES + (2 * r + 1) + 1 + 1 + 1
        super().__init__({
            "left": In(CaptureWatchSignature(geometry)),
            "right": In(CaptureWatchSignature(geometry)),
            "busy": Out(1),
            "done": Out(1),
            "offset": Out(range(-r, r + 1)),
            "confident": Out(1),
            "held": Out(1),
            "locked": Out(1),
            "best": Out(range(-r, r + 1)),
            "cost_best": Out(range(self.cost_max + 1)),
            "cost_second": Out(range(self.cost_max + 1)),
            "texture": Out(range(self.cost_max + 1)),
            "profile_addr_left": Out(range(h)),
            "profile_addr_right": Out(range(h)),
            "cost_addr": Out(range(2 * r + 1)),
        })

    def elaborate(self, platform):
        m = Module()
        g, cfg = self.geometry, self.config
        h, r = g.buf_height, cfg.search_rows
        profile_shape = unsigned(self.profile_max.bit_length())
        reads, frame_seen = {}, []
        for side in ("left", "right"):
            m.submodules[f"{side}_profile"] = mem = Memory(shape=profile_shape, depth=h, init=[])
            domain = self.domains[side]
            self._accumulate(m, getattr(self, side), mem.write_port(domain=domain), profile_shape, domain)
            reads[side] = mem.read_port()
            frame_seen.append(self._frame_done(m, side, domain))
        search = Signal()
        m.d.comb += search.eq(frame_seen[0][0] & frame_seen[1][0] & ~self.busy)
        for seen, pulse in frame_seen:                  # a frame_done in the clock of the search is kept
            with m.If(search):
                m.d.sync += seen.eq(0)
            with m.If(pulse):
                m.d.sync += seen.eq(1)
        m.submodules.costs = costs = Memory(shape=unsigned(self.cost_max.bit_length()), depth=2 * r + 1, init=[])
        cost_write, cost_read = costs.write_port(), costs.read_port()
        m.d.comb += [reads["left"].addr.eq(self.profile_addr_left), reads["right"].addr.eq(self.profile_addr_right),
                     cost_read.addr.eq(self.cost_addr)]

        o = Signal(range(-r, r + 1))            # the offset being swept
        y = Signal(range(h))                    # the right row being read
        j = self.cost_addr                      # the cost being read in the second pass
        best_k = Signal(range(2 * r + 1))
        c_in_use = Signal.like(self.cost_best)
        m.d.comb += [self.profile_addr_right.eq(y), self.profile_addr_left.eq(y + o)]

        issue = Signal()                        # a row read is issued this clock
        issue_pass2 = Signal()                  # a cost read is issued this clock
        first_1, last_1, valid_1, k_1 = Signal(), Signal(), Signal(), Signal(range(2 * r + 1))
        valid_2, j_2, last_2 = Signal(), Signal.like(j), Signal()
        m.d.sync += [valid_1.eq(issue), first_1.eq(y == r), last_1.eq(y == h - r - 1), k_1.eq(o + r),
                     valid_2.eq(issue_pass2), j_2.eq(j), last_2.eq(issue_pass2 & (j == 2 * r))]
        self._sweep(m, reads, cost_write, valid_1, first_1, last_1, k_1, best_k, search)
        self._second(m, cost_read, valid_2, j_2, best_k, c_in_use)

        rules = self._rules(m, best_k, c_in_use)
        m.d.sync += self.done.eq(0)
        with m.FSM():
            with m.State("IDLE"):
                with m.If(search):
                    m.d.sync += [o.eq(-r), y.eq(r), self.busy.eq(1)]
                    m.next = "SWEEP"
            with m.State("SWEEP"):
                m.d.comb += issue.eq(1)
                with m.If(y == h - r - 1):
                    m.d.sync += y.eq(r)
                    with m.If(o == r):
                        m.next = "LAST"
                    with m.Else():
                        m.d.sync += o.eq(o + 1)
                with m.Else():
                    m.d.sync += y.eq(y + 1)
            with m.State("LAST"):                       # the last row's read has been issued
                m.d.sync += [j.eq(0), self.cost_second.eq(self.cost_max)]
                m.next = "DRAIN_0"
            for stage in range(SWEEP_STAGES):          # the sweep's pipeline writes the last cost
                with m.State(f"DRAIN_{stage}"):
                    m.next = f"DRAIN_{stage + 1}" if stage + 1 < SWEEP_STAGES else "SECOND"
            with m.State("SECOND"):
                m.d.comb += issue_pass2.eq(1)
                m.d.sync += j.eq(j + 1)
                with m.If(j == 2 * r):
                    m.d.sync += j.eq(0)
                    m.next = "WAIT"
            with m.State("WAIT"):                       # the last cost read arrives
                m.next = "COMPARE"
            with m.State("COMPARE"):                    # the costs are final: the rules' comparisons registered
                m.next = "DECIDE"
            with m.State("DECIDE"):
                self._decide(m, **rules)
                m.d.sync += self.busy.eq(0)
                m.next = "IDLE"
        return m

    def _accumulate(self, m, watch, write, shape, domain):
        """Add up each row of the writes in ``watch``; store the sum at the row's address when its last column
        is written. Column and row are counted from address 0 (W writes a row)."""
        g = self.geometry
        x, y = Signal(range(g.buf_width), name=f"{domain}_column"), Signal(range(g.buf_height), name=f"{domain}_row")
        at_x = Mux(watch.addr == 0, 0, x)
        at_y = Mux(watch.addr == 0, 0, y)
        acc, total = Signal(shape, name=f"{domain}_row_sum"), Signal(shape, name=f"{domain}_row_total")
        last = at_x == g.buf_width - 1
        m.d.comb += [total.eq(Mux(at_x == 0, 0, acc) + watch.data),
                     write.addr.eq(at_y), write.data.eq(total), write.en.eq(watch.en & last)]
        with m.If(watch.en):
            m.d[domain] += [acc.eq(total), x.eq(Mux(last, 0, at_x + 1)),
                            y.eq(Mux(last, Mux(at_y == g.buf_height - 1, 0, at_y + 1), at_y))]

    def _frame_done(self, m, side, domain):
        """(flag, pulse): the camera's ``frame_done`` brought into ``sync`` by a pulse synchroniser, and the flag
        it sets (the search clears it)."""
        m.submodules[f"{side}_frame_done"] = sync = PulseSynchronizer(i_domain=domain, o_domain="sync")
        m.d.comb += sync.i.eq(getattr(self, side).frame_done)
        return Signal(name=f"{side}_frame_seen"), sync.o

    def _sweep(self, m, reads, cost_write, valid_1, first_1, last_1, k_1, best_k, search):
        """After each row read, in four registered stages (the block RAM's data, the row differences, the terms,
        the sum): D_L, D_R against the previous row, |D_L - D_R| summed into C(o)."""
        width = len(reads["left"].data) + 1
        data = {side: Signal(len(reads[side].data), name=f"row_{side}", reset_less=True) for side in reads}
        prev = {side: Signal(len(reads[side].data), name=f"prev_{side}") for side in reads}
        d_left = Signal(signed(width + 1), reset_less=True)
        d_right = Signal(signed(width + 1), reset_less=True)
        term, texture_term = Signal(width + 1, reset_less=True), Signal(width + 1, reset_less=True)
        difference = Signal(signed(width + 2))
        flags = (valid_1, first_1, last_1, k_1)
        stage_a = (Signal(name="valid_a"), Signal(name="first_a"), Signal(name="last_a"), Signal.like(k_1))
        stage_b = (Signal(name="valid_b"), Signal(name="first_b"), Signal(name="last_b"), Signal.like(k_1))
        m.d.sync += [a.eq(f) for a, f in zip(stage_a, flags)]
        m.d.sync += [b.eq(a) for b, a in zip(stage_b, stage_a)]
        valid_a, valid_b = stage_a[0], stage_b[0]
        m.d.sync += [data[side].eq(reads[side].data) for side in reads]
        m.d.comb += difference.eq(d_left - d_right)
        with m.If(valid_a):
            m.d.sync += [prev["left"].eq(data["left"]), prev["right"].eq(data["right"]),
                         d_left.eq(data["left"] - prev["left"]), d_right.eq(data["right"] - prev["right"])]
        with m.If(valid_b):
            m.d.sync += [term.eq(_magnitude(difference)), texture_term.eq(_magnitude(d_right))]
        valid_1, first_1, last_1, k_1 = Signal(), Signal(), Signal(), Signal.like(k_1)
        m.d.sync += [f.eq(b) for f, b in zip((valid_1, first_1, last_1, k_1), stage_b)]
        acc = Signal.like(self.cost_best)
        total = Signal.like(self.cost_best)
        m.d.comb += [total.eq(acc + term), cost_write.addr.eq(k_1), cost_write.data.eq(total),
                     cost_write.en.eq(valid_1 & ~first_1 & last_1)]
        with m.If(search):
            m.d.sync += [acc.eq(0), self.texture.eq(0)]
        with m.If(valid_1):
            with m.If(~first_1):
                m.d.sync += acc.eq(Mux(last_1, 0, total))
                with m.If(k_1 == 0):
                    m.d.sync += self.texture.eq(self.texture + texture_term)
                with m.If(last_1 & ((k_1 == 0) | (total < self.cost_best))):     # the first minimum
                    m.d.sync += [self.cost_best.eq(total), best_k.eq(k_1)]

    def _second(self, m, cost_read, valid_2, j_2, best_k, c_in_use):
        """The second pass over the costs: c2 (at least two offsets from the best) and C(offset in use)."""
        far = Mux(j_2 >= best_k, j_2 - best_k, best_k - j_2) >= 2
        with m.If(valid_2):
            with m.If(far & (cost_read.data < self.cost_second)):
                m.d.sync += self.cost_second.eq(cost_read.data)
            with m.If(j_2 == self.offset + self.config.search_rows):
                m.d.sync += c_in_use.eq(cost_read.data)

    def _rules(self, m, best_k, c_in_use):
        """The decision's comparisons (docs/rectification.md), registered every clock so that in the DECIDE clock
        they hold what the final costs and the tracker's state gave in the COMPARE clock before it (neither
        changes between the two): the deciding clock holds no subtraction or comparison. Returns the best offset
        (``best``: o1), the tracker's state (``candidate``, ``count``: registers only DECIDE loads), and the
        registered rules: ``confident`` (a clear minimum with texture), ``keep`` (the offset in use is kept),
        ``in_use`` (o1 is the offset in use), ``next_count`` (frames o1 has been the candidate, this one
        included) and ``settled`` (that reaches ``stable_frames``)."""
        cfg, r = self.config, self.config.search_rows
        c1, c2 = self.cost_best, self.cost_second
        best = Signal(range(-r, r + 1))
        m.d.comb += best.eq(best_k - r)
        candidate, count = Signal(range(-r, r + 1)), Signal(range(cfg.stable_frames + 1))
        rules = dict(best=best, candidate=candidate, count=count)
        for name in ("confident", "keep", "in_use", "settled"):
            rules[name] = Signal(name=f"{name}_rule")
        rules["next_count"] = Signal.like(count, name="next_count_rule")
        next_count = Mux(best == candidate, count + 1, 1)
        m.d.sync += [rules["confident"].eq((self.texture >= self.texture_min)
                                           & (c2 - c1 > (c2 >> cfg.margin_shift))),
                     rules["in_use"].eq(best == self.offset),
                     rules["keep"].eq((best == self.offset) | (c_in_use - c1 <= (c_in_use >> cfg.switch_shift))),
                     rules["next_count"].eq(next_count), rules["settled"].eq(next_count >= cfg.stable_frames)]
        return rules

    def _decide(self, m, best, candidate, count, confident, keep, in_use, next_count, settled):
        """One clock: the decision over frames (docs/rectification.md) from the registered rules."""
        switch = ~keep & settled                        # o1 replaces the offset in use
        with m.If(~confident | keep):
            m.d.sync += count.eq(0)
        with m.Else():
            m.d.sync += [candidate.eq(best), count.eq(Mux(settled, 0, next_count))]
        with m.If(confident & switch):
            m.d.sync += self.offset.eq(best)
        m.d.sync += [self.best.eq(best), self.confident.eq(confident), self.held.eq(~confident),
                     self.locked.eq(confident & (in_use | switch)), self.done.eq(1)]


def _magnitude(value):
    """``|value|`` of a signed value as one carry chain: its bits inverted when negative, plus its sign (the
    two's complement), not a negation and a multiplexer."""
    sign = value[-1]
    return (value ^ sign.replicate(len(value))).as_unsigned() + sign
