"""CEA-861 video sync generator: raster position, data enable and sync pulses for one video mode."""

from amaranth.hdl import Module, Signal, Mux
from amaranth.lib import wiring

from spec.video import CEA_1080P60
from hdl.video_bus import TimingSignature, X_BITS, Y_BITS

__all__ = ["SyncGenerator", "check_timing"]


def check_timing(timing, start=(0, 0)):
    """Raise ``ValueError`` unless ``timing`` is a mode the display blocks can produce and ``start`` a raster
    position of it."""
    if timing.h_total > 2 ** X_BITS or timing.v_total > 2 ** Y_BITS:
        raise ValueError(f"{timing.h_total} x {timing.v_total} does not fit the {X_BITS}/{Y_BITS}-bit x/y of "
                         f"TimingSignature")
    if min(timing.h_active, timing.h_sync, timing.v_active, timing.v_sync, timing.v_front) < 1 or \
            min(timing.h_front, timing.h_back, timing.v_back) < 0:
        raise ValueError(f"unsupported video timing {timing} (need h_active, h_sync, v_active, v_sync, "
                         f"v_front >= 1 and non-negative porches)")
    x0, y0 = start
    if not (0 <= x0 < timing.h_total and 0 <= y0 < timing.v_total):
        raise ValueError(f"start {start} is outside the {timing.h_total} x {timing.v_total} raster")


class SyncGenerator(wiring.Component):
    """Free-running raster counter; its own signature is :data:`hdl.video_bus.TimingSignature`.

    Clock domain: ``sync`` (the parent places it in ``pix`` with ``DomainRenamer``).

    The raster is ``timing.h_total`` x ``timing.v_total`` clocks per frame, with nothing in between frames.
    ``x`` counts 0 .. h_total-1 and ``y`` counts 0 .. v_total-1; a line is laid out as

    ``[0, h_active)`` active, then ``h_front`` front porch, ``h_sync`` sync pulse, ``h_back`` back porch,

    and lines ``[0, v_active)`` are active, followed by ``v_front``, ``v_sync`` and ``v_back`` blank lines.

    * ``de`` = ``x < h_active and y < v_active``.
    * ``hsync`` is active for ``h_sync_start <= x < h_sync_start + h_sync`` on every line.
    * ``vsync`` follows the CEA-861 progressive-format convention: its edges coincide with hsync leading
      edges. It becomes active at ``x == h_sync_start`` of line ``v_sync_start - 1`` (the hsync leading edge
      that ends the ``v_front``-th blank line) and inactive exactly ``v_sync`` lines (``v_sync * h_total``
      clocks) later. Counting hsync leading edges: ``v_front`` of them lie strictly between the end of the last
      active line and the vsync leading edge, ``v_sync`` inside the pulse (the first one coincides with its
      leading edge) and ``v_back`` strictly between its trailing edge and the first active line.
    * ``hsync``/``vsync`` are emitted at their final polarity (``timing.hsync_positive``/``vsync_positive``).
    * ``frame_start`` is high for the one clock with ``x == 0 and y == 0``.

    Latency: every output is a register and all outputs describe the same raster position in the same clock
    (no skew between ``x``/``y`` and ``de``/``hsync``/``vsync``/``frame_start``). The reset values describe
    position ``start`` (default (0, 0)), so by default the first clock after reset is the first active pixel
    of a frame (``frame_start`` = 1, ``de`` = 1): from reset the generator is at the top of a frame.
    ``start`` = (x, y) makes a simulation begin elsewhere in the raster (e.g. a few lines before the vsync
    pulse, to look at the vertical blanking of a 1080p frame without simulating the 2.4 M clocks before it);
    the board build uses the default.

    Parameters
    ----------
    timing : :class:`spec.video.VideoTiming`
    start : (int, int)
        The raster position after reset.

    Raises
    ------
    ValueError
        A timing whose totals do not fit ``x``/``y`` or that lacks an active area, sync pulse or front porch; a
        ``start`` outside the raster.
    """

    def __init__(self, timing=CEA_1080P60, *, start=(0, 0)):
        check_timing(timing, start)
        self.timing = timing
        self.start = tuple(start)
        super().__init__(TimingSignature)

    def elaborate(self, platform):
        m = Module()
        t = self.timing

        # The output registers; their reset values describe raster position `start`.
        x0, y0 = self.start
        levels = _levels(t, x0, y0)
        x = Signal(X_BITS, init=x0)
        y = Signal(Y_BITS, init=y0)
        de = Signal(init=levels["de"])
        hsync = Signal(init=levels["hsync"])
        vsync = Signal(init=levels["vsync"])
        frame_start = Signal(init=levels["frame_start"])
        m.d.comb += [self.x.eq(x), self.y.eq(y), self.de.eq(de), self.hsync.eq(hsync), self.vsync.eq(vsync),
                     self.frame_start.eq(frame_start)]

        # The raster position one clock ahead, a register too (reset: the position after `start`), so the
        # outputs are registered compares of registered state: the counter's increment and wrap feed only
        # `nx`/`ny`, never a compare in the same clock.
        x1, y1 = _advance(t, x0, y0)
        nx = Signal(X_BITS, init=x1)
        ny = Signal(Y_BITS, init=y1)
        last_x = nx == t.h_total - 1
        last_y = ny == t.v_total - 1

        # Every output is a function of the next position, registered, so all of them change together.
        h_pulse = (nx >= t.h_sync_start) & (nx < t.h_sync_start + t.h_sync)
        # vsync: from (x = h_sync_start, y = v_first) up to, not including, (x = h_sync_start, y = v_last).
        v_first = t.v_sync_start - 1
        v_last = v_first + t.v_sync
        v_pulse = (((ny > v_first) & (ny < v_last)) |
                   ((ny == v_first) & (nx >= t.h_sync_start)) |
                   ((ny == v_last) & (nx < t.h_sync_start)))

        m.d.sync += [
            nx.eq(Mux(last_x, 0, nx + 1)),
            ny.eq(Mux(last_x, Mux(last_y, 0, ny + 1), ny)),
            x.eq(nx),
            y.eq(ny),
            de.eq((nx < t.h_active) & (ny < t.v_active)),
            hsync.eq(h_pulse if t.hsync_positive else ~h_pulse),
            vsync.eq(v_pulse if t.vsync_positive else ~v_pulse),
            frame_start.eq((nx == 0) & (ny == 0)),
        ]
        return m


def _advance(t, x, y):
    """The raster position one clock after (x, y)."""
    if x < t.h_total - 1:
        return x + 1, y
    return 0, (y + 1) % t.v_total


def _levels(t, x, y):
    """Output levels at raster position (x, y), for the reset values (the same rules as the logic above)."""
    h_pulse = t.h_sync_start <= x < t.h_sync_start + t.h_sync
    v_first = t.v_sync_start - 1
    v_last = v_first + t.v_sync
    v_pulse = v_first < y < v_last or (y == v_first and x >= t.h_sync_start) or \
        (y == v_last and x < t.h_sync_start)
    return {
        "de": int(x < t.h_active and y < t.v_active),
        "hsync": int(h_pulse == t.hsync_positive),
        "vsync": int(v_pulse == t.vsync_positive),
        "frame_start": int(x == 0 and y == 0),
    }
