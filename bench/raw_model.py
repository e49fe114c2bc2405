"""The raw reference model, for the system benchmark: the same Verilated system and C++ testbench run from
``bench/raw_main.cpp`` alone, to measure what the project's Python adds to the Verilator route.

:func:`run_raw` hands a finished :class:`sim.testbench.system.run_verilator.VerilatorRun` (a run's ``driver``, made
with ``sim.system.Verilator(keep_stimulus=True)``)
to the raw model: the same port bindings, each camera's stream as a file, and the run's stimulus log -- every input
the phases and the Python models set, with the number of evaluations before it -- so the raw model evaluates the
design at exactly the same points with exactly the same inputs, without Python. It returns the raw model's
figures and its recorded CH7301C pins, which must equal the project run's word for word.
"""

import hashlib
import json
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from sim.runners.verilator.build import CXX_OPTS, SOURCE_DIR, build, once, verilate

__all__ = ["build_raw", "raw_executable", "run_raw"]

RAW_MAIN = Path(__file__).resolve().parent / "raw_main.cpp"


def raw_executable(done):
    """The raw model's executable beside the build ``done`` (a :class:`sim.runners.verilator.build.Build`)."""
    return done.directory / "raw_model" / "raw"


def build_raw(setup, *, log=None):
    """The Verilator route's build for ``setup`` plus the raw model made from the same Verilog."""
    done = build(setup, log=log)
    stamp = done.directory / f"raw-{hashlib.sha256(RAW_MAIN.read_bytes()).hexdigest()[:12]}.stamp"
    once(stamp, lambda: verilate(done.directory, done.directory / "raw_model", "--exe", "-o", "raw", "-CFLAGS",
                                 f"{' '.join(CXX_OPTS)} -I{done.directory} -I{SOURCE_DIR}", RAW_MAIN),
         log and (lambda: log(f"building the raw model in {raw_executable(done).parent}")))
    return done


def _config(run, directory, stimulus=None):
    h = run.h
    lines = [f"clock {i} {port} {half}" for i, (port, half) in sorted(h.bindings["clock"].items())]
    for i, (ports, words) in sorted(h.bindings["camera"].items()):
        path = directory / f"camera_{i}.u16"
        words.astype("<u2").tofile(path)
        lines.append(f"camera {i} {' '.join(map(str, ports))} {path}")
    ports, capacity = h.bindings["recorder"]
    lines.append(f"recorder {' '.join(map(str, ports))} {capacity}")
    (h.stimulus() if stimulus is None else stimulus).tofile(directory / "stimulus.bin")
    lines.append(f"stimulus {directory / 'stimulus.bin'}")
    lines.append(f"output {directory / 'recording.u32'}")
    (directory / "raw.cfg").write_text("\n".join(lines) + "\n")
    return directory / "raw.cfg"


def run_raw(run, stimulus=None):
    """Run the raw model on ``run``'s stimulus (or on ``stimulus``, a :data:`sim.runners.verilator.ctestbench.STIMULUS`
    array). Returns ``(figures, recording)``: ``figures`` has the raw model's
    ``wall_s`` (its simulation), ``process_s`` (the whole process: loading the model and the files too),
    ``evals``, ``t_end_ps``, ``recorded``; ``recording`` its uint32 pin words."""
    raw = raw_executable(build_raw(run.setup))
    with tempfile.TemporaryDirectory(prefix="raw_") as tmp:
        config = _config(run, Path(tmp), stimulus)
        start = time.perf_counter()
        done = subprocess.run([str(raw), str(config)], capture_output=True, text=True)
        process = time.perf_counter() - start
        if done.returncode:
            raise RuntimeError(f"the raw model failed ({done.returncode}): {done.stderr.strip() or done.stdout}")
        figures = json.loads(done.stdout.strip().splitlines()[-1])
        figures["process_s"] = process
        recording = np.fromfile(Path(tmp) / "recording.u32", dtype="<u4")
    return figures, recording
