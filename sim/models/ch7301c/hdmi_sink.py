"""HDMI / CH7301C sink model: samples the 12-bit dual-edge bus and the syncs, checks the timing, rebuilds frames.

Three layers, so the Amaranth simulator and cocotb use the same model:

* :class:`HdmiSink`, the pure-Python core. Feed it one pixel clock at a time with :meth:`HdmiSink.sample`
  (``hsync``, ``vsync``, ``de`` and the two 12-bit words: the one following the XCLK rising edge and the one
  following the falling edge). It rebuilds every complete frame as a ``uint8`` ``(v_active, h_active, 3)``
  array (:attr:`HdmiSink.frames`), measures every timing interval it sees (:attr:`HdmiSink.observed`) and
  records each deviation from a :class:`spec.video.VideoTiming` as a :class:`Violation` with the frame,
  line and clock where it happened.
* :func:`amaranth_sink_testbench`: an Amaranth async testbench that samples the pins on both XCLK edges.
* :class:`CocotbSink`: the same for cocotb (Verilator / Icarus), with a tight sampling loop.

Word format (CH7301C IDF 0, see ``hdl/ch7301c_output.py``): the rising-edge word is ``G[3:0] B[7:0]``, the
falling-edge word ``R[7:0] G[7:4]``. Each word is read in the half clock period that *follows* its XCLK edge,
which is where the transmitter holds it (a real CH7301C latches it with XCLK delayed into the data eye).

Timing rules checked (all from the :class:`~spec.video.VideoTiming`; "active" = at the pulse polarity):

* line length: ``h_total`` clocks between consecutive hsync leading edges;
* hsync width ``h_sync``; horizontal front porch ``h_front`` (de falling edge -> hsync leading edge) and back
  porch ``h_back`` (hsync trailing edge -> de rising edge); active line length ``h_active`` (de high run);
* vsync edges coincide with hsync leading edges (CEA-861 progressive convention); vsync width ``v_sync``
  lines = ``v_sync * h_total`` clocks; vertical front porch: ``v_front`` hsync leading edges strictly between
  the end of the last active line and the vsync leading edge; back porch: ``v_back`` hsync leading edges
  strictly between the vsync trailing edge and the first active line;
* frame: ``v_active`` active lines, ``h_total * v_total`` clocks from the first active pixel of one frame to
  the first active pixel of the next;
* polarity: hsync and vsync must be at their inactive level while de is high;
* the data pins carry 0 outside de (``check_blank_data``; the Chrontel multiplexed RGB input expects 0 in
  non-active pixels).

The first frame: with ``starts_at_frame=True`` (the default; the sync generator starts at the top of a
frame after reset) the first active line seen is line 0 of frame 0. Otherwise frames start at the first
active line after a vsync pulse. Checks that need a previous edge start once that edge has been seen.
"""

import os
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["HdmiSink", "Violation", "SinkError", "amaranth_sink_testbench", "CocotbSink", "write_png"]


@dataclass(frozen=True)
class Violation:
    """One timing or format error seen by the sink."""
    kind: str            # e.g. "line_length", "hsync_width", "hsync_polarity"
    clock: int           # pixel-clock index (0 = first sample)
    frame: int           # frame index (-1 before the first frame starts)
    line: int            # active line within the frame (-1 outside active lines)
    message: str

    def __str__(self):
        where = f"clock {self.clock}"
        if self.frame >= 0:
            where += f", frame {self.frame}"
        if self.line >= 0:
            where += f", after active line {self.line}"
        return f"{self.kind}: {self.message} ({where})"


class SinkError(AssertionError):
    """The sink saw timing violations (raised by :meth:`HdmiSink.check`)."""


def write_png(frame, path):
    """Write a ``uint8`` ``(h, w, 3)`` frame as a PNG (Pillow); returns the path."""
    from PIL import Image
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.asarray(frame, dtype=np.uint8), mode="RGB").save(path)
    return path


class HdmiSink:
    """Pure-Python CH7301C/HDMI sink: per pixel clock in, checked timing and rebuilt frames out.

    ``timing`` is any :class:`spec.video.VideoTiming`. ``max_reports`` bounds how many violations of each kind
    are kept in :attr:`violations` (all are counted in :attr:`violation_counts`). ``keep_frames`` bounds how
    many rebuilt frames are kept (the most recent ones; ``None`` keeps all).
    """

    def __init__(self, timing, *, starts_at_frame=True, check_blank_data=True, max_reports=20,
                 keep_frames=None, on_frame=None):
        self.timing = timing
        self.starts_at_frame = starts_at_frame
        self.check_blank_data = check_blank_data
        self.max_reports = max_reports
        self.keep_frames = keep_frames
        self.on_frame = on_frame
        self.frames = []                 # complete frames, uint8 (v_active, h_active, 3)
        self.frames_completed = 0
        self.violations = []             # the first max_reports of each kind
        self.violation_counts = Counter()
        #: every measured interval: name -> Counter(value -> times seen)
        self.observed = {k: Counter() for k in (
            "line_clocks", "hsync_clocks", "h_front", "h_back", "active_pixels",
            "vsync_clocks", "vsync_lines", "v_front", "v_back", "active_lines", "frame_clocks")}
        self.clock = 0
        self._hs_on = 1 if timing.hsync_positive else 0
        self._vs_on = 1 if timing.vsync_positive else 0
        self._prev_hs = self._prev_vs = self._prev_de = False
        self._hs_lead = self._hs_trail = self._de_rise = self._de_fall = None
        self._vs_lead = self._vs_trail = None
        self._hs_since_de_fall = None   # hsync leading edges since the last de falling edge
        self._hs_since_vs_trail = None  # ... since the last vsync trailing edge (None: not counting)
        self._vs_lines = 0              # hsync leading edges inside the current vsync pulse
        self._frame_index = -1          # frame being received (-1: none yet)
        self._in_frame = False          # receiving active lines of a frame
        self._armed = starts_at_frame   # the next de rising edge starts a frame
        self._row = 0                   # active lines of the current frame received so far
        self._frame_start_clock = None
        self._frame = None
        self._pixels = []               # packed words of the current active line
        self._line_ok = False

    # -- the per-clock core ---------------------------------------------------------------------------------

    def sample(self, hsync, vsync, de, first, second):
        """One pixel clock: sync/de levels and the words after the rising (``first``) and falling edge."""
        n = self.clock
        self.clock = n + 1
        hs = hsync == self._hs_on
        vs = vsync == self._vs_on
        if de:
            if hs or vs:
                self._polarity(n, hs, vs)
            if self._prev_de and hs == self._prev_hs and vs == self._prev_vs:
                self._pixels.append(first | (second << 12))      # the common case: inside an active line
                return
        elif self.check_blank_data and (first or second):
            self._report("blank_data", n, f"data pins carry {first:#05x}/{second:#05x} outside de "
                                          f"(expected 0 during blanking)")

        if hs != self._prev_hs:
            if hs:
                self._hsync_lead(n)
            else:
                self._hsync_trail(n)
        if vs != self._prev_vs:
            if vs:
                self._vsync_lead(n, hs and not self._prev_hs)
            else:
                self._vsync_trail(n, hs and not self._prev_hs)
        if de != self._prev_de:
            if de:
                self._de_rise_at(n)
                self._pixels.append(first | (second << 12))
            else:
                self._de_fall_at(n)
        self._prev_hs, self._prev_vs, self._prev_de = hs, vs, bool(de)

    def feed(self, samples):
        """Many clocks at once: an iterable of ``(hsync, vsync, de, first, second)`` tuples."""
        sample = self.sample
        for s in samples:
            sample(*s)

    def feed_columns(self, hsync, vsync, de, first, second):
        """Many clocks at once as arrays, one element per pixel clock: the same as :meth:`sample` clock by clock,
        with each run of steady clocks done in one step: inside an active line (de high on this clock and the one
        before, both syncs inactive on both: the pixel is appended) or in a blanking interval (de low on both,
        the syncs unchanged, both words 0: nothing to do)."""
        hsync, vsync, de = (np.asarray(a, dtype=bool) for a in (hsync, vsync, de))
        first, second = np.asarray(first, dtype=np.int64), np.asarray(second, dtype=np.int64)
        hs, vs = hsync == bool(self._hs_on), vsync == bool(self._vs_on)

        def before(a, last):
            return np.concatenate(([last], a[:-1]))
        idle = de & ~hs & ~vs
        inside = idle & before(idle, self._prev_de and not self._prev_hs and not self._prev_vs)
        quiet = (~de & ~before(de, self._prev_de) & (hs == before(hs, self._prev_hs))
                 & (vs == before(vs, self._prev_vs)) & (first == 0) & (second == 0))
        words = first | (second << 12)
        edges = np.flatnonzero(~(inside | quiet))
        columns = zip(edges.tolist(), hsync[edges].tolist(), vsync[edges].tolist(), de[edges].tolist(),
                      first[edges].tolist(), second[edges].tolist())
        start = 0
        for i, *pins in columns:
            self._steady(words, de, start, i)
            self.sample(*pins)
            start = i + 1
        self._steady(words, de, start, len(de))

    def _steady(self, words, de, start, stop):
        """Clocks ``start`` .. ``stop - 1``, all inside one active line or all in one blanking interval."""
        if stop > start:
            if de[start]:
                self._pixels.extend(words[start:stop].tolist())
            self.clock += stop - start

    # -- edges ----------------------------------------------------------------------------------------------

    def _hsync_lead(self, n):
        t = self.timing
        if self._hs_lead is not None:
            self._measure("line_clocks", n - self._hs_lead, t.h_total, n, "line length",
                          "clocks between hsync leading edges")
        if self._de_fall is not None and (self._hs_lead is None or self._de_fall > self._hs_lead):
            self._measure("h_front", n - self._de_fall, t.h_front, n, "horizontal front porch",
                          "clocks from de falling edge to hsync leading edge")
        self._hs_lead = n
        if self._hs_since_de_fall is not None:
            self._hs_since_de_fall += 1
        if self._hs_since_vs_trail is not None:
            self._hs_since_vs_trail += 1
        if self._vs_lead is not None and self._prev_vs:
            self._vs_lines += 1

    def _hsync_trail(self, n):
        if self._hs_lead is not None:
            self._measure("hsync_clocks", n - self._hs_lead, self.timing.h_sync, n, "hsync width", "clocks")
        self._hs_trail = n

    def _vsync_lead(self, n, with_hsync_lead):
        t = self.timing
        if not with_hsync_lead:
            self._report("vsync_alignment", n, "vsync leading edge does not coincide with an hsync leading "
                         f"edge ({self._since(self._hs_lead, n)} after the last one)")
        if self._hs_since_de_fall is not None:
            # the coinciding hsync leading edge was already counted: it is not "strictly between"
            between = self._hs_since_de_fall - (1 if with_hsync_lead else 0)
            self._measure("v_front", between, t.v_front, n, "vertical front porch",
                          "hsync leading edges between the last active line and the vsync leading edge")
        if self._in_frame:
            self._end_frame_early(n, "vsync pulse started")
        self._vs_lead = n
        self._vs_lines = 1 if with_hsync_lead else 0
        self._hs_since_vs_trail = None

    def _vsync_trail(self, n, with_hsync_lead):
        t = self.timing
        if not with_hsync_lead:
            self._report("vsync_alignment", n, "vsync trailing edge does not coincide with an hsync leading "
                         f"edge ({self._since(self._hs_lead, n)} after the last one)")
        if self._vs_lead is not None:
            lines = self._vs_lines - (1 if with_hsync_lead else 0)
            self._measure("vsync_clocks", n - self._vs_lead, t.v_sync * t.h_total, n, "vsync width", "clocks")
            self._measure("vsync_lines", lines, t.v_sync, n, "vsync width",
                          "hsync leading edges inside the vsync pulse")
        self._vs_trail = n
        self._hs_since_vs_trail = 0
        self._armed = True

    def _de_rise_at(self, n):
        t = self.timing
        if self._hs_trail is not None and (self._de_fall is None or self._hs_trail > self._de_fall):
            self._measure("h_back", n - self._hs_trail, t.h_back, n, "horizontal back porch",
                          "clocks from hsync trailing edge to de rising edge")
        self._de_rise = n
        self._pixels = []
        if self._armed:
            self._armed = False
            if self._hs_since_vs_trail is not None:
                self._measure("v_back", self._hs_since_vs_trail, t.v_back, n, "vertical back porch",
                              "hsync leading edges between the vsync trailing edge and the first active line")
            self._hs_since_vs_trail = None
            if self._frame_start_clock is not None:
                self._measure("frame_clocks", n - self._frame_start_clock, t.clocks_per_frame, n,
                              "frame length", "clocks from first active pixel to first active pixel")
            self._frame_start_clock = n
            self._frame_index += 1
            self._in_frame = True
            self._row = 0
            self._frame = np.zeros((t.v_active, t.h_active, 3), dtype=np.uint8)
        elif self._in_frame and self._row >= t.v_active:
            self._report("active_lines", n, f"more than {t.v_active} active lines in the frame")

    def _de_fall_at(self, n):
        t = self.timing
        width = n - self._de_rise
        self._measure("active_pixels", width, t.h_active, n, "active line length", "clocks with de high")
        self._de_fall = n
        self._hs_since_de_fall = 0
        if not self._in_frame or self._row >= t.v_active:
            self._pixels = []
            return
        words = np.array(self._pixels[:t.h_active], dtype=np.uint32)
        self._pixels = []
        first = words & 0xFFF
        second = words >> 12
        row = self._frame[self._row]
        w = len(words)
        row[:w, 0] = second >> 4                                   # R[7:0]
        row[:w, 1] = ((second & 0xF) << 4) | (first >> 8)          # G[7:4] G[3:0]
        row[:w, 2] = first & 0xFF                                  # B[7:0]
        self._row += 1
        if self._row == t.v_active:
            self.observed["active_lines"][self._row] += 1
            self._in_frame = False
            self.frames_completed += 1
            self.frames.append(self._frame)
            if self.keep_frames is not None and len(self.frames) > self.keep_frames:
                del self.frames[0]
            if self.on_frame is not None:
                self.on_frame(self._frame_index, self._frame)
            self._frame = None

    def _end_frame_early(self, n, why):
        t = self.timing
        self.observed["active_lines"][self._row] += 1
        self._report("active_lines", n, f"frame has {self._row} active lines, expected {t.v_active} ({why})")
        self._in_frame = False
        self._frame = None

    def _polarity(self, n, hs, vs):
        t = self.timing
        if hs:
            level = "high" if self._hs_on else "low"
            self._report("hsync_polarity", n, f"hsync is {level} (its active level for "
                         f"{'positive' if t.hsync_positive else 'negative'} polarity) during active video: "
                         f"wrong polarity or a pulse inside the active area")
        if vs:
            level = "high" if self._vs_on else "low"
            self._report("vsync_polarity", n, f"vsync is {level} (its active level for "
                         f"{'positive' if t.vsync_positive else 'negative'} polarity) during active video: "
                         f"wrong polarity or a pulse inside the active area")

    # -- bookkeeping ----------------------------------------------------------------------------------------

    @staticmethod
    def _since(previous, n):
        return "no earlier one" if previous is None else f"{n - previous} clocks"

    def _measure(self, key, value, expected, n, what, unit):
        self.observed[key][value] += 1
        if value != expected:
            self._report(key, n, f"{what} is {value}, expected {expected} ({unit})")

    def _report(self, kind, n, message):
        self.violation_counts[kind] += 1
        if self.violation_counts[kind] <= self.max_reports:
            line = self._row - 1 if self._in_frame and self._row > 0 else -1
            self.violations.append(Violation(kind, n, self._frame_index, line, message))

    def report_violation(self, kind, message):
        """Record a violation found by a driver (e.g. a wrong XCLK level) at the current clock."""
        self._report(kind, self.clock, message)

    # -- results --------------------------------------------------------------------------------------------

    @property
    def ok(self):
        """True when no violation has been seen."""
        return not self.violation_counts

    def report(self):
        """A human-readable summary: the counts per kind, then the first violations of each kind."""
        if self.ok:
            return (f"hdmi sink: {self.clock} clocks, {self.frames_completed} complete frame(s), "
                    f"no timing violations")
        lines = [f"hdmi sink: {sum(self.violation_counts.values())} violation(s) in {self.clock} clocks: " +
                 ", ".join(f"{k} x{v}" for k, v in sorted(self.violation_counts.items()))]
        lines += [f"  {v}" for v in self.violations]
        return "\n".join(lines)

    def check(self):
        """Raise :class:`SinkError` with :meth:`report` if any violation was seen."""
        if not self.ok:
            raise SinkError(self.report())

    def write_png(self, path, index=-1):
        """Write one rebuilt frame (default: the last) as a PNG."""
        if not self.frames:
            raise SinkError(f"no complete frame to write ({self.report()})")
        return write_png(self.frames[index], path)


# -- Amaranth simulator driver ------------------------------------------------------------------------------

def amaranth_sink_testbench(sink, pins, clocks=None, progress=None, progress_every=10_000):
    """An Amaranth async testbench feeding ``sink`` from the CH7301C pins.

    ``pins`` is any object with ``data``, ``hsync``, ``vsync``, ``de``, ``xclk_p`` signals (e.g. a
    :class:`hdl.display_path.DisplayPath`). The testbench waits for each rising edge of ``xclk_p``, reads the syncs,
    de and the rising-edge word once the design has settled, then waits for the falling edge and reads the
    falling-edge word. It samples ``clocks`` pixel clocks (``None``: forever; then bound the simulation).
    ``progress(clocks_done)`` is called every ``progress_every`` clocks if given.
    """
    async def testbench(ctx):
        # A testbench resumes after the design has settled, so ctx.get sees the values that follow the edge
        # (Trigger.sample() would return the values from before the edge).
        get, sample = ctx.get, sink.sample
        rising, falling = ctx.posedge(pins.xclk_p), ctx.negedge(pins.xclk_p)
        n = 0
        while clocks is None or n < clocks:
            await rising
            hs, vs, de, first = get(pins.hsync), get(pins.vsync), get(pins.de), get(pins.data)
            await falling
            sample(hs, vs, de, first, get(pins.data))
            n += 1
            if progress is not None and n % progress_every == 0:
                progress(n)
    return testbench


# -- cocotb driver -------------------------------------------------------------------------------------------

class CocotbSink:
    """Samples the CH7301C pins (``pins``: cocotb handles ``data``, ``hsync``, ``vsync``, ``de``, ``xclk_p``,
    ``xclk_n``, e.g. ``sim.runners.cocotb.TopPorts(dut).ch7301c``) into a :class:`HdmiSink`, fast enough for full
    1080p frames.

    The driver aligns itself to a rising edge of ``xclk_p`` and then samples every half period,
    ``period_ps / 4`` after each XCLK edge: in the middle of the high phase it reads ``xclk_p``, ``xclk_n``,
    ``hsync``, ``vsync``, ``de`` and the rising-edge word, in the middle of the low phase ``xclk_p``,
    ``xclk_n`` and the falling-edge word. Mid-phase is where the words are stable (and where the CH7301C
    latches them once XCLK is delayed into the data eye), so no ``ReadOnly`` phase is needed: two ``Timer``
    awaits per pixel clock instead of four edge/``ReadOnly`` awaits. The XCLK levels are checked at every
    sample (``xclk`` violations), so a stopped, inverted or mis-timed clock cannot go unnoticed, and an X or Z
    on any pin stops the run with :class:`SinkError`.

    Values are read as binary strings straight from the simulator handle (``handle._handle``: cocotb's GPI
    object; the public ``handle.value`` builds a ``LogicArray`` per read, several times slower in this loop).
    ``python -m bench display`` gives the rate.

    ``progress_file``: if given, ``"<done> <total>"`` is written there every ``progress_every`` clocks (a
    parent process shows it as a progress bar).
    """

    def __init__(self, pins, sink, *, period_ps, progress_file=None, progress_every=50_000):
        if period_ps % 4:
            raise ValueError("period_ps must be a multiple of 4 ps so the quarter-period sample points are exact")
        self.sink = sink
        self.period_ps = period_ps
        self.pins = {name: getattr(pins, name) for name in ("data", "hsync", "vsync", "de", "xclk_p", "xclk_n")}
        self.progress_file = progress_file
        self.progress_every = progress_every

    @staticmethod
    def _reader(handle):
        gpi = getattr(handle, "_handle", None)
        if gpi is not None and hasattr(gpi, "get_signal_val_binstr"):
            return gpi.get_signal_val_binstr
        return lambda: str(handle.value)            # public API fallback (slower)

    async def run(self, clocks):
        """Sample ``clocks`` pixel clocks, starting at the next rising edge of ``xclk_p``."""
        from cocotb.triggers import RisingEdge, Timer
        p = self.pins
        data, hsync, vsync, de = (self._reader(p[n]) for n in ("data", "hsync", "vsync", "de"))
        xp, xn = self._reader(p["xclk_p"]), self._reader(p["xclk_n"])
        sink = self.sink
        sample = sink.sample
        high_ok = {"10" + a + b + c for a in "01" for b in "01" for c in "01"}
        half = Timer(self.period_ps // 2, "ps")

        await RisingEdge(p["xclk_p"])
        await Timer(self.period_ps // 4, "ps")
        every = self.progress_every if self.progress_file else clocks
        done = 0
        while done < clocks:
            chunk = min(every, clocks - done)
            for _ in range(chunk):
                hi = xp() + xn() + hsync() + vsync() + de()
                first = data()
                await half
                lo = xp() + xn()
                second = data()
                await half
                if hi not in high_ok or lo != "01":
                    self._bad_levels(hi, lo, first, second)
                try:
                    sample(hi[2] == "1", hi[3] == "1", hi[4] == "1", int(first, 2), int(second, 2))
                except ValueError:
                    raise SinkError(f"X/Z on the data pins at clock {sink.clock}: {first!r} / {second!r}") \
                        from None
            done += chunk
            if self.progress_file:
                _write_progress(self.progress_file, done, clocks)
        return sink

    def _bad_levels(self, hi, lo, first, second):
        if any(c not in "01" for c in hi + lo):
            raise SinkError(f"X/Z on xclk/hsync/vsync/de at clock {self.sink.clock}: xclk_p/xclk_n/hsync/vsync/de "
                            f"= {hi!r} in the high phase, xclk_p/xclk_n = {lo!r} in the low phase")
        self.sink.report_violation(
            "xclk", f"xclk_p/xclk_n are {hi[0]}/{hi[1]} a quarter period after the rising edge and {lo[0]}/{lo[1]} "
                    f"a quarter period after the falling edge (expected 1/0 then 0/1)")


def _write_progress(path, done, total):
    tmp = f"{path}.tmp"
    with open(tmp, "w") as f:
        f.write(f"{done} {total}\n")
    os.replace(tmp, path)
