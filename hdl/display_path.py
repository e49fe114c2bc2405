"""The display path on its own: SyncGenerator -> PatternGenerator -> CH7301COutput (CH7301C pins out)."""

from amaranth.hdl import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import Out

from hdl.ch7301c_output import CH7301COutput, CH7301CSignature
from hdl.forward import forward
from spec.video import CEA_1080P60
from hdl.pattern_gen import PatternGenerator
from hdl.sync_gen import SyncGenerator

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
    sync_gen, pattern, output
        The three blocks, for testbenches and wave dumps.

    Clock domain: ``sync`` (the pixel clock; a board top level renames it to ``pix``).
    Latency: :data:`DISPLAY_PATH_LATENCY` = 2 clocks from raster position to pins (``frame_start`` is not
    delayed: it is high two clocks before pixel (0, 0) reaches the pins). From reset, the pins carry
    2 blank clocks, then the first pixel of frame 0. ``start`` is the sync generator's raster position after
    reset (simulation windows; see :class:`hdl.sync_gen.SyncGenerator`).
    """

    ch7301c: Out(CH7301CSignature)
    frame_start: Out(1)

    def __init__(self, timing=CEA_1080P60, *, ddr="behavioural", start=(0, 0)):
        self.mode = timing
        self.ddr = ddr
        self.start = start
        self.sync_gen = SyncGenerator(timing, start=start)
        self.pattern = PatternGenerator(timing)
        self.output = CH7301COutput(timing, ddr=ddr)
        super().__init__()
        forward(self, "ch7301c", self.output, "pins")
        forward(self, "frame_start", self.sync_gen)

    def elaborate(self, platform):
        m = Module()
        m.submodules.sync_gen = sync_gen = self.sync_gen
        m.submodules.pattern = pattern = self.pattern
        m.submodules.output = output = self.output
        wiring.connect(m, sync_gen, pattern.timing)
        wiring.connect(m, pattern.video, output.video)
        return m
