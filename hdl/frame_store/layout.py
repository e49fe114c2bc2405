"""FrameStoreLayout: where the camera frames live in the DDR2 (docs/frame_store.md, "Layout").

Each camera has ``buffers`` frame buffers spread over the DDR2's banks (each bank keeps a row of its own open, so
streams in different banks do not close each other's rows): with ``banks`` banks and ``cameras`` cameras, camera
``c`` has the ``n = banks // cameras`` banks from ``c * n`` (at least one), its buffer ``b`` in the
``(b mod n)``-th of them; the buffers of one bank lie one after another from ``base`` in it. So the two cameras'
frames -- the held pair every reader reads, the frames the writers write -- never share a bank, and a writer shares
a bank with its camera's held frame for one buffer pair in three (2 cameras x 3 buffers in 4 banks: camera 0 in
banks 0, 1, 0; camera 1 in banks 2, 3, 2). A buffer holds ``height`` rows ``stride`` bytes apart; a row holds
``width`` pixels, one byte each by default (the grey value in the low bits), so an 8-bit 800 x 600 build needs only other
sizes. ``stride`` is a whole number of BL4 bursts (32 bytes), so every row starts a burst and no burst spans two
rows; the bytes of a row's last burst beyond ``width`` are masked when written and ignored when read.

A pixel is ``pixel_bytes`` bytes (1 or 2; 2 for the depth maps' codes, which are wider than a byte: pixel ``x`` is
bytes ``pixel_bytes * x`` .. ``pixel_bytes * x + pixel_bytes - 1`` of its row, low byte first). With ``maps`` > 0
the store also holds ``maps`` depth-map buffers of ``width`` x ``height`` codes of ``map_bits`` bits
(:attr:`FrameStoreLayout.map_layout`: a layout of one "camera", the map writer's, laid out over the banks as a
camera's buffers are, from the first word after the cameras' buffers in every bank).

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
        Memory word address, within each bank, of the bank's first buffer (burst-aligned).
    banks : int
        Banks the buffers are spread over, 1 .. ``MIG.BANKS`` (1: all in bank 0, one after another).
    pixel_bytes : int
        Bytes a pixel, 1 or 2.
    maps : int
        Depth-map buffers (0: none; otherwise at least 3, as the map's :class:`~hdl.frame_store.ownership.
        BufferOwnership` with its one reader needs).
    map_bits : int
        A map code's bits (``DepthConfig.code_bits``, at most 16): the maps' ``pixel_bytes``.

    Raises
    ------
    ValueError
        A size below 1, a stride that is not a whole number of bursts or shorter than a row, a base that is not
        burst-aligned, a number of banks the part does not have, a pixel of other than 1 or 2 bytes, 1 or 2 map
        buffers, map codes wider than 16 bits, or buffers that do not fit in a bank.
    """
    width: int = 400
    height: int = 300
    cameras: int = 2
    buffers: int = 3
    stride: int | None = None
    base: int = 0
    banks: int = MIG.BANKS
    pixel_bytes: int = 1
    maps: int = 0
    map_bits: int = 8

    def __post_init__(self):
        for name in ("width", "height", "cameras", "buffers"):
            if getattr(self, name) < 1:
                raise ValueError(f"{name} must be at least 1, got {getattr(self, name)}")
        if self.pixel_bytes not in (1, 2):
            raise ValueError(f"pixel_bytes must be 1 or 2, got {self.pixel_bytes}")
        if self.maps and (self.maps < 3 or not 1 <= self.map_bits <= 16):
            raise ValueError(f"maps must be 0 or at least 3 buffers of codes of 1..16 bits, got {self.maps} of "
                             f"{self.map_bits}")
        if self.stride is None:
            object.__setattr__(self, "stride", -(-self.row_bytes // BURST_BYTES) * BURST_BYTES)
        if self.stride % BURST_BYTES or self.stride < self.row_bytes:
            raise ValueError(f"stride must be a multiple of {BURST_BYTES} bytes and at least a row's bytes "
                             f"({self.row_bytes}), got {self.stride}")
        if self.base < 0 or self.base % MIG.BURST_LENGTH:
            raise ValueError(f"base must be a burst-aligned memory word address, got {self.base}")
        if not 1 <= self.banks <= MIG.BANKS:
            raise ValueError(f"banks must be in 1..{MIG.BANKS}, got {self.banks}")
        per_camera = max(1, self.banks // self.cameras)
        places, filled = {}, [0] * self.banks
        for c in range(self.cameras):
            for b in range(self.buffers):
                bank = (c * per_camera + b % per_camera) % self.banks
                places[c, b] = (bank, filled[bank])
                filled[bank] += 1
        object.__setattr__(self, "_places", places)
        cameras_words = max(slot + 1 for _, slot in places.values()) * self.buffer_words
        if self.base + cameras_words > MIG.BANK_WORDS:
            raise ValueError(f"{max(filled)} buffers of {self.buffer_words} memory words from {self.base} do not "
                             f"fit in a bank's {MIG.BANK_WORDS} memory words")
        object.__setattr__(self, "_cameras_words", cameras_words)
        maps = None
        if self.maps:
            maps = FrameStoreLayout(width=self.width, height=self.height, cameras=1, buffers=self.maps,
                                    base=self.base + cameras_words, banks=self.banks,
                                    pixel_bytes=-(-self.map_bits // 8))
        object.__setattr__(self, "_map_layout", maps)

    @property
    def row_bytes(self):
        """Bytes of a row's pixels."""
        return self.width * self.pixel_bytes

    @property
    def pixels_per_burst(self):
        """Pixels a burst holds."""
        return BURST_BYTES // self.pixel_bytes

    @property
    def map_layout(self):
        """The depth maps' buffers as a layout of their own (one camera: the map writer; ``maps`` buffers;
        ``ceil(map_bits / 8)`` bytes a pixel; from the first memory word after the cameras' buffers in each bank),
        or ``None`` without maps."""
        return self._map_layout

    @property
    def bursts_per_row(self):
        """Bursts that hold a row's pixels (the row's last burst may be partly masked)."""
        return -(-self.row_bytes // BURST_BYTES)

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
    def bank_words(self):
        """The memory words from ``base`` that the fullest bank's buffers take, the maps' included (in every bank
        used, the same window holds its buffers: a memory model keeps these words of banks 0 .. ``banks_used`` -
        1)."""
        if self._map_layout is None:
            return self._cameras_words
        return self._cameras_words + self._map_layout.bank_words

    @property
    def banks_used(self):
        """Banks 0 .. ``banks_used`` - 1 hold the buffers."""
        used = max(bank for bank, _ in self._places.values()) + 1
        return used if self._map_layout is None else max(used, self._map_layout.banks_used)

    def bank_of(self, camera, buffer):
        """The bank holding camera ``camera``'s buffer ``buffer``."""
        return self._places[camera, buffer][0]

    def buffer_base(self, camera, buffer):
        """Memory word address of camera ``camera``'s buffer ``buffer``."""
        bank, slot = self._places[camera, buffer]
        return bank * MIG.BANK_WORDS + self.base + slot * self.buffer_words

    def burst_address(self, camera, buffer, row, burst):
        """Memory word address of burst ``burst`` of row ``row`` in a buffer."""
        return self.buffer_base(camera, buffer) + row * self.stride_words + burst * MIG.BURST_LENGTH

    def buffer_of(self, address):
        """``(camera, buffer)`` whose words hold memory word ``address`` (a map buffer ``b``: ``(cameras, b)``),
        or ``None`` outside the buffers."""
        bank, offset = divmod(address, MIG.BANK_WORDS)
        if not self.base <= offset < self.base + self._cameras_words:
            if self._map_layout is not None and self._map_layout.buffer_of(address) is not None:
                return self.cameras, self._map_layout.buffer_of(address)[1]
            return None
        place = (bank, (offset - self.base) // self.buffer_words)
        return next((key for key, value in self._places.items() if value == place), None)


#: Small sizes for the tests: 40 x 6 (2 bursts a row, the second partly masked), 3 buffers.
SMALL_LAYOUT = FrameStoreLayout(width=40, height=6)
