"""The display path on its own: SyncGenerator -> PatternGenerator -> CH7301COutput (CH7301C pins out)."""

from amaranth.hdl import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import Out

from hdl.ch7301c_output import CH7301COutput, CH7301CSignature, check_ddr
from spec.video import CEA_1080P60
from hdl.pattern_gen import PatternGenerator, check_active
from hdl.sync_gen import SyncGenerator, check_timing

__all__ = ["DisplayPath", "DISPLAY_PATH_LATENCY"]

#: Clocks from a raster position on the sync generator to that pixel on the pins (pattern 1 + output 1).
DISPLAY_PATH_LATENCY = 2


class DisplayPath(wiring.Component):
    """Test pattern on the CH7301C bus: the design the display demo, tests and bench use.

    ``SyncGenerator(timing)`` -> ``PatternGenerator(timing)`` -> ``CH7301COutput(timing, ddr=ddr)``.

    Parameters
    ----------
    timing : :class:`spec.video.VideoTiming`
    ddr : str
        ``"behavioural"`` or ``"virtex5"`` (:class:`~hdl.ch7301c_output.CH7301COutput`).
    start : (int, int)
        The sync generator's raster position after reset.

    Attributes
    ----------
    ch7301c : ``Out(CH7301CSignature)``
        The output stage's pins (:class:`~hdl.ch7301c_output.CH7301COutput` gives the dual-edge format).
    frame_start : ``Out(1)``
        The sync generator's strobe, for testbenches and triggers.

    Clock domain: ``sync`` (the pixel clock; a board top level renames it to ``pix``).
    Latency: :data:`DISPLAY_PATH_LATENCY` = 2 clocks from raster position to pins (``frame_start`` is not
    delayed: it is high two clocks before pixel (0, 0) reaches the pins). From reset, the pins carry
    2 blank clocks, then the first pixel of frame 0. ``start`` is the sync generator's raster position after
    reset (simulation windows; see :class:`hdl.sync_gen.SyncGenerator`). The three blocks are the submodules
    ``sync_gen``, ``pattern``, ``output`` (their signals are named so in a dump).

    Raises
    ------
    ValueError
        Parameters one of the three blocks rejects.
    """

    ch7301c: Out(CH7301CSignature)
    frame_start: Out(1)

    def __init__(self, timing=CEA_1080P60, *, ddr="behavioural", start=(0, 0)):
        check_timing(timing, start)
        check_active(timing)
        check_ddr(ddr)
        self.mode = timing
        self.ddr = ddr
        self.start = start
        super().__init__()

    def elaborate(self, platform):
        m = Module()
        m.submodules.sync_gen = sync_gen = SyncGenerator(self.mode, start=self.start)
        m.submodules.pattern = pattern = PatternGenerator(self.mode)
        m.submodules.output = output = CH7301COutput(self.mode, ddr=self.ddr)
        wiring.connect(m, sync_gen, pattern.timing)
        wiring.connect(m, pattern.video, output.video)
        wiring.connect(m, wiring.flipped(self.ch7301c), output.pins)
        m.d.comb += self.frame_start.eq(sync_gen.frame_start)
        return m
