"""The user's MIG core folder (``stereodepth verilog --mig DIR``): what the build takes from it, checked.

CoreGen writes a MIG 3.x core into ``DIR`` (the core's folder, ``ipcore_dir/<component name>``) with
``user_design/rtl/*.v`` (the core's RTL: its top module, named after the component, and about 20 ``ddr2_*.v``
files) and ``user_design/par/<component name>.ucf`` (its constraints) [freecores/genesys_ddr2
``rtl/ipcore_dir/MEMCtrl/user_design/rtl``; /work/shared/ddr2-facts.md]. :func:`read_mig_core` reads them and checks,
each failure a :class:`MIGCoreError` with one line naming what is missing or wrong:

* the folders and files exist (at least one ``.v``; one ``.ucf``, or ``<core name>.ucf`` among several);
* one file defines ``module <core name>`` and its port list has every port of :data:`board.mig.MIG_PORTS` in
  that direction (a core generated with "DCM enabled" has ``sys_clk_p`` / ``clk200_p`` in their place, and is
  named as such).

The files are read, never copied into this repository: the build copies them into its own folder (``mig/``).
"""

import re
from dataclasses import dataclass
from pathlib import Path

from board.mig import DEFAULT_CORE_NAME, MIG_PORTS

__all__ = ["MIGCoreError", "MIGCoreFiles", "read_mig_core", "module_ports", "RTL_FOLDER", "PAR_FOLDER"]

RTL_FOLDER = Path("user_design", "rtl")
PAR_FOLDER = Path("user_design", "par")

#: Ports of a core generated with "DCM enabled" (it makes its own clocks from a differential clock pair).
_DCM_ENABLED_PORTS = ("sys_clk_p", "sys_clk_n", "clk200_p", "clk200_n", "sys_clk", "idly_clk_200")


class MIGCoreError(ValueError):
    """A MIG core folder the build cannot use (one line: what is missing or wrong)."""


@dataclass(frozen=True)
class MIGCoreFiles:
    """A checked MIG core: ``rtl`` ``(file name, text)`` sorted by name, the UCF's name and text."""
    folder: Path
    core_name: str
    rtl: tuple
    ucf_name: str
    ucf_text: str


def _strip_comments(text):
    return re.sub(r"//[^\n]*", "", re.sub(r"/\*.*?\*/", "", text, flags=re.S))


def module_ports(text, name):
    """``{port: direction}`` of the ANSI-style port list of ``module name`` in the Verilog ``text``, or ``None``
    when the text does not define that module."""
    text = _strip_comments(text)
    start = re.search(rf"\bmodule\s+{re.escape(name)}\b", text)
    if start is None:
        return None
    end = text.find(");", start.end())
    header = text[start.end():end if end >= 0 else len(text)]
    declarations = re.finditer(r"\b(input|output|inout)\b\s*(?:wire|reg)?\s*(?:signed\s*)?(?:\[[^\]]*\]\s*)?"
                               r"(\w+(?:\s*,\s*(?!input|output|inout)\w+)*)", header)
    ports = {}
    for declaration in declarations:
        for port in re.split(r"\s*,\s*", declaration[2]):
            ports[port] = declaration[1]
    return ports


def _read(path):
    try:
        return path.read_text(errors="replace")
    except OSError as exc:
        raise MIGCoreError(f"cannot read {path}: {exc.strerror or exc}") from None


def _rtl_files(folder):
    rtl = folder / RTL_FOLDER
    if not rtl.is_dir():
        raise MIGCoreError(f"{folder} has no {RTL_FOLDER}/ (the core's RTL, from CoreGen's MIG: docs/board.md)")
    files = sorted(p for p in rtl.iterdir() if p.suffix == ".v" and p.is_file())
    if not files:
        raise MIGCoreError(f"{rtl} holds no .v file (generate the core with Verilog as its language)")
    return tuple((p.name, _read(p)) for p in files)


def _ucf_file(folder, core_name):
    par = folder / PAR_FOLDER
    if not par.is_dir():
        raise MIGCoreError(f"{folder} has no {PAR_FOLDER}/ (the core's UCF, from CoreGen's MIG: docs/board.md)")
    ucfs = sorted(p for p in par.iterdir() if p.suffix == ".ucf" and p.is_file())
    named = [p for p in ucfs if p.stem == core_name]
    if named:
        return named[0]
    if len(ucfs) == 1:
        return ucfs[0]
    if not ucfs:
        raise MIGCoreError(f"{par} holds no .ucf file (the core's constraints)")
    raise MIGCoreError(f"{par} holds {len(ucfs)} .ucf files and none is {core_name}.ucf: keep the core's own")


def _check_ports(rtl, core_name, folder):
    for file_name, text in rtl:
        ports = module_ports(text, core_name)
        if ports is not None:
            break
    else:
        raise MIGCoreError(f"no file in {folder / RTL_FOLDER} defines module {core_name} (the core's component "
                           "name: give it with --mig-name)")
    dcm = [p for p in _DCM_ENABLED_PORTS if p in ports]
    if dcm:
        raise MIGCoreError(f"module {core_name} ({file_name}) has port {dcm[0]}: the core was generated with the "
                           "DCM enabled; regenerate it with \"DCM disabled\" (docs/board.md)")
    missing = [p for p in MIG_PORTS if p not in ports]
    if missing:
        shown = ", ".join(missing[:4]) + (f" and {len(missing) - 4} more" if len(missing) > 4 else "")
        raise MIGCoreError(f"module {core_name} ({file_name}) lacks MIG's port(s) {shown}: not a MIG 3.x DDR2 "
                           "core with the settings of docs/board.md")
    wrong = [p for p, (direction, _) in MIG_PORTS.items() if ports[p] != direction]
    if wrong:
        raise MIGCoreError(f"module {core_name} ({file_name}) has port {wrong[0]} as {ports[wrong[0]]}, MIG's is "
                           f"{MIG_PORTS[wrong[0]][0]}")


def read_mig_core(folder, core_name=DEFAULT_CORE_NAME):
    """Read and check the MIG core in ``folder`` (see the module docstring); returns :class:`MIGCoreFiles`.

    Raises
    ------
    MIGCoreError
        One line naming what is missing or wrong.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise MIGCoreError(f"no such MIG core folder: {folder}")
    rtl = _rtl_files(folder)
    ucf = _ucf_file(folder, core_name)
    _check_ports(rtl, core_name, folder)
    return MIGCoreFiles(folder=folder.resolve(), core_name=core_name, rtl=rtl, ucf_name=ucf.name,
                        ucf_text=_read(ucf))
