"""CapturePath: one or two cameras' capture paths with their frame buffers (the left half of thesis figure 4.1).

For each camera ``c`` in ``cameras`` (default ``("a", "b")``): a :class:`~hdl.capture.CameraCapture` in the
``cam_<c>`` domain (the camera's PCLK) writing a :class:`~hdl.frame_buffer.FrameBuffer` whose read port is in
``read_domain`` (``pix`` by default). :class:`~hdl.system.StereoDepthSystem` is built on it, and the capture tests
and bench run it alone.
"""

from amaranth import DomainRenamer, Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.capture import CameraCapture, CameraSignature, CaptureStatusSignature, check_geometry as check_capture
from hdl.frame_buffer import FrameBuffer, FrameBufferReadSignature, FrameBufferWriteSignature
from spec.sensor import SENSOR
from hdl.signature import ParametricSignature

__all__ = ["CapturePortSignature", "CapturePath"]


class CapturePortSignature(ParametricSignature):
    """Everything of one camera's capture path, as the path presents it: ``pins`` (``In(CameraSignature)``, the
    sensor pins), ``write`` (``Out(FrameBufferWriteSignature)``, the write port the capture drives into its buffer,
    for testbenches to watch, or into the frame store), ``status`` (``Out(CaptureStatusSignature)``), all in the
    camera's domain, and with ``buffered`` ``read`` (``In(FrameBufferReadSignature)``, the buffer's read port, in
    the read domain)."""

    def __init__(self, geometry, buffered=True):
        super().__init__({
            "pins": In(CameraSignature),
            "write": Out(FrameBufferWriteSignature(geometry)),
            "status": Out(CaptureStatusSignature),
            **({"read": In(FrameBufferReadSignature(geometry))} if buffered else {}),
        }, geometry=geometry, buffered=buffered)


class CapturePath(wiring.Component):
    """Capture + frame buffer per camera.

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
        Its ``downscale`` chooses each capture's block (:class:`~hdl.capture.CameraCapture`): the thesis's kept pixel
        of each block in 5-bit grey, or the block's 8-bit mean.
    cameras : tuple of str
        Camera names; camera ``c`` is captured in domain ``cam_<c>`` and has the member ``cam_<c>``.
    r_byte_first : bool
        Byte order the captures expect (:class:`~hdl.capture.CameraCapture`).
    read_domain : str
        Domain of the buffers' read ports.
    init : sequence of int
        Initial contents of every buffer.
    buffers : bool
        The frame buffers; without them the path is the captures alone, their ``write`` ports for the parent to
        take (the frame store: docs/frame_store.md).

    Attributes
    ----------
    cam_<c> : ``Out(CapturePortSignature(geometry))``, one per camera
        The capture's ``pins``, ``write`` and ``status`` and the buffer's ``read`` port, connected to them.

    Clock domains: ``cam_<c>`` per camera and ``read_domain``, all defined by the parent (for a top-level export,
    Amaranth makes their clocks the ports ``cam_a_clk``, ``pix_clk``, ...). Latency: as
    :class:`~hdl.capture.CameraCapture` (write port) and :class:`~hdl.frame_buffer.FrameBuffer` (read port).

    Raises
    ------
    ValueError
        Camera names that are not distinct, or a geometry the captures reject.
    """

    def __init__(self, geometry=SENSOR, *, cameras=("a", "b"), r_byte_first=True, read_domain="pix", init=(),
                 buffers=True):
        if not cameras or len(set(cameras)) != len(cameras):
            raise ValueError(f"cameras must be distinct names, got {cameras!r}")
        check_capture(geometry)
        self.geometry = geometry
        self.cameras = tuple(cameras)
        self.r_byte_first = r_byte_first
        self.read_domain = read_domain
        self.init = tuple(init)
        self.buffers = buffers
        super().__init__({f"cam_{c}": Out(CapturePortSignature(geometry, buffers)) for c in self.cameras})

    def port(self, camera):
        """The member of camera ``camera``."""
        return getattr(self, f"cam_{camera}")

    def elaborate(self, platform):
        m = Module()
        for c in self.cameras:
            capture = CameraCapture(self.geometry, r_byte_first=self.r_byte_first)
            m.submodules[f"capture_{c}"] = DomainRenamer(f"cam_{c}")(capture)
            port = self.port(c)
            for name in ("pins", "status"):
                wiring.connect(m, wiring.flipped(getattr(port, name)), getattr(capture, name))
            if not self.buffers:
                wiring.connect(m, capture.write, wiring.flipped(port.write))
                continue
            buffer = FrameBuffer(self.geometry, write_domain=f"cam_{c}", read_domain=self.read_domain, init=self.init)
            m.submodules[f"buffer_{c}"] = buffer
            wiring.connect(m, capture.write, buffer.write, wiring.flipped(port.write))
            wiring.connect(m, wiring.flipped(port.read), buffer.read)
        return m
