"""CameraWriter: one camera's path into the frame store: the packer in the camera's domain, an asynchronous FIFO
into ``mem``, the burst writer there (docs/frame_store.md, "Camera writers")."""

from amaranth import DomainRenamer, Module
from amaranth.lib import wiring
from amaranth.lib.fifo import AsyncFIFO
from amaranth.lib.wiring import In, Out

from hdl.capture import CaptureStatusSignature
from hdl.frame_buffer import FrameBufferWriteSignature
from spec.memory import MIG
from spec.sensor import SENSOR

from .burst_packer import BurstPacker, burst_entry_layout, check_grey
from .burst_writer import BurstWriter, check_camera
from .layout import FrameStoreLayout
from .mem_port import BurstWriteSignature
from .ownership import WriterOwnershipSignature

__all__ = ["CameraWriter", "ROOM_ENTRIES", "FIFO_ENTRIES_PER_BURST"]

#: Entries ``room`` keeps free: the word a pixel written in the clock before ``room`` fell may still fill, an
#: ``END`` and a ``START``, and one for the level's own clock of lag.
ROOM_ENTRIES = 4
#: FIFO entries a burst takes: its memory words.
FIFO_ENTRIES_PER_BURST = MIG.BURST_LENGTH
assert 2 * FIFO_ENTRIES_PER_BURST > ROOM_ENTRIES, "the least FIFO (2 bursts) keeps room for more than ROOM_ENTRIES"


class CameraWriter(wiring.Component):
    """A :class:`~hdl.frame_store.burst_packer.BurstPacker` in ``cam_domain``, an :class:`amaranth.lib.fifo.AsyncFIFO`
    of ``fifo_depth`` bursts' entries (four memory words a burst, and frame marks: :data:`FIFO_ENTRIES_PER_BURST`
    ``fifo_depth`` entries; LUT RAM 32 entries deep costs as much as 8) into ``mem_domain`` and a
    :class:`~hdl.frame_store.burst_writer.BurstWriter` there.

    Parameters
    ----------
    layout : :class:`hdl.frame_store.layout.FrameStoreLayout`
    camera : int
        The camera's number in the layout.
    geometry : :class:`spec.sensor.SensorGeometry`
        The capture's write port.
    cam_domain, mem_domain : str
    fifo_depth : int
        Bursts the FIFO holds (a power of two): how many bursts the camera may run ahead of the memory's grants.
    room : bool
        Add the ``room`` port (for a source that can wait, the depth maps' writer; a camera cannot).

    Attributes
    ----------
    write : ``In(FrameBufferWriteSignature(geometry))``, ``cam_domain``
    status : ``In(CaptureStatusSignature)``, ``cam_domain``
    own : ``Out(WriterOwnershipSignature(layout.buffers))``, ``mem_domain``
    mem : ``Out(BurstWriteSignature())``, ``mem_domain``
    room : ``Out(1)``, ``cam_domain``
        With ``room=True``: the FIFO has room for :data:`ROOM_ENTRIES` more entries (its level as the write side
        counts it, a clock late): a source that writes only while ``room`` is high never loses a word.

    Latency: the packer's, the FIFO's (a few clocks of each domain), the burst writer's.

    Raises
    ------
    ValueError
        The packer's and the burst writer's checks; ``fifo_depth`` not a power of two of at least 2.
    """

    def __init__(self, layout=FrameStoreLayout(), camera=0, geometry=SENSOR, *, cam_domain="cam_a",
                 mem_domain="mem", fifo_depth=8, room=False):
        if fifo_depth < 2 or fifo_depth & (fifo_depth - 1):
            raise ValueError(f"fifo_depth must be a power of two of at least 2, got {fifo_depth}")
        check_grey(geometry, layout.pixel_bytes)
        check_camera(layout, camera)
        self.layout, self.camera, self.geometry = layout, camera, geometry
        self.cam_domain, self.mem_domain, self.fifo_depth = cam_domain, mem_domain, fifo_depth
        super().__init__({
            "write": In(FrameBufferWriteSignature(geometry)),
            "status": In(CaptureStatusSignature),
            "own": Out(WriterOwnershipSignature(layout.buffers)),
            "mem": Out(BurstWriteSignature()),
            **({"room": Out(1)} if room else {}),
        })

    def elaborate(self, platform):
        m = Module()
        packer = BurstPacker(self.layout, self.geometry)
        writer = BurstWriter(self.layout, self.camera)
        width = burst_entry_layout(self.layout).size
        entries = self.fifo_depth * FIFO_ENTRIES_PER_BURST
        fifo = AsyncFIFO(width=width, depth=entries, w_domain=self.cam_domain, r_domain=self.mem_domain)
        m.submodules.packer = DomainRenamer(self.cam_domain)(packer)
        m.submodules.fifo = fifo
        m.submodules.writer = DomainRenamer(self.mem_domain)(writer)
        wiring.connect(m, wiring.flipped(self.write), packer.write)
        wiring.connect(m, wiring.flipped(self.status), packer.status)
        m.d.comb += [
            fifo.w_data.eq(packer.entry.data), fifo.w_en.eq(packer.entry.en), packer.entry.rdy.eq(fifo.w_rdy),
            writer.entries.data.eq(fifo.r_data), writer.entries.rdy.eq(fifo.r_rdy), fifo.r_en.eq(writer.entries.en),
        ]
        wiring.connect(m, wiring.flipped(self.own), writer.own)
        wiring.connect(m, wiring.flipped(self.mem), writer.mem)
        if "room" in self.signature.members:
            m.d.comb += self.room.eq(fifo.w_level + ROOM_ENTRIES <= entries)
        return m
