"""Verilog export: flat port names and compact memory initialisation.

Flat names. Interfaces are nested ``amaranth.lib.wiring`` signatures; flat names exist only where a tool needs them
(the exported top's ports, which cocotb reaches by name, and the board's IO buffers). There is one rule, Amaranth's
own for Verilog export: the member at path ``(a, b, c)`` is the port ``a__b__c`` (:func:`flat_name`;
``StereoDepthSystem``'s ``cam_a.data`` is ``cam_a__data``, ``i2c.dvi.scl.oe`` is ``i2c__dvi__scl__oe``).
:func:`flat_ports` lists a component's ports by that rule.

Compact memory initialisation.

Amaranth (through Yosys ``write_verilog``) writes one ``initial`` assignment per memory word::

    reg [4:0] memory [119999:0];
    initial begin
      memory[0] = 5'h00;
      ...
      memory[119999] = 5'h00;
    end

A 400 x 300 frame buffer is 120,000 such lines per camera, which makes Verilator and Yosys slow. When an
``initial`` block assigns every word ``0 .. depth-1`` of one memory, in order, with the same constant,
:func:`compact_memory_init` replaces it with an equivalent loop::

    integer memory__init_i;
    initial begin
      for (memory__init_i = 0; memory__init_i < 120000; memory__init_i = memory__init_i + 1)
        memory[memory__init_i] = 5'h00;
    end

Any other ``initial`` block (non-uniform contents, partial initialisation, anything not matching the exact
pattern) is left untouched, so the rewrite can only change how the same values are written, never which.
Equivalence is tested in ``tests/test_capture.py`` (the rewritten text differs from the original only in
the replaced blocks, and a uniform init of every depth is rewritten while non-uniform ones are not) and by
the cocotb capture tests, which read a whole buffer back as zeros after reset and as the golden image after
a capture, on the compact export.
"""

import re

__all__ = ["flat_name", "flat_ports", "amaranth_verilog", "export_verilog", "compact_memory_init"]


def flat_name(path):
    """The flat name of the member at ``path`` (a tuple of names and indices): ``"__".join(path)``."""
    return "__".join(str(part) for part in path)


def flat_ports(component):
    """``{flat name: signal}`` for every port of ``component``'s signature, as the exported top names them."""
    return {flat_name(path): value for path, _, value in component.signature.flatten(component)}

# A Verilog identifier: simple, or escaped (backslash ... terminated by a space, which is part of it here).
_NAME = r"(?P<name>\\\S+ |[A-Za-z_][A-Za-z0-9_$]*)"
_DECL = re.compile(r"^(?P<indent>[ \t]*)reg (?P<width>\[\d+:0\] )?" + _NAME + r" \[(?P<hi>\d+):0\];$")
_ASSIGN = re.compile(r"^[ \t]*" + _NAME + r"\[(?P<index>\d+)\] = (?P<value>\d+'[hbdo][0-9a-fA-F_]+);$")


def compact_memory_init(verilog):
    """Rewrite every uniform, complete memory ``initial`` block of ``verilog`` as a loop (see module doc).
    Returns ``(text, rewritten)``, ``rewritten`` being the names of the memories whose block was replaced."""
    lines = verilog.split("\n")
    out = []
    rewritten = []
    i = 0
    while i < len(lines):
        line = lines[i]
        decl = _DECL.match(line)
        if decl and i + 1 < len(lines) and lines[i + 1].strip() == "initial begin":
            name, depth = decl["name"], int(decl["hi"]) + 1
            end = i + 2 + depth
            block = lines[i + 2:end]
            if (end < len(lines) and lines[end].strip() == "end" and len(block) == depth
                    and _uniform(block, name, depth)):
                value = _ASSIGN.match(block[0])["value"]
                indent = decl["indent"]
                var = _loop_var(name, verilog)
                out += [
                    line,
                    f"{indent}integer {var};",
                    f"{indent}initial begin",
                    f"{indent}  for ({var} = 0; {var} < {depth}; {var} = {var} + 1)",
                    f"{indent}    {name}[{var}] = {value};",
                    f"{indent}end",
                ]
                rewritten.append(name)
                i = end + 1
                continue
        out.append(line)
        i += 1
    return "\n".join(out), rewritten


def _uniform(block, name, depth):
    value = None
    for index, line in enumerate(block):
        m = _ASSIGN.match(line)
        if m is None or m["name"] != name or int(m["index"]) != index:
            return False
        if value is None:
            value = m["value"]
        elif m["value"] != value:
            return False
    return value is not None and len(block) == depth


def _loop_var(name, verilog):
    base = re.sub(r"[^A-Za-z0-9_]", "_", name.strip().lstrip("\\"))
    var, n = f"{base}__init_i", 0
    while re.search(rf"\b{var}\b", verilog):       # never reuse an identifier the design has
        n += 1
        var = f"{base}__init_i{n}"
    return var


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
    ``sim.cocotb_runner.run_cocotb`` as its ``design``."""
    text, _ = compact_memory_init(amaranth_verilog(component, name, ports))
    return text
