"""Video timing: the CEA-861 1080p60 mode the CH7301C drives and a small mode of the same structure for tests."""

from dataclasses import dataclass

from .board import CLOCKS

__all__ = ["VideoTiming", "CEA_1080P60", "SMALL_TIMING"]


@dataclass(frozen=True)
class VideoTiming:
    """Horizontal and vertical timing of one video mode, in pixel clocks and lines.

    A line is ``h_active`` pixels of data, then ``h_front`` porch, ``h_sync`` sync pulse, ``h_back`` porch.
    A frame is ``v_active`` lines, then ``v_front``, ``v_sync``, ``v_back`` lines. ``*_sync_positive`` is the
    pulse polarity (True: high during the pulse).
    """
    h_active: int
    h_front: int
    h_sync: int
    h_back: int
    v_active: int
    v_front: int
    v_sync: int
    v_back: int
    hsync_positive: bool = True
    vsync_positive: bool = True
    pixel_hz: int = CLOCKS.PIXEL_HZ

    @property
    def h_total(self):
        return self.h_active + self.h_front + self.h_sync + self.h_back

    @property
    def v_total(self):
        return self.v_active + self.v_front + self.v_sync + self.v_back

    @property
    def h_sync_start(self):
        return self.h_active + self.h_front

    @property
    def v_sync_start(self):
        return self.v_active + self.v_front

    @property
    def clocks_per_frame(self):
        return self.h_total * self.v_total

    @property
    def frame_hz(self):
        return self.pixel_hz / self.clocks_per_frame


#: CEA-861 1920x1080p @ 60 Hz (VIC 16): 2200 x 1125 at 148.5 MHz, exactly 60.00 Hz, positive syncs.
CEA_1080P60 = VideoTiming(
    h_active=1920, h_front=88, h_sync=44, h_back=148,
    v_active=1080, v_front=4, v_sync=5, v_back=36,
    hsync_positive=True, vsync_positive=True, pixel_hz=CLOCKS.PIXEL_HZ,
)

#: A small mode with the same structure, for fast tests of the same RTL (124 x 59 = 7316 clocks a frame;
#: its active area holds the default four-panel layout of SMALL_SENSOR's 16 x 12 buffers with SMALL_DEPTH).
SMALL_TIMING = VideoTiming(
    h_active=112, h_front=4, h_sync=3, h_back=5,
    v_active=52, v_front=2, v_sync=2, v_back=3,
    hsync_positive=True, vsync_positive=True, pixel_hz=CLOCKS.PIXEL_HZ,
)
