"""FrameStore: the cameras' frames in the DDR2 behind MIG, written by each camera and read as held pairs by the
display side (docs/frame_store.md): a :class:`~hdl.frame_store.camera_writer.CameraWriter` per camera, the
:class:`~hdl.frame_store.ownership.BufferOwnership`, a :class:`~hdl.frame_store.row_reader.RowReader` per read
stream, the :class:`~hdl.frame_store.arbiter.MemoryArbiter` in front of MIG.

The read streams share one hold: the pair taken by ``take`` (a pulse in the read domain, at the start of a display
frame) serves every stream until the next ``take``; ``taken`` pulses in the read domain once the hold has changed,
so rows asked for after ``taken`` come from the new pair. Before the first complete pair, rows read as zeros.

With ``layout.maps`` the store also holds the depth maps (docs/frame_store.md, "Depth maps in the store"): a map
writer path (a :class:`CameraWriter` of the maps' layout, fed in the read domain by
:class:`hdl.map_writer.MapWriter`), the maps' own :class:`BufferOwnership` (one "camera", one reader), and one read
stream of the held map (urgent: the compositor reads it), with a hold of its own (``map_take``, ``map_taken``,
``map_valid``).
"""

from dataclasses import replace

from amaranth import DomainRenamer, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.cdc import FFSynchronizer, PulseSynchronizer
from amaranth.lib.wiring import In, Out

from hdl.capture import CaptureStatusSignature
from hdl.frame_buffer import FrameBufferWriteSignature
from hdl.mig_user import MIGUserSignature
from hdl.signature import ParametricSignature
from spec.sensor import SENSOR

from .arbiter import MemoryArbiter
from .burst_packer import check_grey
from .camera_writer import CameraWriter
from .layout import FrameStoreLayout
from .ownership import BufferOwnership, check_ownership
from .row_reader import RowReader, RowStreamSignature

__all__ = ["FrameStore", "CameraFeedSignature"]


class CameraFeedSignature(ParametricSignature):
    """What a camera's capture gives the frame store, as the capture drives it: ``write``
    (``Out(FrameBufferWriteSignature(geometry))``) and ``status`` (``Out(CaptureStatusSignature)``)."""

    def __init__(self, geometry):
        super().__init__({"write": Out(FrameBufferWriteSignature(geometry)), "status": Out(CaptureStatusSignature)},
                         geometry=geometry)


class FrameStore(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    layout : :class:`hdl.frame_store.layout.FrameStoreLayout`
        Its ``cameras`` must match ``cam_domains``.
    geometry : :class:`spec.sensor.SensorGeometry`
        The captures' write ports.
    streams : sequence of (int, bool)
        One read stream per entry: the camera it reads and whether it is urgent (the display's: served before the
        writers; the others after them).
    slots : int
        Row slots of each stream's ring.
    cam_domains : sequence of str
        Camera ``c``'s domain.
    read_domain, mem_domain : str
    fifo_depth, read_depth : int
        The camera FIFOs' entries and the returning FIFOs' words.
    map_slots, map_fifo_depth : int
        With ``layout.maps``: the map stream's row slots, the map writer's FIFO entries.

    Attributes
    ----------
    cameras : ``In(CameraFeedSignature(geometry)).array(layout.cameras)``
        Camera ``c``'s in ``cam_domains[c]``.
    streams : ``In(RowStreamSignature(layout.height, layout.width, slots)).array(len(streams))``, ``read_domain``
    take : ``In(1)``, ``read_domain``
    taken : ``Out(1)``, ``read_domain``
    mig : ``Out(MIGUserSignature())``, ``mem_domain``
    map_feed : ``In(CameraFeedSignature(map_geometry))``, ``read_domain``
        With ``layout.maps``: the map writer's codes (``map_geometry``: ``geometry`` with ``layout.map_bits`` bits a
        pixel).
    map_stream : ``In(RowStreamSignature(height, width, map_slots, 8 * map_layout.pixel_bytes))``, ``read_domain``
    map_take, map_taken, map_valid : ``In(1)``, ``Out(1)``, ``Out(1)``, ``read_domain``
        With ``layout.maps``: hold the latest whole map; the hold has changed; a map is held (it changes only at a
        take, and reaches the read domain before ``map_taken``).
    map_room : ``Out(1)``, ``read_domain``
        With ``layout.maps``: the map writer's FIFO has room (:class:`CameraWriter`'s ``room``): write codes only
        while it is high.

    Latency: the parts'; ``taken`` a few clocks of both domains after ``take``.

    Raises
    ------
    ValueError
        No stream, a stream's camera outside the layout, ``cam_domains`` not one a camera, more than two cameras,
        the parts' checks.
    """

    def __init__(self, layout=FrameStoreLayout(), geometry=SENSOR, *, streams=((0, True), (1, True)), slots=4,
                 cam_domains=("cam_a", "cam_b"), read_domain="pix", mem_domain="mem", fifo_depth=8, read_depth=32,
                 map_slots=4, map_fifo_depth=8):
        streams = tuple((int(c), bool(u)) for c, u in streams)
        if not streams or any(not 0 <= c < layout.cameras for c, _ in streams):
            raise ValueError(f"streams must read cameras 0..{layout.cameras - 1}, got {streams}")
        if len(cam_domains) != layout.cameras:
            raise ValueError(f"{layout.cameras} cameras need as many domains, got {cam_domains}")
        check_grey(geometry)
        check_ownership(layout.cameras, 1, layout.buffers)
        self.layout, self.geometry, self.stream_list, self.slots = layout, geometry, streams, slots
        self.cam_domains, self.read_domain, self.mem_domain = tuple(cam_domains), read_domain, mem_domain
        self.fifo_depth, self.read_depth = fifo_depth, read_depth
        self.map_slots, self.map_fifo_depth = map_slots, map_fifo_depth
        maps = {}
        if layout.maps:
            self.map_geometry = replace(geometry, grey_bits=layout.map_bits)
            maps = {
                "map_feed": In(CameraFeedSignature(self.map_geometry)),
                "map_stream": In(RowStreamSignature(layout.height, layout.width, map_slots,
                                                    8 * layout.map_layout.pixel_bytes)),
                "map_take": In(1),
                "map_taken": Out(1),
                "map_valid": Out(1),
                "map_room": Out(1),
            }
        super().__init__({
            "cameras": In(CameraFeedSignature(geometry)).array(layout.cameras),
            "streams": In(RowStreamSignature(layout.height, layout.width, slots)).array(len(streams)),
            "take": In(1),
            "taken": Out(1),
            "mig": Out(MIGUserSignature()),
            **maps,
        })

    def elaborate(self, platform):
        m = Module()
        lay, mem = self.layout, self.mem_domain
        own = BufferOwnership(cameras=lay.cameras, readers=1, buffers=lay.buffers)
        m.submodules.ownership = DomainRenamer(mem)(own)
        # Urgent streams first: the arbiter serves its first `urgent` readers before the writers.
        order = sorted(range(len(self.stream_list)), key=lambda i: not self.stream_list[i][1])
        urgent = sum(u for _, u in self.stream_list)
        maps = bool(lay.maps)
        # The map stream (the compositor's) is urgent: after the cameras' urgent streams, before the writers; the map
        # writer comes last (it waits for room, and the engine for it).
        arbiter = MemoryArbiter(writers=lay.cameras + maps, readers=len(order) + maps, urgent=urgent + maps,
                                last_writers=int(maps))
        m.submodules.arbiter = DomainRenamer(mem)(arbiter)
        wiring.connect(m, wiring.flipped(self.mig), arbiter.mig)
        for c, domain in enumerate(self.cam_domains):
            writer = CameraWriter(lay, c, self.geometry, cam_domain=domain, mem_domain=mem,
                                  fifo_depth=self.fifo_depth)
            m.submodules[f"writer_{c}"] = writer
            wiring.connect(m, wiring.flipped(self.cameras[c].write), writer.write)
            wiring.connect(m, wiring.flipped(self.cameras[c].status), writer.status)
            wiring.connect(m, writer.own, own.writers[c])
            wiring.connect(m, writer.mem, arbiter.writers[c])
        hold = own.readers[0]
        for rank, i in enumerate(order):
            rank += maps and rank >= urgent                 # the map stream's rank is ``urgent``
            camera = self.stream_list[i][0]
            reader = RowReader(lay, camera, slots=self.slots, depth=self.read_depth, read_domain=self.read_domain,
                               mem_domain=mem)
            m.submodules[f"reader_{i}"] = reader
            wiring.connect(m, wiring.flipped(self.streams[i]), reader.stream)
            m.d.comb += [reader.hold.valid.eq(hold.valid), reader.hold.buffer.eq(hold.buffer[camera])]
            wiring.connect(m, reader.mem, arbiter.readers[rank])
        self._take(m, hold, self.take, self.taken)
        if maps:
            self._maps(m, arbiter, urgent)
        return m

    def _maps(self, m, arbiter, rank):
        """The depth maps: their writer (the read domain's feed into ``mem``), ownership, read stream and hold."""
        lay, mem = self.layout.map_layout, self.mem_domain
        own = BufferOwnership(cameras=1, readers=1, buffers=lay.buffers)
        m.submodules.map_ownership = DomainRenamer(mem)(own)
        writer = CameraWriter(lay, 0, self.map_geometry, cam_domain=self.read_domain, mem_domain=mem,
                              fifo_depth=self.map_fifo_depth, room=True)
        m.submodules.map_writer = writer
        m.d.comb += self.map_room.eq(writer.room)
        wiring.connect(m, wiring.flipped(self.map_feed.write), writer.write)
        wiring.connect(m, wiring.flipped(self.map_feed.status), writer.status)
        wiring.connect(m, writer.own, own.writers[0])
        wiring.connect(m, writer.mem, arbiter.writers[self.layout.cameras])
        hold = own.readers[0]
        reader = RowReader(lay, 0, slots=self.map_slots, depth=self.read_depth, read_domain=self.read_domain,
                           mem_domain=mem)
        m.submodules.map_reader = reader
        wiring.connect(m, wiring.flipped(self.map_stream), reader.stream)
        m.d.comb += [reader.hold.valid.eq(hold.valid), reader.hold.buffer.eq(hold.buffer[0])]
        wiring.connect(m, reader.mem, arbiter.readers[rank])
        self._take(m, hold, self.map_take, self.map_taken, "map_")
        # The hold's valid changes only at a take, two read-domain clocks after it; ``map_taken`` comes later.
        m.submodules.map_valid_sync = FFSynchronizer(hold.valid, self.map_valid, o_domain=self.read_domain)

    def _take(self, m, hold, take, taken, prefix=""):
        """``take`` into ``mem``; ``taken`` back once the ownership has answered (a clock after the take)."""
        m.submodules[f"{prefix}take_sync"] = to_mem = PulseSynchronizer(i_domain=self.read_domain,
                                                                         o_domain=self.mem_domain)
        m.submodules[f"{prefix}taken_sync"] = to_read = PulseSynchronizer(i_domain=self.mem_domain,
                                                                          o_domain=self.read_domain)
        answered = Signal(name=f"{prefix}answered")
        m.d[self.mem_domain] += answered.eq(to_mem.o)
        m.d.comb += [to_mem.i.eq(take), hold.take.eq(to_mem.o), to_read.i.eq(answered), taken.eq(to_read.o)]
