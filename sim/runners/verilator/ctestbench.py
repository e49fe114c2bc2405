"""The C++ testbench (``testbench.h`` through ``ctestbench.cpp``) from Python: :class:`CTestbench`.

One :class:`CTestbench` is one Verilated system with its testbench: the clocks run, the cameras replay and the recorder
samples in C++; Python sets inputs, starts clocks and cameras, and runs the simulation until a time, until a watched
output changes or until the recorder is full. Ports are named as the exported top names them, or by their path in
the top's signature. The NumPy arrays handed to the testbench (camera streams, the buffers it fills) are kept alive
here.
"""

import ctypes

import numpy as np

from board.export import flat_name

__all__ = ["CTestbench", "STIMULUS", "CLOCKS", "LIMIT", "WATCH", "RECORDED", "RECORD_BITS"]

#: The testbench's clocks, in its order (``mem``: MIG's clk0, bound in the DDR2 build only).
CLOCKS = ("sync", "pix", "cam_a", "cam_b", "mem")
#: :meth:`CTestbench.run`'s reasons to stop.
LIMIT, WATCH, RECORDED = 0, 1, 2
#: A stimulus record of the log (testbench.h ``Stimulus``).
STIMULUS = np.dtype([("evals", "<u8"), ("t", "<u8"), ("kind", "<u4"), ("a", "<u4"), ("b", "<u8")])
#: The recorder's word: field -> (lowest bit, width).
RECORD_BITS = {"first": (0, 12), "second": (12, 12), "de": (24, 1), "vsync": (25, 1), "hsync": (26, 1),
               "xclk_n_high": (27, 1), "xclk_p_high": (28, 1), "xclk_n_low": (29, 1), "xclk_p_low": (30, 1)}

_U64, _INT, _PTR = ctypes.c_uint64, ctypes.c_int, ctypes.c_void_p
_SIGNATURES = {
    "tb_new": (_PTR, []), "tb_free": (None, [_PTR]),
    "tb_port_count": (_INT, [_PTR]), "tb_port_name": (ctypes.c_char_p, [_PTR, _INT]),
    "tb_port_width": (_INT, [_PTR, _INT]), "tb_port_is_input": (_INT, [_PTR, _INT]),
    "tb_set": (None, [_PTR, _INT, _U64]), "tb_get": (_U64, [_PTR, _INT]),
    "tb_now": (_U64, [_PTR]), "tb_evals": (_U64, [_PTR]),
    "tb_bind_clock": (None, [_PTR, _INT, _INT, _U64]), "tb_start_clock": (None, [_PTR, _INT, _U64]),
    "tb_bind_camera": (None, [_PTR, _INT, _INT, _INT, _INT, _PTR, _U64, _PTR, _U64]),
    "tb_start_camera": (None, [_PTR, _INT]), "tb_camera_seen": (_U64, [_PTR, _INT]),
    "tb_bind_recorder": (None, [_PTR, _INT, _INT, _INT, _INT, _INT, _INT, _PTR]),
    "tb_record": (None, [_PTR, _U64]), "tb_recorded": (_U64, [_PTR]),
    "tb_watch": (_INT, [_PTR, _INT]), "tb_clear_watches": (None, [_PTR]), "tb_run": (_INT, [_PTR, _U64]),
    "tb_watch_falling_edges": (None, [_PTR, _INT]),
    "tb_logging": (None, [_PTR, _INT]), "tb_log_size": (_U64, [_PTR]), "tb_log_copy": (None, [_PTR, _PTR]),
    "tb_stimulus_bytes": (_INT, []),
}
_LIBRARIES = {}
#: The glibc tunable that reserves static TLS for many Verilator builds in one process (each is compiled with
#: ``-ftls-model=initial-exec``: ``sim.runners.verilator.build.PIC_OPTS``); the Makefile exports it.
STATIC_TLS_ENV = "GLIBC_TUNABLES=glibc.rtld.optional_static_tls=262144"


def _library(path):
    path = str(path)
    if path not in _LIBRARIES:
        try:
            lib = ctypes.CDLL(path)
        except OSError as exc:
            if "static TLS" not in str(exc):
                raise
            raise RuntimeError(f"{path}: no static TLS left in this process for another Verilator build (each one "
                               f"loaded keeps its thread-local state there): start the process with "
                               f"{STATIC_TLS_ENV}, as make does, or run fewer builds in it") from None
        for name, (restype, argtypes) in _SIGNATURES.items():
            fn = getattr(lib, name)
            fn.restype, fn.argtypes = restype, argtypes
        if lib.tb_stimulus_bytes() != STIMULUS.itemsize:
            raise RuntimeError(f"{path}: stimulus record of {lib.tb_stimulus_bytes()} bytes, expected "
                               f"{STIMULUS.itemsize}")
        _LIBRARIES[path] = lib
    return _LIBRARIES[path]


class CTestbench:
    """The Verilated system of a :class:`sim.runners.verilator.build.Build` with its C++ testbench (see the module
    docstring). ``log=True`` keeps the stimulus log (:meth:`stimulus`) for the raw model."""

    def __init__(self, build, *, log=False):
        self._lib = lib = _library(build.library)
        self._h = lib.tb_new()
        self.ports = {lib.tb_port_name(self._h, i).decode(): i for i in range(lib.tb_port_count(self._h))}
        self._index = dict(self.ports)              # names and paths already looked up
        self._wide = build.wide_ports
        self._limit = [1 << lib.tb_port_width(self._h, i) if lib.tb_port_is_input(self._h, i) else 0
                       for i in range(len(self.ports))]     # 0: an output
        lib.tb_watch_falling_edges(self._h, int(build.negedge))
        self._keep = []
        #: What is bound to which ports (for the raw model's configuration): ``{"clock": {index: (port, half_ps)},
        #: "camera": {index: (ports, words)}, "recorder": (ports, capacity)}``.
        self.bindings = {"clock": {}, "camera": {}, "recorder": None}
        lib.tb_logging(self._h, int(log))

    def close(self):
        if getattr(self, "_h", None):
            self._lib.tb_free(self._h)
            self._h = None

    def __del__(self):
        self.close()

    def port(self, name):
        """The index of a port, by its flat name or its path in the top's signature (``("bus", "dvi", "scl")``
        is ``bus__dvi__scl``: :func:`board.export.flat_name`)."""
        index = self._index.get(name)
        if index is None:
            flat = name if isinstance(name, str) else flat_name(name)
            if flat in self._wide:
                raise KeyError(f"port {flat!r} is wider than 64 bits: the C++ testbench leaves it alone")
            if flat not in self.ports:
                raise KeyError(f"the model has no port {flat!r}")
            index = self._index[name] = self.ports[flat]
        return index

    def width(self, name):
        """The width in bits of a port."""
        return self._lib.tb_port_width(self._h, self.port(name))

    def signed(self, name):
        """A port's value read as a two's-complement signed number."""
        value, bits = self[name], self.width(name)
        return value - (1 << bits) if value >> (bits - 1) else value

    def __getitem__(self, name):
        return self._lib.tb_get(self._h, self.port(name))

    def __setitem__(self, name, value):
        index, value = self.port(name), int(value)
        if not 0 <= value < self._limit[index]:
            raise ValueError(f"{name!r} is an output" if not self._limit[index] else
                             f"{value} does not fit {name!r} ({self._limit[index].bit_length() - 1} bits)")
        self._lib.tb_set(self._h, index, value)

    @property
    def now_ps(self):
        return self._lib.tb_now(self._h)

    @property
    def evals(self):
        return self._lib.tb_evals(self._h)

    # -- clocks, cameras, recorder ----------------------------------------------------------------------------

    def bind_clock(self, clock, port, half_ps):
        index, port = CLOCKS.index(clock), self.port(port)
        self.bindings["clock"][index] = (port, int(half_ps))
        self._lib.tb_bind_clock(self._h, index, port, int(half_ps))

    def start_clock(self, clock, first_rise_ps):
        self._lib.tb_start_clock(self._h, CLOCKS.index(clock), int(first_rise_ps))

    def bind_camera(self, index, pins, words, seen):
        """Camera ``index`` (0, 1) drives the ports ``pins`` (data, lv, fv names) from ``words`` (uint16
        ``{fv, lv, d}``) and keeps the pins at its rising edges in ``seen`` (uint16, any length)."""
        words = np.ascontiguousarray(words, dtype=np.uint16)
        if seen.dtype != np.uint16 or not seen.flags.c_contiguous:
            raise TypeError("seen must be a contiguous uint16 array")
        self._keep += [words, seen]
        ports = [self.port(p) for p in pins]
        self.bindings["camera"][index] = (ports, words)
        self._lib.tb_bind_camera(self._h, index, *ports, words.ctypes.data, len(words), seen.ctypes.data, len(seen))

    def start_camera(self, index):
        self._lib.tb_start_camera(self._h, index)

    def camera_seen(self, index):
        return self._lib.tb_camera_seen(self._h, index)

    def bind_recorder(self, pins, out):
        """The recorder samples the ports ``pins`` (data, hsync, vsync, de, xclk_p, xclk_n names) into ``out``
        (uint32)."""
        if out.dtype != np.uint32 or not out.flags.c_contiguous:
            raise TypeError("out must be a contiguous uint32 array")
        self._keep.append(out)
        self._recording = out
        ports = [self.port(p) for p in pins]
        self.bindings["recorder"] = (ports, len(out))
        self._lib.tb_bind_recorder(self._h, *ports, out.ctypes.data)

    def record(self, pixel_clocks):
        if pixel_clocks > len(self._recording):
            raise ValueError(f"the recorder's buffer holds {len(self._recording)} pixel clocks, not {pixel_clocks}")
        self._lib.tb_record(self._h, int(pixel_clocks))

    @property
    def recorded(self):
        return self._lib.tb_recorded(self._h)

    # -- running ------------------------------------------------------------------------------------------------

    def watch(self, names):
        """Replace the watched ports: :meth:`run` stops after an evaluation that changed one of them."""
        self._lib.tb_clear_watches(self._h)
        for name in names:
            if not self._lib.tb_watch(self._h, self.port(name)):
                raise ValueError(f"too many watched ports (at {name!r})")

    def run(self, limit_ps):
        """Simulate up to ``limit_ps`` (inclusive); returns why it stopped: :data:`LIMIT`, :data:`WATCH` (a
        watched port changed; the time is that of the evaluation that changed it) or :data:`RECORDED`."""
        return self._lib.tb_run(self._h, int(limit_ps))

    def stimulus(self):
        """The stimulus log so far (a :data:`STIMULUS` array)."""
        out = np.empty(self._lib.tb_log_size(self._h), dtype=STIMULUS)
        if len(out):
            self._lib.tb_log_copy(self._h, out.ctypes.data)
        return out
