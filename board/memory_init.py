"""Memory initial values in Verilog text: written compactly for simulators, left out for the board build.

Amaranth (through Yosys ``write_verilog``) writes one ``initial`` assignment per memory word::

    reg [0:0] bit0 [119999:0];
    initial begin
      bit0[0] = 1'h0;
      ...
      bit0[119999] = 1'h0;
    end

A 400 x 300 frame buffer is 120,000 such lines per memory. Two rewrites, each touching only an ``initial``
block that assigns every word ``0 .. depth-1`` of one memory, in order, with the same constant:

* :func:`compact_memory_init` (simulation exports, ``board.export``): the block becomes an equivalent loop.
* :func:`strip_zero_memory_init` (the board's ``top.v``): a block of zeros is removed. Virtex-5 block and
  distributed RAM without INIT attributes configure to zero, so the hardware is the same; the file shrinks from
  megabytes to a few hundred kilobytes, which XST reads much faster. Simulators then start such memories
  unknown (Icarus: X) or zero (Verilator), which the board-top simulation tolerates (it reads the frame buffers
  only after a capture has written them).

Any other ``initial`` block (non-uniform, partial, non-zero for the strip) is left untouched, so a rewrite can
only change how the same values are written, never which. Tested in tests/test_capture.py and
tests/test_genesys.py.
"""

import re

__all__ = ["compact_memory_init", "strip_zero_memory_init"]

# A Verilog identifier: simple, or escaped (backslash ... terminated by a space, which is part of it here).
_NAME = r"(?P<name>\\\S+ |[A-Za-z_][A-Za-z0-9_$]*)"
_DECL = re.compile(r"^(?P<indent>[ \t]*)reg (?P<width>\[\d+:0\] )?" + _NAME + r" \[(?P<hi>\d+):0\];$")
_ASSIGN = re.compile(r"^[ \t]*" + _NAME + r"\[(?P<index>\d+)\] = (?P<value>\d+'[hbdo][0-9a-fA-F_]+);$")


def _uniform(block, name, depth):
    value = None
    for index, line in enumerate(block):
        m = _ASSIGN.match(line)
        if m is None or m["name"] != name or int(m["index"]) != index:
            return None
        if value is None:
            value = m["value"]
        elif m["value"] != value:
            return None
    return value if len(block) == depth else None


def _rewrite(verilog, replace):
    """Call ``replace(decl_match, value, verilog)`` for every uniform complete init block; it returns the lines
    that replace the declaration and the block, or None to keep them. Returns ``(text, names rewritten)``."""
    lines = verilog.split("\n")
    out, rewritten, i = [], [], 0
    while i < len(lines):
        line = lines[i]
        decl = _DECL.match(line)
        if decl and i + 1 < len(lines) and lines[i + 1].strip() == "initial begin":
            depth = int(decl["hi"]) + 1
            end = i + 2 + depth
            value = _uniform(lines[i + 2:end], decl["name"], depth) if end < len(lines) else None
            new = None
            if value is not None and lines[end].strip() == "end":
                new = replace(decl, value, verilog)
            if new is not None:
                out += new
                rewritten.append(decl["name"])
                i = end + 1
                continue
        out.append(line)
        i += 1
    return "\n".join(out), rewritten


def _loop_var(name, verilog):
    base = re.sub(r"[^A-Za-z0-9_]", "_", name.strip().lstrip("\\"))
    var, n = f"{base}__init_i", 0
    while re.search(rf"\b{var}\b", verilog):       # never reuse an identifier the design has
        n += 1
        var = f"{base}__init_i{n}"
    return var


def compact_memory_init(verilog):
    """Every uniform, complete memory ``initial`` block of ``verilog`` as a loop::

        integer bit0__init_i;
        initial begin
          for (bit0__init_i = 0; bit0__init_i < 120000; bit0__init_i = bit0__init_i + 1)
            bit0[bit0__init_i] = 1'h0;
        end

    Returns ``(text, rewritten)``, ``rewritten`` being the names of the memories whose block was replaced."""
    def loop(decl, value, text):
        indent, name, var = decl["indent"], decl["name"], _loop_var(decl["name"], text)
        depth = int(decl["hi"]) + 1
        return [decl.group(0), f"{indent}integer {var};", f"{indent}initial begin",
                f"{indent}  for ({var} = 0; {var} < {depth}; {var} = {var} + 1)",
                f"{indent}    {name}[{var}] = {value};", f"{indent}end"]
    return _rewrite(verilog, loop)


def _is_zero(value):
    digits = value.split("'", 1)[1][1:].replace("_", "")
    return set(digits) <= {"0"}


def strip_zero_memory_init(verilog):
    """``verilog`` without the ``initial`` blocks that set every word of a memory to zero (the declaration
    stays). Returns ``(text, stripped)``, ``stripped`` being the memories' names."""
    return _rewrite(verilog, lambda decl, value, text: [decl.group(0)] if _is_zero(value) else None)
