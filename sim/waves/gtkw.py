"""GTKWave save files (``.gtkw``) of the project's own: a useful first view, named markers, decoded buses.

Every save file the project writes comes from here. A :class:`Waves` says what to show, in terms of the
design's signals: groups of traces (a :class:`Show` for a signal or a name in the dump, an :class:`I2CBus`
for a bus decoded by ``sim/waves/i2c_filter.py``), named markers at events of the run (:class:`Event`: the first
time a signal takes a value, optionally after another event), and the window GTKWave opens on (two events with a
margin, or the whole run). Every state machine in the dump that no group shows is added in a group of its own.
A group with no change inside the opening window starts closed.

The names come from the design, never from a hand-written string: Amaranth's VCD writer names each traced
signal (its own GTKWave output, read back), and of the names the dump gives that signal (Amaranth records a
signal once per module that uses it, as aliases) the one without a ``$NN`` collision suffix in the innermost
module is shown: that module is the one that drives or reads it, where its name is its own. A signal whose
every name has such a suffix is shown with it (tests/test_gtkw_files.py fails on those).

A dump is a VCD, or an FST (Icarus under cocotb), read through GTKWave's ``fst2vcd``.

The directives (GTKWave 3.3 manual, "Save files"; checked against GTKWave 3.3.118 by opening the files,
tests/test_gtkw_files.py): ``[timestart]`` (left edge of the window), ``*zoom marker a b ...`` (zoom and the
named markers' times), ``[markername] Xlabel``, ``[size]``, ``[signals_width]``, ``@flags``, ``-label``
(group and blank rows), ``+{alias} name``, ``^<1 program`` + ``#{name} a b`` (a combined vector handed to a
transaction filter), ``^1 file`` (translate filter file). GTKWave shows ``(width - signals_width - 64) / 200 *
2**-zoom`` dump time units across the window (measured; the test checks the window it opens on).

Usage (Amaranth simulator)::

    with recording(sim, "x.vcd", "x.gtkw", Waves(groups={"bus": [I2CBus("i2c", dut.scl, dut.sda)]})):
        sim.run()
"""

import math
import re
import subprocess
import tempfile
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["Show", "I2CBus", "Event", "Waves", "DumpVar", "read_vars", "changes", "recording", "write_save_file",
           "I2C_FILTER", "common_prefix"]

#: The transaction filter program GTKWave runs for an :class:`I2CBus`.
I2C_FILTER = Path(__file__).resolve().parent / "i2c_filter.py"
_COLLISION = re.compile(r"\$\d+")
_FLAGS = {"hex": 0x22, "dec": 0x24, "bin": 0x28, "transaction": 0x10000028, "translated": 0x2000}
_GROUP_BEGIN, _GROUP_END, _BLANK, _CLOSED, _COLLAPSED = 0x800200, 0x1000200, 0x200, 0x400000, 0x1000
_MARKERS = "ABCDEFGHIJKLMNOPQRSTUVWXYZ"


@dataclass(frozen=True)
class Show:
    """One trace: ``what`` is a signal of the design, or the end of a name in the dump (``"capture_a.row"``: the
    dump variable whose scoped name ends so; exactly one must). ``fmt``: ``hex``, ``dec`` or ``bin``;
    ``alias``: the name shown (default: the signal's own); ``translate``: a translate filter file."""
    what: object
    fmt: str = None
    alias: str = None
    translate: Path = None


@dataclass(frozen=True)
class I2CBus:
    """An I2C bus shown as its two lines and, under them, two decoded rows (bytes, transactions)."""
    label: str
    scl: object
    sda: object


@dataclass(frozen=True)
class Event:
    """A named marker at the first time ``signal`` (a signal or a dump name, as in :class:`Show`) equals
    ``value``, at or after the event labelled ``after`` (a label or a tuple of labels: after all of them)."""
    label: str
    signal: object
    value: int = 1
    after: str = None


@dataclass
class Waves:
    """What a save file shows; see the module docstring. ``view``: ``None`` (the whole run) or ``(from, to)``
    event labels, widened by ``before_s`` / ``after_s`` seconds (default: ``margin`` of its length on each
    side). ``fsm_group``: add every FSM state the groups do not show in a group of its own."""
    groups: dict
    events: list = field(default_factory=list)
    view: tuple = None
    margin: float = 0.05
    before_s: float = None
    after_s: float = None
    size: tuple = (1600, 1000)
    signals_width: int = 300
    fsm_group: bool = True

    def signals(self):
        """The design signals the save file refers to (for the VCD writer's ``traces``)."""
        out = []
        for entries in self.groups.values():
            for e in entries:
                for s in _entry_signals(e):
                    if not isinstance(s, str) and not any(s is o for o in out):
                        out.append(s)
        for e in self.events:
            if not isinstance(e.signal, str) and not any(e.signal is o for o in out):
                out.append(e.signal)
        return out


def _entry_signals(entry):
    if isinstance(entry, I2CBus):
        return [entry.scl, entry.sda]
    if isinstance(entry, Show):
        return [entry.what]
    return [entry]


# --- the dump --------------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class DumpVar:
    """A variable of a VCD: ``scope`` (tuple), ``name``, ``width``, ``kind`` (``wire``, ``string``...), ``ident``
    (the VCD identifier, shared by aliases) and ``full``, the name GTKWave knows it by."""
    scope: tuple
    name: str
    width: int
    kind: str
    ident: str
    full: str


@contextmanager
def _dump_lines(path):
    """The lines of a dump in VCD form: a VCD as it is, an FST (Icarus's) through GTKWave's ``fst2vcd``."""
    if Path(path).suffix != ".fst":
        with open(path) as f:
            yield f
        return
    with subprocess.Popen(["fst2vcd", "-f", str(path)], stdout=subprocess.PIPE, text=True) as convert:
        try:
            yield convert.stdout
        finally:
            convert.stdout.close()
            convert.kill()


def read_vars(vcd_path):
    """``(variables, timescale text)`` from a dump's header (a VCD, or an FST: :func:`_dump_lines`)."""
    scope, out, timescale, in_timescale = [], [], None, False
    with _dump_lines(vcd_path) as f:
        for line in f:
            words = line.split()
            if not words:
                continue
            if in_timescale:                    # fst2vcd writes the timescale on a line of its own
                timescale, in_timescale = (timescale or "") + " ".join(w for w in words if w != "$end"), \
                    words[-1] != "$end"
                continue
            if words[0] == "$scope":
                scope.append(words[2])
            elif words[0] == "$upscope":
                scope.pop()
            elif words[0] == "$var":
                kind, width, ident, name = words[1], int(words[2]), words[3], words[4]
                rng = words[5] if len(words) > 6 and words[5].startswith("[") else ""
                if not rng and width > 1 and kind not in ("string", "real"):
                    rng = f"[{width - 1}:0]"
                out.append(DumpVar(tuple(scope), name, width, kind, ident, ".".join((*scope, name)) + rng))
            elif words[0] == "$timescale":
                timescale = " ".join(w for w in words[1:] if w != "$end") or None
                in_timescale = words[-1] != "$end"
            elif words[0] == "$enddefinitions":
                break
    return out, timescale


def changes(vcd_path, idents):
    """``({ident: [(time, value text), ...]}, last time)`` for the given identifiers of a VCD (or FST)."""
    want = set(idents)
    out = {i: [] for i in want}
    t = 0
    with _dump_lines(vcd_path) as f:
        for line in f:
            if line.startswith("$enddefinitions"):
                break
        for line in f:
            c = line[0]
            if c == "#":
                t = int(line[1:])
            elif c in "01xzXZ":
                ident = line[1:].rstrip("\n")
                if ident in want:
                    out[ident].append((t, c))
            elif c in "bBsSrR":
                value, _, ident = line[1:].rstrip("\n").partition(" ")
                if ident in want:
                    out[ident].append((t, value))
    return out, t


def _value(text):
    try:
        return int(text, 2)
    except ValueError:
        return None


def _event_times(events, resolve, seen):
    """``{label: time}`` of the events that happened (see :class:`Event`); ``seen``: :func:`changes`."""
    idents = {e.label: resolve(e.signal).ident for e in events}
    times = {}
    for e in events:
        after = (e.after,) if isinstance(e.after, str) else tuple(e.after or ())
        if any(a not in times for a in after):
            continue
        after = max((times[a] for a in after), default=0)
        hit = next((t for t, v in seen[idents[e.label]] if t >= after and _value(v) == e.value), None)
        if hit is not None:
            times[e.label] = hit
    return times


# --- names -----------------------------------------------------------------------------------------------------

def _best(candidates):
    """The name to show of a signal's aliases: no ``$NN`` suffix if there is one, then the innermost module."""
    return min(candidates, key=lambda v: (bool(_COLLISION.search(v.full)), -len(v.scope), v.full))


class _Names:
    """Resolves signals (through the names Amaranth's own save file gives them) and dump-name endings."""

    def __init__(self, variables, amaranth_names):
        self.vars = variables
        self.by_full = {v.full: v for v in variables}
        self.by_ident = {}
        for v in variables:
            self.by_ident.setdefault(v.ident, []).append(v)
        self.amaranth = amaranth_names          # id(signal) -> Amaranth's name for it

    def __call__(self, what):
        if isinstance(what, str):
            if what in self.by_full:
                return self.by_full[what]
            idents = {v.ident for v in self.vars if v.full.split("[")[0].endswith("." + what)}
            if len(idents) != 1:
                raise LookupError(f"the dump has {len(idents)} variables named ...{what}, not one")
            return _best(self.by_ident[idents.pop()])
        name = self.amaranth.get(id(what))
        if name is None or name not in self.by_full:
            raise LookupError(f"{what!r} is not in the dump")
        return _best(self.by_ident[self.by_full[name].ident])


def _amaranth_names(gtkw_text, keys):
    """Read back the save file Amaranth wrote for ``{key: signal}`` traces: ``{key: name}``."""
    names, group = {}, None
    for line in gtkw_text.splitlines():
        if line.startswith("-"):
            group = None if group == line[1:] else line[1:]
        elif group is not None and line and line[0] not in "[@*" and group in keys:
            names.setdefault(group, line.strip())
    return names


@contextmanager
def recording(sim, vcd_path, gtkw_path, waves):
    """Record the simulation ``sim`` to ``vcd_path`` and, when the block ends, write ``gtkw_path`` for ``waves``
    (a :class:`Waves`, or a dict of groups). Wraps ``sim.write_vcd``."""
    if not isinstance(waves, Waves):
        waves = Waves(groups=dict(waves) if isinstance(waves, dict) else {"signals": list(waves)})
    vcd_path = Path(vcd_path).resolve()
    vcd_path.parent.mkdir(parents=True, exist_ok=True)
    signals = waves.signals()
    keys = {f"s{i}": s for i, s in enumerate(signals)}
    with tempfile.TemporaryDirectory(prefix="gtkw_") as tmp:
        amaranth_gtkw = Path(tmp) / "amaranth.gtkw"
        with sim.write_vcd(str(vcd_path), str(amaranth_gtkw), traces=keys):
            yield
        found = _amaranth_names(amaranth_gtkw.read_text(), keys)
    names = {id(s): found.get(k) for k, s in keys.items()}
    if gtkw_path is not None:
        write_save_file(gtkw_path, vcd_path, waves, amaranth_names=names)


# --- the save file ---------------------------------------------------------------------------------------------

def _zoom(span, waves):
    """GTKWave's zoom value that shows ``span`` dump time units across the window (see the module docstring)."""
    pixels = waves.size[0] - waves.signals_width - 64
    return -math.log2(max(span, 1) * 200 / pixels)


_UNITS = {"s": 1, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "ps": 1e-12, "fs": 1e-15}


def _seconds(timescale):
    """Seconds per dump time unit of a VCD ``$timescale`` (``1 fs``, ``10ps``...)."""
    m = re.fullmatch(r"\s*(\d+)\s*([a-z]+)\s*", timescale or "1 s")
    return int(m[1]) * _UNITS[m[2]]


def _window(waves, times, end, unit_s):
    if waves.view and all(label in times for label in waves.view):
        first, last = times[waves.view[0]], times[waves.view[1]]
    else:
        first, last = 0, end
    pad = (last - first) * waves.margin
    before = pad if waves.before_s is None else waves.before_s / unit_s
    after = pad if waves.after_s is None else waves.after_s / unit_s
    return max(0, int(first - before)), min(end, int(last + after))


def _trace_lines(entry, resolve):
    if isinstance(entry, I2CBus):
        scl, sda = resolve(entry.scl), resolve(entry.sda)
        return [f"@{_FLAGS['bin']:x}", scl.full, sda.full, f"@{_FLAGS['transaction']:x}", f"^<1 {I2C_FILTER}",
                f"#{{{entry.label}}} {scl.full} {sda.full}", f"@{_BLANK:x}", "-"]
    show = entry if isinstance(entry, Show) else Show(entry)
    var = resolve(show.what)
    fmt = show.fmt or ("bin" if var.width == 1 else "hex")
    lines = [f"@{_FLAGS[fmt] | (_FLAGS['translated'] if show.translate else 0):x}"]
    if show.translate:
        lines.append(f"^1 {Path(show.translate).resolve()}")
    alias = f"+{{{show.alias}}} " if show.alias else ""
    return lines + [alias + var.full]


def _is_fsm_state(var):
    """An FSM's state in the dump: Amaranth names it ``<fsm name>_state`` (``fsm_state`` unless the FSM is named)
    and its VCD writer records a named FSM's state as text."""
    return var.name == "fsm_state" or (var.kind == "string" and var.name.endswith("_state"))


def _fsm_entries(variables, shown):
    """Every FSM state variable of the dump (:func:`_is_fsm_state`) not in ``shown`` (identifiers), labelled by
    its module path below the modules they all share."""
    fsms = {}
    for v in sorted(variables, key=lambda v: v.scope):
        if _is_fsm_state(v) and v.ident not in shown:
            fsms.setdefault(v.ident, v)
    common = common_prefix([v.scope for v in fsms.values()])
    return [Show(v.full, alias=".".join(v.scope[common:]) + " state") for v in fsms.values()]


def common_prefix(scopes):
    """How many leading names all ``scopes`` (tuples) share, leaving at least one of the shortest."""
    n = min((len(s) for s in scopes), default=0)
    for i in range(n):
        if len({s[i] for s in scopes}) > 1:
            return i
    return max(0, n - 1)


def write_save_file(gtkw_path, vcd_path, waves, *, amaranth_names=None):
    """Write the save file for ``waves`` over the VCD ``vcd_path``; returns ``{label: time}`` of the markers."""
    variables, timescale = read_vars(vcd_path)
    resolve = _Names(variables, amaranth_names or {})
    groups = dict(waves.groups)
    if waves.fsm_group:
        shown = {resolve(w).ident for entries in groups.values() for e in entries for w in _entry_signals(e)}
        fsms = _fsm_entries(variables, shown)
        if fsms:
            groups["more_state_machines" if "state_machines" in groups else "state_machines"] = fsms
    members = {name: {resolve(w).ident for e in entries for w in _entry_signals(e)}
               for name, entries in groups.items()}
    seen, end = changes(vcd_path, {resolve(e.signal).ident for e in waves.events}.union(*members.values()))
    times = _event_times(waves.events, resolve, seen)
    first, last = _window(waves, times, end, _seconds(timescale))
    # GTKWave opens at time 0 instead when the window would run past the end of the dump: show 2 % more than
    # asked and start early enough that the window ends inside the dump.
    shown = (last - first) * 1.02
    first = max(0, min(first, int(end - shown)))
    lines = [f'[dumpfile] "{Path(vcd_path).resolve()}"', f"[timestart] {first}",
             f"[size] {waves.size[0]} {waves.size[1]}", "[pos] -1 -1"]
    marks = [-1] * len(_MARKERS)
    for i, e in enumerate(waves.events[:len(_MARKERS)]):
        marks[i] = times.get(e.label, -1)
    lines.append(f"*{_zoom(shown, waves):.6f} -1 " + " ".join(str(m) for m in marks))
    lines += [f"[markername] {_MARKERS[i]}{e.label}" for i, e in enumerate(waves.events[:len(_MARKERS)])
              if e.label in times]
    lines += ["[sst_expanded] 0", f"[signals_width] {waves.signals_width}"]
    for name, entries in groups.items():
        # a group none of whose signals changes inside the window opens closed
        closed = _CLOSED if not any(first < t <= first + shown for i in members[name] for t, _ in seen[i]) else 0
        lines += [f"@{_GROUP_BEGIN | closed:x}", f"-{name}"]
        for entry in entries:
            lines += _trace_lines(entry, resolve)
        lines += [f"@{_GROUP_END | closed | (_COLLAPSED if closed else 0):x}", f"-{name}"]
    Path(gtkw_path).write_text("\n".join(lines) + "\n")
    return times
