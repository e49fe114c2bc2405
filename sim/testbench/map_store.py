"""The depth maps through the frame store, on the MIG model, without the display: what ``tests/test_map_store.py``
runs (docs/frame_store.md, "Depth maps in the store").

:class:`MapStoreBench` (``pix`` and ``mem`` domains) holds a :class:`~hdl.depth.DepthEngine` reading two image
pairs from block RAM (``pair`` chooses the pair a map reads: set it before ``start``), its reads granted in the
clocks a pseudo-random pattern leaves free (``grant_mask``, as :class:`sim.testbench.depth.DepthTestbench`: a
slower engine), a :class:`~hdl.map_writer.MapWriter` draining its ring into a :class:`~hdl.frame_store.
frame_store.FrameStore` with map buffers (one idle camera), the :class:`~sim.models.mig.MIGModel` behind it, and a
:class:`~hdl.map_window.MapWindow` on the held map whose ``result`` port the test reads as the compositor does.
"""

from amaranth import Cat, ClockDomain, DomainRenamer, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.memory import Memory

from hdl.depth import DepthEngine
from hdl.frame_store.frame_store import FrameStore
from hdl.frame_store.layout import FrameStoreLayout
from hdl.map_window import MapWindow
from hdl.map_writer import MapWriter
from sim.models.mig import MIGModel, layout_window

__all__ = ["MapStoreBench"]


class MapStoreBench:
    """``m``: the module (see the module docstring) for ``pairs`` (a list of (left, right) arrays of the buffers'
    size), the map writer a code every ``pace`` clocks at most, the store's map FIFO ``fifo_depth`` entries, the model
    ready after ``init_clocks`` (nothing is written before: the writer waits); ``layout``: the store's; signals ``start``, ``pair``, ``grant_mask`` (pix, in), ``writer_busy`` (out);
    ``window`` the map window (its ``take`` driven by the test, ``taken`` and ``valid`` from the store);
    ``model`` the MIG model."""

    def __init__(self, geometry, config, pairs, *, out_rows=4, pace=1, banks=4, fifo_depth=8, init_clocks=20):
        w, h = geometry.buf_width, geometry.buf_height
        self.layout = FrameStoreLayout(width=w, height=h, cameras=1, buffers=3, base=64, banks=banks, maps=3,
                                       map_bits=config.code_bits)
        self.m = m = Module()
        m.domains += [ClockDomain("pix"), ClockDomain("mem")]
        pix = DomainRenamer("pix")
        self.start, self.pair = Signal(), Signal(range(len(pairs)))
        self.grant_mask = Signal(8)
        self.engine = engine = DepthEngine(geometry, config, out_rows=out_rows)
        m.submodules.engine = pix(engine)
        lfsr = Signal(16, init=0xACE1)
        m.d.pix += lfsr.eq(Cat(lfsr[1:], lfsr[0] ^ lfsr[2] ^ lfsr[3] ^ lfsr[5]))
        for side, port, bits in ((0, engine.left, lfsr[:8]), (1, engine.right, lfsr[8:])):
            image = [int(v) for pair in pairs for v in pair[side].flat]
            mem = Memory(shape=geometry.grey_bits, depth=len(image), init=image)
            m.submodules[f"image_{side}"] = mem
            read = mem.read_port(domain="pix")
            m.d.comb += [port.grant.eq((bits & self.grant_mask) == 0),
                         read.addr.eq(self.pair * (w * h) + port.port.addr), port.port.data.eq(read.data)]
        self.writer = writer = MapWriter(geometry, config, out_rows=out_rows, pace=pace)
        m.submodules.map_writer = pix(writer)
        wiring.connect(m, writer.result, engine.result)
        m.d.comb += [engine.start.eq(self.start), writer.start.eq(self.start)]
        self.store = store = FrameStore(self.layout, geometry, streams=((0, True),), cam_domains=("pix",),
                                        map_slots=out_rows, map_fifo_depth=fifo_depth)
        m.submodules.store = store
        wiring.connect(m, writer.feed, store.map_feed)
        m.d.comb += writer.room.eq(store.map_room)
        self.window = window = MapWindow(geometry, config.code_bits, slots=out_rows,
                                         pixel_bits=8 * self.layout.map_layout.pixel_bytes)
        m.submodules.window = pix(window)
        wiring.connect(m, window.stream, store.map_stream)
        m.d.comb += [store.map_take.eq(window.take), window.taken.eq(store.map_taken),
                     window.valid.eq(store.map_valid)]
        self.model = MIGModel(af_depth=32, wdf_depth=32, **layout_window(self.layout), init_clocks=init_clocks)
        m.submodules.mig = DomainRenamer("mem")(self.model)
        wiring.connect(m, store.mig, self.model.user)
