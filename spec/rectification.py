"""The automatic rectification's constants: the vertical-offset estimator (docs/rectification.md)."""

from dataclasses import dataclass

__all__ = ["RectificationConfig", "RECTIFICATION", "SMALL_RECTIFICATION"]


@dataclass(frozen=True)
class RectificationConfig:
    """The row-profile search for the vertical offset between the two buffers (docs/rectification.md).

    Offsets -``search_rows`` .. ``search_rows`` buffer rows are tried on the rows of the window
    ``search_rows + 1 .. height - search_rows - 1`` (the same rows for every offset, every read inside the image).
    """
    search_rows: int = 16       # R: offsets -R..R buffer rows (the goal: at least +-16)
    margin_shift: int = 2       # clear minimum: c2 - c1 > c2 >> margin_shift (the best 25 % below the rest)
    texture_shift: int = 5      # texture: T >= (width * window rows) >> texture_shift (1/32 grey per pixel per row)
    switch_shift: int = 3       # a new offset must beat the one in use: C(in use) - c1 > C(in use) >> switch_shift
    stable_frames: int = 2      # frames in a row that must agree on a new offset before it is taken

    def window(self, height):
        """The rows y of the profile derivative compared (range): R + 1 .. height - R - 1."""
        return range(self.search_rows + 1, height - self.search_rows)

    def check(self, height):
        """``ValueError`` unless the configuration fits buffers ``height`` rows high."""
        if self.search_rows < 1:
            raise ValueError(f"search_rows must be at least 1, not {self.search_rows}")
        if len(self.window(height)) < 1:
            raise ValueError(f"a search over +-{self.search_rows} rows needs buffers at least "
                             f"{2 * self.search_rows + 2} rows high, not {height}")
        if self.stable_frames < 1:
            raise ValueError(f"stable_frames must be at least 1, not {self.stable_frames}")
        for name in ("margin_shift", "texture_shift", "switch_shift"):
            if getattr(self, name) < 0:
                raise ValueError(f"{name} must not be negative, not {getattr(self, name)}")


#: The board's estimator: +-16 buffer rows (+-64 sensor rows) on the 400 x 300 buffers.
RECTIFICATION = RectificationConfig()
#: For SMALL_SENSOR's 16 x 12 buffers: +-3 rows (window rows 4..8).
SMALL_RECTIFICATION = RectificationConfig(search_rows=3)
