"""GTKWave translate filter files for the design's state machines and enumerations, from the design itself.

A Verilog simulator's dump (cocotb on Verilator or Icarus) has a state machine's state as a number; a translate
filter file (``value name`` per line, GTKWave manual "Translate Filter File") makes GTKWave show the name. The
encodings are read from the elaborated design, never written by hand:

* :func:`state_machines`: every ``m.FSM`` of an elaboratable. Amaranth gives each FSM a state signal
  (``fsm_state``) whose ``decoder`` maps an encoded value to ``"NAME/value"`` and fails for a value no state
  has; each value the signal's width allows is put to it.
* :func:`enum_states`: the members of an ``amaranth.lib.enum`` class (``hdl.i2c_master.Cmd``,
  ``hdl.i2c_init.ErrorCode``).

:func:`write_filter` writes a file in the decimal form GTKWave shows a trace in when its format is ``dec``
(which :class:`sim.waves.gtkw.Show` uses with a filter). Amaranth's own VCD writer already records FSM states and
enum-shaped signals as text through the same decoders, so the filters serve the Verilog simulators' dumps.
"""

import re
from dataclasses import dataclass
from pathlib import Path

__all__ = ["StateMachine", "state_machines", "enum_states", "design_enums", "write_filter"]

_DECODED = re.compile(r"(.+)/(\d+)")


@dataclass(frozen=True)
class StateMachine:
    """One FSM: ``path`` (module names from the top, the top being ``"top"``), ``signal`` (its state signal's
    name there), ``width`` and ``states`` (``{encoded value: state name}``)."""
    path: tuple
    signal: str
    width: int
    states: dict


def state_machines(elaboratable):
    """Every FSM of ``elaboratable`` after elaboration (see the module docstring), in hierarchy order."""
    from amaranth.hdl import Fragment
    design = Fragment.get(elaboratable, platform=None).prepare()
    out, seen = [], set()
    for info in design.fragments.values():
        for signal, name in info.signal_names.items():
            if id(signal) in seen or not callable(signal.decoder) or isinstance(signal.decoder, type):
                continue
            states = _decode_all(signal)
            if states:
                seen.add(id(signal))
                out.append(StateMachine(tuple(info.name), name, len(signal), states))
    return out


def _decode_all(signal):
    """``{value: name}`` when the signal's decoder gives ``NAME/value`` for its values (an FSM state), else {}."""
    states = {}
    for value in range(2 ** len(signal)):
        try:
            text = signal.decoder(value)
        except (KeyError, IndexError, ValueError):
            continue
        m = _DECODED.fullmatch(str(text))
        if not m or int(m[2]) != value:
            return {}
        states[value] = m[1]
    return states


def enum_states(enum_class):
    """``{value: name}`` of an enumeration's members."""
    return {member.value: member.name for member in enum_class}


def design_enums():
    """The design's enumerations by the names of the signals that carry them (``cmd``, ``error_code``)."""
    from hdl.i2c_init import ErrorCode
    from hdl.i2c_master import Cmd
    return {"cmd": Cmd, "error_code": ErrorCode, "fail_code": ErrorCode}


def write_filter(path, states):
    """Write ``{value: name}`` as a GTKWave translate filter file (decimal values); returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(f"{value} {name}\n" for value, name in sorted(states.items())))
    return path
