"""FrameStoreLayout: where the camera frames live in the DDR2 (docs/frame_store.md, "Layout").

Each camera has ``buffers`` frame buffers, one after another from ``base``; camera ``c``'s buffer ``b`` is buffer
number ``c * buffers + b``. A buffer holds ``height`` rows ``stride`` bytes apart; a row holds ``width`` pixels, one
byte each (the grey value in the low bits), so an 8-bit 800 x 600 build needs only other sizes. ``stride`` is a
whole number of BL4 bursts (32 bytes), so every row starts a burst and no burst spans two rows; the bytes of a
row's last burst beyond ``width`` are masked when written and ignored when read.

Addresses count 64-bit memory words, as MIG's ``app_af_addr`` does (:class:`spec.memory.MIG`).
"""

from dataclasses import dataclass

from spec.memory import MIG

__all__ = ["FrameStoreLayout", "SMALL_LAYOUT", "BURST_BYTES", "WORD_BYTES"]

#: Bytes in one BL4 burst (4 memory words of 64 bits) and in one user-interface word (128 bits).
BURST_BYTES = MIG.BURST_LENGTH * 8
WORD_BYTES = MIG.DATA_WIDTH // 8


@dataclass(frozen=True)
class FrameStoreLayout:
    """The frame store's geometry.

    Parameters
    ----------
    width, height : int
        Pixels per row and rows per frame.
    cameras : int
        Cameras (each with its own buffers).
    buffers : int
        Buffers per camera.
    stride : int or None
        Bytes from one row's start to the next's; ``None``: ``width`` rounded up to a whole burst.
    base : int
        Memory word address of the first buffer (burst-aligned).

    Raises
    ------
    ValueError
        A size below 1, a stride that is not a whole number of bursts or shorter than a row, a base that is not
        burst-aligned, or buffers that do not fit in the memory.
    """
    width: int = 400
    height: int = 300
    cameras: int = 2
    buffers: int = 3
    stride: int | None = None
    base: int = 0

    def __post_init__(self):
        for name in ("width", "height", "cameras", "buffers"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be at least 1, got {getattr(self, name)}")
        if self.stride is None:
            object.__setattr__(self, "stride", -(-self.width // BURST_BYTES) * BURST_BYTES)
        if self.stride % BURST_BYTES or self.stride < self.width:
            raise ValueError(f"stride must be a multiple of {BURST_BYTES} bytes and at least the width "
                             f"({self.width}), got {self.stride}")
        if self.base < 0 or self.base % MIG.BURST_LENGTH:
            raise ValueError(f"base must be a burst-aligned memory word address, got {self.base}")
        if self.end > MIG.MEMORY_WORDS:
            raise ValueError(f"{self.cameras} x {self.buffers} buffers of {self.buffer_words} memory words from "
                             f"{self.base} do not fit in {MIG.MEMORY_WORDS} memory words")

    @property
    def bursts_per_row(self):
        """Bursts that hold a row's pixels (the row's last burst may be partly masked)."""
        return -(-self.width // BURST_BYTES)

    @property
    def words_per_row(self):
        """User-interface words (128 bits) a row's bursts carry: 2 per burst."""
        return self.bursts_per_row * MIG.WORDS_PER_BURST

    @property
    def stride_words(self):
        """The stride in 64-bit memory words."""
        return self.stride // 8

    @property
    def buffer_words(self):
        """One buffer's size in 64-bit memory words."""
        return self.stride_words * self.height

    @property
    def end(self):
        """The memory word address after the last buffer."""
        return self.base + self.cameras * self.buffers * self.buffer_words

    def buffer_base(self, camera, buffer):
        """Memory word address of camera ``camera``'s buffer ``buffer``."""
        return self.base + (camera * self.buffers + buffer) * self.buffer_words

    def burst_address(self, camera, buffer, row, burst):
        """Memory word address of burst ``burst`` of row ``row`` in a buffer."""
        return self.buffer_base(camera, buffer) + row * self.stride_words + burst * MIG.BURST_LENGTH

    def buffer_of(self, address):
        """``(camera, buffer)`` whose words hold memory word ``address``, or ``None`` outside the buffers."""
        if not self.base <= address < self.end:
            return None
        number = (address - self.base) // self.buffer_words
        return divmod(number, self.buffers)


#: Small sizes for the tests: 40 x 6 (2 bursts a row, the second partly masked), 3 buffers.
SMALL_LAYOUT = FrameStoreLayout(width=40, height=6)
