"""CapturePath: one or two cameras' capture paths with their frame buffers (a test / integration wrapper).

For each camera ``c`` in ``cameras`` (default ``("a", "b")``): a :class:`~hdl.capture.CameraCapture` in the
``cam_<c>`` domain (the camera's PCLK) writing a :class:`~hdl.frame_buffer.FrameBuffer` whose read port is in
``read_domain`` (``pix`` by default). This is the left half of thesis figure 4.1.

Ports, per camera ``c``:

* ``cam_<c>_data[8]``, ``cam_<c>_lv``, ``cam_<c>_fv``: the sensor pins (``cam_<c>`` domain);
* ``cam_<c>_w_addr``, ``cam_<c>_w_data``, ``cam_<c>_w_en``: a copy of the frame-buffer write port, so a test
  bench can check every write (``cam_<c>`` domain);
* ``cam_<c>_frame_start``, ``cam_<c>_frame_done``, ``cam_<c>_frame_ok``, ``cam_<c>_frame_count``,
  ``cam_<c>_in_frame``: the capture's status (``cam_<c>`` domain);
* ``cam_<c>_r_addr`` -> ``cam_<c>_r_data``: the frame buffer's read port (``read_domain``, one clock of
  latency).

The clock domains are not created here: the parent (or, for a top-level export, Amaranth) provides
``cam_<c>`` and ``pix``; exported Verilog names their clocks ``cam_a_clk``, ``pix_clk`` and so on.
Latency: as :class:`~hdl.capture.CameraCapture` (write port) and :class:`~hdl.frame_buffer.FrameBuffer`
(read port).
"""

from amaranth import DomainRenamer, Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from .capture import CameraCapture
from .frame_buffer import FrameBuffer
from .params import SENSOR

__all__ = ["CapturePath"]

_STATUS = ("frame_start", "frame_done", "frame_ok", "frame_count", "in_frame")


class CapturePath(wiring.Component):
    def __init__(self, geometry=SENSOR, *, cameras=("a", "b"), r_byte_first=True, read_domain="pix",
                 init=()):
        if not cameras or len(set(cameras)) != len(cameras):
            raise ValueError(f"cameras must be distinct names, got {cameras!r}")
        self.geometry = geometry
        self.cameras = tuple(cameras)
        self.r_byte_first = r_byte_first
        self.read_domain = read_domain
        self._init = init
        members = {}
        for c in self.cameras:
            p = f"cam_{c}_"
            members.update({
                p + "data": In(8), p + "lv": In(1), p + "fv": In(1),
                p + "w_addr": Out(geometry.addr_bits), p + "w_data": Out(geometry.gray_bits), p + "w_en": Out(1),
                p + "frame_start": Out(1), p + "frame_done": Out(1), p + "frame_ok": Out(1),
                p + "frame_count": Out(16), p + "in_frame": Out(1),
                p + "r_addr": In(geometry.addr_bits), p + "r_data": Out(geometry.gray_bits),
            })
        super().__init__(members)

    def port(self, camera, name):
        """The port ``cam_<camera>_<name>``."""
        return getattr(self, f"cam_{camera}_{name}")

    def elaborate(self, platform):
        m = Module()
        for c in self.cameras:
            domain = f"cam_{c}"
            capture = DomainRenamer(domain)(CameraCapture(self.geometry, r_byte_first=self.r_byte_first))
            buffer = FrameBuffer(self.geometry, write_domain=domain, read_domain=self.read_domain,
                                 init=self._init)
            m.submodules[f"capture_{c}"] = capture
            m.submodules[f"buffer_{c}"] = buffer
            m.d.comb += [
                capture.data.eq(self.port(c, "data")),
                capture.lv.eq(self.port(c, "lv")),
                capture.fv.eq(self.port(c, "fv")),
                buffer.w_addr.eq(capture.w_addr),
                buffer.w_data.eq(capture.w_data),
                buffer.w_en.eq(capture.w_en),
                self.port(c, "w_addr").eq(capture.w_addr),
                self.port(c, "w_data").eq(capture.w_data),
                self.port(c, "w_en").eq(capture.w_en),
                buffer.r_addr.eq(self.port(c, "r_addr")),
                self.port(c, "r_data").eq(buffer.r_data),
            ]
            for name in _STATUS:
                m.d.comb += self.port(c, name).eq(getattr(capture, name))
        return m
