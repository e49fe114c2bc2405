"""Each memory of the board design, the XST coding template it is written in and its block RAM cost (what
``stereodepth resources`` lists under "memories").

Read from the RTLIL Amaranth writes (``memory`` declarations and their ``$memwr_v2``/``$memrd_v2`` ports), so the
listing describes the HDL XST receives, not a synthesis result. Per memory: its hierarchical name, depth x
width, write and read ports, whether the reads are synchronous, whether the write port has lane (byte) enables,
whether read and write ports share one clock, and from that the template (docs/board.md names the XST User Guide
section of each):

* ``simple dual-port``: one write port, synchronous reads, one clock;
* ``dual-port, two clocks``: the same with the read ports on another clock than the write port;
* ``ROM, synchronous read``: no write port, every read registered;
* ``lane write enables``: a write port whose enable differs between bit lanes -- not one of XST's documented
  dual-port templates (docs/board.md), so it is reported as a problem;
* ``ROM, asynchronous read``: no write port, a read without a clock -- a distributed (LUT) ROM, never block
  RAM; listed so that what is not block RAM is visible;
* ``asynchronous read``: a RAM with a read port without a clock -- distributed RAM, never block RAM;
* ``small``: below :data:`SMALL_BITS`, wherever XST puts it;
* ``distributed (ROM_STYLE/RAM_STYLE)``: the memory carries the XST attribute asking for LUTs.


Block RAM cost: the fewest RAMB36 equivalents (a RAMB18 is half) over the Virtex-5 port aspect ratios (UG190,
"Block RAM": RAMB18 16K x 1 .. 1K x 18 and 512 x 36 in simple dual-port mode; RAMB36 32K x 1 .. 1K x 36 and
512 x 72 simple dual-port), one copy per read port beyond the first.
"""

import math
import re
from dataclasses import dataclass

__all__ = ["MemoryInfo", "memories", "block_cost", "mapped_blocks", "lines", "SMALL_BITS", "PROBLEMS"]

#: Memories below this many bits are not required to be block RAM (the rule: "larger than a few hundred bits").
SMALL_BITS = 512
#: Templates that do not give block RAM by construction.
PROBLEMS = ("lane write enables", "asynchronous read")

# (depth, width, RAMB36 equivalents) of one block in each Virtex-5 aspect ratio (UG190).
_ASPECTS = ([(16384 >> i, w, 0.5) for i, w in enumerate((1, 2, 4, 9, 18))] + [(512, 36, 0.5)] +
            [(32768 >> i, w, 1.0) for i, w in enumerate((1, 2, 4, 9, 18, 36))] + [(512, 72, 1.0)])


def block_cost(depth, width):
    """The fewest RAMB36 equivalents holding a ``depth`` x ``width`` memory with one write and one read port."""
    return min(math.ceil(depth / d) * math.ceil(width / w) * cost for d, w, cost in _ASPECTS)


@dataclass
class MemoryInfo:
    name: str
    depth: int
    width: int
    write_ports: int = 0
    read_ports: int = 0
    async_reads: int = 0
    lanes: int = 1                  # distinct write-enable signals of the widest write port
    clocks: tuple = ()              # (write clocks, read clocks) as RTLIL signal names
    one_clock: bool = True
    style: str = ""                 # the memory's RAM_STYLE/ROM_STYLE attribute, if any

    @property
    def bits(self):
        return self.depth * self.width

    @property
    def template(self):
        if self.bits < SMALL_BITS:
            return "small"
        if self.style == "distributed":
            return "distributed (ROM_STYLE/RAM_STYLE)"
        if self.async_reads:
            return "asynchronous read" if self.write_ports else "ROM, asynchronous read"
        if self.lanes > 1:
            return "lane write enables"
        if not self.write_ports:
            return "ROM, synchronous read"
        return "simple dual-port" if self.one_clock else "dual-port, two clocks"

    @property
    def blocks36(self):
        if self.template in ("small", "asynchronous read", "ROM, asynchronous read",
                             "distributed (ROM_STYLE/RAM_STYLE)"):
            return 0
        return block_cost(self.depth, self.width) * max(1, self.read_ports)

    def row(self, mapped=None):
        out = {"name": self.name, "depth": self.depth, "width": self.width, "bits": self.bits,
               "write_ports": self.write_ports, "read_ports": self.read_ports, "template": self.template,
               "ramb36": self.blocks36}
        if mapped is not None:
            out["yosys_ramb36"] = mapped
        return out


_MODULE = re.compile(r"^module \\(\S+)")
_MEMORY = re.compile(r"^\s*memory width (\d+) size (\d+) \\(\S+)")
_WIRE = re.compile(r"^\s*wire width (\d+) (?:.*? )?([\\$]\S+)\s*$")
_STYLE = re.compile(r'^\s*attribute \\(?:ROM_STYLE|RAM_STYLE|rom_style|ram_style) "(\w+)"')
_CELL = re.compile(r"^\s*cell \$(memwr_v2|memrd_v2) ")
_PARAM = re.compile(r"^\s*parameter \\(\w+) (.*)$")
_CONNECT = re.compile(r"^\s*connect \\(\w+) (.*)$")
_BIT = re.compile(r"([\\$][^\s{}]+) \[(\d+)(?::(\d+))?\]|([\\$][^\s{}]+)|(\d+)'([01xz]+)")


def _bits(spec, wires):
    """The bits of an RTLIL signal spec, each as a hashable token (constants as themselves)."""
    out = []
    for m in _BIT.finditer(spec):
        name, hi, lo, whole, cwidth, cbits = m.groups()
        if name is not None:
            lo = hi if lo is None else lo
            out += [(name, i) for i in range(int(lo), int(hi) + 1)]
        elif whole is not None:
            out += [(whole, i) for i in range(wires.get(whole, 1))]
        else:
            out += [("const", c) for c in cbits]
    return out


def memories(rtlil_text, top="top"):
    """Every memory in ``rtlil_text``, a list of :class:`MemoryInfo` named by hierarchy below ``top``."""
    found, wires, module, cell, style = {}, {}, "", None, ""
    for line in rtlil_text.splitlines():
        if m := _STYLE.match(line):
            style = m.group(1).lower()
            continue
        if not line.lstrip().startswith(("attribute", "memory")):
            style = ""                      # the attribute was another object's
        if m := _MODULE.match(line):
            module, wires = m.group(1), {}
            continue
        if m := _WIRE.match(line):
            wires[m.group(2)] = int(m.group(1))
            continue
        if m := _MEMORY.match(line):
            path = module.split(".", 1)[1] if module.startswith(top + ".") else ("" if module == top else module)
            name = f"{path}.{m.group(3)}" if path else m.group(3)
            found[(module, m.group(3))] = MemoryInfo(name, depth=int(m.group(2)), width=int(m.group(1)),
                                                     style=style)
            style = ""
            continue
        if m := _CELL.match(line):
            cell = {"kind": m.group(1), "params": {}, "connect": {}}
            continue
        if cell is None:
            continue
        if m := _PARAM.match(line):
            cell["params"][m.group(1)] = m.group(2).strip().strip('"').replace("\\\\", "")
        elif m := _CONNECT.match(line):
            cell["connect"][m.group(1)] = m.group(2).strip()
        elif line.strip() == "end":
            _add_port(found.get((module, cell["params"].get("MEMID", ""))), cell, wires)
            cell = None
    for info in found.values():
        write, read = info.clocks if info.clocks else ((), ())
        info.one_clock = len(set(write) | set(read)) <= 1
    return sorted(found.values(), key=lambda i: i.name)


def _add_port(info, cell, wires):
    if info is None:
        return
    write, read = info.clocks if info.clocks else ((), ())
    clk = cell["connect"].get("CLK", "")
    if cell["kind"] == "memwr_v2":
        info.write_ports += 1
        enables = {b for b in _bits(cell["connect"].get("EN", ""), wires)}
        info.lanes = max(info.lanes, len(enables))
        write = write + (clk,)
    else:
        info.read_ports += 1
        if cell["params"].get("CLK_ENABLE", "1") == "0":
            info.async_reads += 1
        else:
            read = read + (clk,)
    info.clocks = (write, read)


def mapped_blocks(netlist, infos):
    """RAMB36 equivalents (RAMB18 = 1/2) Yosys mapped for each memory, ``{name: blocks}``, from the mapped
    cells' hierarchical names (``<memory name>.<...>``)."""
    counts = {info.name: 0.0 for info in infos}
    prefixes = sorted(counts, key=len, reverse=True)
    for module in netlist["modules"].values():
        for cell_name, cell in module.get("cells", {}).items():
            kind = cell["type"]
            if not kind.startswith(("RAMB36", "RAMB18")):
                continue
            name = cell_name.lstrip("\\")
            for prefix in prefixes:
                if name.startswith(prefix + "."):
                    counts[prefix] += 1 if kind.startswith("RAMB36") else 0.5
                    break
    return counts


def lines(infos, mapped=None):
    """The memory table ``stereodepth resources`` prints."""
    out = [f"{'memory':48} {'depth x width':>14} {'bits':>7} {'template':24} {'RAMB36':>6}"
           + (f" {'Yosys':>6}" if mapped is not None else "")]
    for info in infos:
        line = (f"{info.name:48} {f'{info.depth} x {info.width}':>14} {info.bits:>7} {info.template:24} "
                f"{info.blocks36:>6g}")
        if mapped is not None:
            line += f" {mapped.get(info.name, 0):>6g}"
        out.append(line)
    total = sum(i.blocks36 for i in infos)
    out.append(f"{'total':48} {'':>14} {sum(i.bits for i in infos):>7} {'':24} {total:>6g}"
               + (f" {sum(mapped.values()):>6g}" if mapped is not None else ""))
    bad = [i.name for i in infos if i.template in PROBLEMS]
    out.append("not block RAM by construction: " + (", ".join(bad) if bad else "none"))
    styled = [i.name for i in infos if i.template.startswith("distributed")]
    if styled:
        out.append("distributed by attribute: " + ", ".join(styled))
    roms = [i.name for i in infos if i.template == "ROM, asynchronous read"]
    if roms:
        out.append("distributed (LUT) ROMs, asynchronous read: " + ", ".join(roms))
    return out
