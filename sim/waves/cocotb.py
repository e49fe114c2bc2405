"""The GTKWave save file of a cocotb run with waves (``STEREO_WAVES=1``, or ``run_cocotb(waves=True)``).

:func:`sim.runners.cocotb.run_cocotb` asks each simulator for a dump in the run's own test directory (Verilator:
``dump.vcd``, where cocotb's runner has it write; Icarus: ``dump.fst`` through the ``+dumpfile_path`` plusarg of
cocotb's dump module, :func:`dump_plusargs`, instead of one file per build that every run would overwrite) and
then writes ``dump.gtkw`` beside it (:func:`write_run_save_file`) with :mod:`sim.waves.gtkw`:

* the top module's ports, grouped by the first part of their flat name (``status__cam__done`` goes to
  ``status``; ``clk``, ``rst`` and other one-part names to ``ports``, the first group), sorted by name;
* an I2C bus (ports ``<p>__scl`` and ``<p>__sda``, or ``<p>__scl__i`` and ``<p>__sda__i``: the lines as the
  design reads them) decoded by ``sim/waves/i2c_filter.py`` under its lines;
* every state machine of the Amaranth design (:func:`sim.waves.fsm_filters.state_machines`) that is in the dump, shown
  by state name through a translate filter file written beside the save file (``dump_filters/``), and the
  ports that carry an enumeration (``*__error_code``, ``*__cmd``: :func:`sim.waves.fsm_filters.design_enums`);
* named markers at the events the caller names (:class:`RunWaves`), the window between two of them or the whole
  run.
"""

import re
from dataclasses import dataclass, field
from pathlib import Path

from sim.waves.gtkw import Event, I2CBus, Show, Waves, common_prefix, read_vars, write_save_file

__all__ = ["RunWaves", "dump_file", "dump_plusargs", "write_run_save_file", "top_ports"]


@dataclass
class RunWaves:
    """What a cocotb run's save file shows besides the top's ports (see the module docstring).

    ``design``: the Amaranth elaboratable the Verilog was exported from, or a function that builds it (called
    only when waves are on), for the state machines' names; default: the design given to ``run_cocotb`` when it
    is an elaboratable. ``events``: :class:`sim.waves.gtkw.Event` whose ``signal`` is a flat port name
    (``init__cam_a__done``); an event on a port the top does not have is left out. ``view``: ``(from, to)``
    event labels, else the whole run; ``before_s``/``after_s`` widen it."""
    design: object = None
    events: list = field(default_factory=list)
    view: tuple = None
    before_s: float = None
    after_s: float = None


def dump_file(simulator, test_dir):
    """Where ``simulator`` writes the run's dump in ``test_dir``."""
    return Path(test_dir) / ("dump.fst" if simulator == "icarus" else "dump.vcd")


def dump_plusargs(simulator, test_dir):
    """The plusargs that put the dump at :func:`dump_file` (Icarus; Verilator writes there already)."""
    return [f"+dumpfile_path={dump_file(simulator, test_dir)}"] if simulator == "icarus" else []


def top_ports(verilog_text, top):
    """The port names of module ``top`` in Yosys's Verilog, in the order of its header."""
    m = re.search(rf"^module {re.escape(top)}\((.*?)\);", verilog_text, re.M | re.S)
    if m is None:
        raise ValueError(f"no module {top} in the Verilog")
    return [p.strip() for p in m[1].split(",") if p.strip()]


def write_run_save_file(dump, verilog_text, top, run_waves=None, design=None):
    """Write ``<dump>.gtkw`` for the dump of a run of module ``top`` (see the module docstring); ``design``:
    the Amaranth elaboratable, if ``run_waves`` names none. Returns the save file's path."""
    from sim.waves.fsm_filters import design_enums, state_machines, write_filter
    run_waves = run_waves or RunWaves()
    dump = Path(dump)
    gtkw = dump.with_suffix(".gtkw")
    filters = dump.parent / f"{dump.stem}_filters"
    if not dump.exists():
        raise FileNotFoundError(f"the simulator wrote no dump at {dump}")
    variables, _ = read_vars(dump)
    scope = min((v.scope for v in variables if v.scope and v.scope[-1] == top), key=len, default=None)
    if scope is None:
        raise ValueError(f"the dump {dump} has no scope {top}")
    here = {v.name: v for v in variables if v.scope == scope}
    enums = {name: write_filter(filters / f"enum_{cls.__name__}.txt", {m.value: m.name for m in cls})
             for name, cls in design_enums().items()}
    groups = _port_groups([p for p in top_ports(verilog_text, top) if p in here], here, enums)
    design = run_waves.design if run_waves.design is not None else design
    design = design() if callable(design) and not hasattr(design, "elaborate") else design
    if design is not None:
        fsms = _fsm_shows(state_machines(design), scope, variables, filters, write_filter)
        if fsms:                                # after the clock and reset, before the other ports
            groups = {**{k: v for k, v in groups.items() if k == "ports"}, "state_machines": fsms, **groups}
    events = [Event(e.label, here[e.signal].full, e.value, e.after) for e in run_waves.events if e.signal in here]
    labels = {e.label for e in events}
    view = run_waves.view if run_waves.view and set(run_waves.view) <= labels else None
    write_save_file(gtkw, dump, Waves(groups=groups, events=events, view=view, before_s=run_waves.before_s,
                                      after_s=run_waves.after_s))
    return gtkw


def _port_groups(ports, here, enums):
    """``{group: [entries]}`` of the top's ports (see the module docstring)."""
    groups = {"ports": []}
    for port in sorted(ports):
        parts = port.split("__")
        groups.setdefault(parts[0] if len(parts) > 1 else "ports", []).append(port)
    out = {}
    for name, members in groups.items():
        entries, buses = [], set()
        for port in members:
            prefix, line = _i2c_line(port)
            if prefix is not None and prefix not in buses and _i2c_partner(port, line) in here:
                buses.add(prefix)
                scl, sda = (port, _i2c_partner(port, line)) if line == "scl" else (_i2c_partner(port, line), port)
                entries.append(I2CBus(prefix.replace("__", "_") + "_i2c", here[scl].full, here[sda].full))
            elif prefix is None or prefix not in buses:
                enum = enums.get(port.split("__")[-1])
                var = here[port]
                entries.append(Show(var.full, fmt="dec", translate=enum) if enum else Show(var.full))
        if entries:
            out[name] = entries
    return out


_I2C_LINE = re.compile(r"(.+)__(scl|sda)(__i)?")


def _i2c_line(port):
    """``(bus prefix, "scl"/"sda")`` of a port that is an I2C line as the design reads it, else ``(None, None)``."""
    m = _I2C_LINE.fullmatch(port)
    return (m[1], m[2]) if m else (None, None)


def _i2c_partner(port, line):
    other = "sda" if line == "scl" else "scl"
    return re.sub(rf"__{line}(__i)?$", lambda m: f"__{other}{m[1] or ''}", port)


def _fsm_shows(fsms, scope, variables, filters, write_filter):
    """A :class:`Show` with its translate filter for each state machine the dump holds."""
    found = []
    for fsm in fsms:
        where = (*scope, *fsm.path[1:])
        var = next((v for v in variables if v.scope == where and v.name == fsm.signal), None)
        if var is not None:
            found.append((fsm, var))
    common = common_prefix([var.scope for _, var in found])
    out = []
    for fsm, var in found:
        path = write_filter(filters / f"{'.'.join(var.scope)}.{fsm.signal}.txt", fsm.states)
        label = " ".join(var.scope[common:])               # GTKWave shows an alias after its last "."
        out.append(Show(var.full, fmt="dec", alias=f"{label} state", translate=path))
    return out
