"""A compiler wrapper that keeps Verilator's runtime objects between builds (``OBJCACHE`` of ``verilated.mk``).

Every Verilator build compiles the same runtime library beside its model -- ``verilated.cpp``,
``verilated_vpi.cpp``, ``verilated_timing.cpp``, ... from the wheel's ``include`` directory -- about 13 s of a
cocotb build (the model of a small design takes less). ``verilated.mk`` prefixes every compile with
``$(OBJCACHE)``; :mod:`sim.runners.cocotb` sets it to this script, which

* compiles a source outside Verilator's ``include`` directory (the model, the precompiled header, cocotb's
  ``verilator.cpp``, which includes the model's header) as if it were not there;
* for a runtime source, keys the object by the whole compile command (optimisation, the ``-D`` switches of the
  build: tracing, timing, coverage), the source and ``verilated_config.h`` (Verilator's version) and the compiler
  program, and copies the object and its ``.d`` file from ``<cache>/<key>/`` when an earlier build made them, or
  compiles and stores them there.

Usage (what ``make`` runs): ``python objcache.py CACHE_DIR COMPILER ARGS...``. Only the standard library: it runs
under the build's ``make``, not inside the project.
"""

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path


def _key(args, source, include):
    h = hashlib.sha256()
    out = args.index("-o") + 1
    for i, arg in enumerate(args):
        h.update(b"\0" + (b"<out>" if i == out else arg.encode()))
    for path in (source, include / "verilated_config.h"):
        h.update(b"\0" + path.read_bytes())
    compiler = shutil.which(args[0])
    if compiler:
        st = os.stat(compiler)
        h.update(f"\0{os.path.realpath(compiler)}\0{st.st_size}\0{st.st_mtime_ns}".encode())
    return h.hexdigest()[:24]


def main(argv):
    cache, args = Path(argv[0]), argv[1:]
    include = Path(os.environ.get("VERILATOR_ROOT", "/nonexistent")).resolve() / "include"
    source = Path(args[-1]).resolve() if args else None
    if source is None or "-o" not in args or "-c" not in args or source.parent != include or not source.exists():
        os.execvp(args[0], args)
    obj = Path(args[args.index("-o") + 1])
    dep = obj.with_suffix(".d")
    entry = cache / _key(args, source, include)
    if (entry / "ok").exists():
        shutil.copyfile(entry / obj.name, obj)
        if (entry / dep.name).exists():
            shutil.copyfile(entry / dep.name, dep)
        return 0
    done = subprocess.run(args)
    if done.returncode != 0:
        return done.returncode
    cache.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(dir=cache, prefix=".tmp-"))
    shutil.copyfile(obj, tmp / obj.name)
    if dep.exists():
        shutil.copyfile(dep, tmp / dep.name)
    (tmp / "ok").write_text("ok\n")
    try:
        os.rename(tmp, entry)             # atomic; another build may have stored the same object first
    except OSError:
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
