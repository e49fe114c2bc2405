"""Per-block resource breakdown of a flattened Yosys netlist (what ``python -m bench depth_budget --blocks`` and
``python -m bench resources --memory ddr2 --blocks`` print).

The netlist is the one :func:`board.resources.run_yosys` maps (``synth_xilinx -family xc5v -flatten``), so the
blocks add up to the design's own count. Yosys keeps, on every flip-flop, memory and shift register, the source
line its signal was declared on (``src``), but the LUTs ABC makes have none. So a LUT (and a MUXF7/MUXF8/CARRY4)
is charged to the first flip-flop, block RAM, shift register or LUT RAM its output reaches through logic
(breadth first), and that cell to the source file (one block a file, ``hdl/`` rule) and line of its
declaration: a block's LUTs are the logic that computes its registers, summed over the block's instances (the
two paths are one ``sgm_path`` row). Logic shared by several blocks is charged to one of them; logic that
reaches only outputs is charged to ``top``. A register declared in one block and driven in another (a
sub-block's output port) is charged to the sub-block, where it is declared. A netlist without ``src`` (the
board's, as its platform writes the RTLIL) is split by the block path of each cell's output net's deepest name
(``system.frame_store.writer_0.packer``) instead.

Kinds of LUT: logic (LUT1..LUT6, INV: what ``stereodepth resources`` counts), LUT RAM (Virtex-5 distributed
memory: RAM64M / RAM32M four LUTs each, RAMnnX1D two, RAM128X1D four; UG190, "Distributed RAM") and shift
registers (SRL16E / SRLC32E, one LUT each). XST's "slice LUTs" count all three.
"""

import collections
import re
from dataclasses import dataclass, fields

__all__ = ["BlockCells", "attribute", "blocks", "block_lines", "line_lines", "LUT_RAM_LUTS", "SHIFT_LUTS"]

LOGIC_LUTS = {f"LUT{i}" for i in range(1, 7)} | {"INV"}
#: LUTs per distributed-memory cell.
LUT_RAM_LUTS = {"RAM32M": 4, "RAM64M": 4, "RAM32X1D": 2, "RAM64X1D": 2, "RAM128X1D": 4, "RAM32X1S": 1,
                "RAM64X1S": 1, "RAM128X1S": 2, "RAM256X1S": 4}
SHIFT_LUTS = {"SRL16E": 1, "SRLC16E": 1, "SRLC32E": 1}
_THROUGH = LOGIC_LUTS | {"MUXF7", "MUXF8", "CARRY4", "MUXCY", "XORCY"}


@dataclass
class BlockCells:
    """One block's cells: LUTs by kind, flip-flops, RAMB36 equivalents (RAMB18 = 1/2), CARRY4."""
    logic: int = 0
    lut_ram: int = 0
    shift: int = 0
    ffs: int = 0
    ramb36: float = 0.0
    carry4: int = 0

    @classmethod
    def of(cls, cells):
        """From a cell count per type (Yosys ``stat``)."""
        return cls(logic=sum(n for t, n in cells.items() if t in LOGIC_LUTS),
                   lut_ram=sum(LUT_RAM_LUTS[t] * n for t, n in cells.items() if t in LUT_RAM_LUTS),
                   shift=sum(SHIFT_LUTS[t] * n for t, n in cells.items() if t in SHIFT_LUTS),
                   ffs=sum(n for t, n in cells.items() if t.startswith("FD")),
                   ramb36=sum(n for t, n in cells.items() if t.startswith("RAMB36"))
                   + sum(n for t, n in cells.items() if t.startswith("RAMB18")) / 2,
                   carry4=cells.get("CARRY4", 0))

    @property
    def luts(self):
        """All LUTs: logic, LUT RAM and shift registers."""
        return self.logic + self.lut_ram + self.shift

    def add(self, other):
        for f in fields(self):
            setattr(self, f.name, getattr(self, f.name) + getattr(other, f.name))


def attribute(netlist):
    """``{(block, source line): {cell type: count}}`` for the top module of a Yosys JSON ``netlist``."""
    top = next(m for m in netlist["modules"].values() if m.get("attributes", {}).get("top"))
    names = collections.defaultdict(list)           # bit -> [(name, its declaration)]
    for name, info in top["netnames"].items():
        if name.startswith("$"):
            continue
        declared = info.get("attributes", {}).get("src", "").split("|")[0]
        for bit in info["bits"]:
            if isinstance(bit, int):
                names[bit].append((name, declared))
    cells = top["cells"]
    consumers = collections.defaultdict(list)
    for cname, cell in cells.items():
        for port, bits in cell["connections"].items():
            if cell["port_directions"].get(port) == "input":
                for bit in bits:
                    if isinstance(bit, int):
                        consumers[bit].append(cname)

    def outputs(cell):
        return [b for p, bits in cell["connections"].items() if cell["port_directions"].get(p) == "output"
                for b in bits]

    def ours(src):
        return bool(src) and "/share/" not in src and "/amaranth/" not in src and "/contextlib" not in src

    def stem_line(src):
        """``/.../hdl/depth/sgm_path.py:111.9-111.60`` -> ``("depth/sgm_path", "depth/sgm_path:111")``."""
        path, _, where = src.rpartition(":")
        parts = path.removesuffix(".py").split("/")
        stem = "/".join(parts[parts.index("hdl") + 1:]) if "hdl" in parts else parts[-1]
        return stem, f"{stem}:{where.split('.')[0]}"

    def place(cname):
        """A cell's block and source line: where its signal is declared (a flip-flop's own ``src``); for a
        cell without one, the declaration of the outermost name of its output net (memories) or of its data
        input (shift registers)."""
        cell = cells[cname]
        sources = [s for s in cell["attributes"].get("src", "").split("|") if ours(s)]
        if sources:
            return stem_line(sources[0])
        # A shift register's output may be a sub-block's input port: its data input names the chain's owner.
        bits = cell["connections"].get("D", []) if cell["type"] in SHIFT_LUTS else outputs(cell)
        declared = sorted(((n.count("."), d) for b in bits for n, d in names.get(b, ()) if ours(d)))
        if declared:
            return stem_line(declared[0][1])
        # No source at all (a netlist written without ``src``, as the board's platform writes it): the block
        # path of the deepest name, Amaranth's ``$n`` suffixes dropped.
        def deepest_of(bits):
            return sorted((n for b in bits for n, _ in names.get(b, ())), key=lambda n: -n.count("."))
        deepest = deepest_of(bits) or deepest_of(outputs(cell))     # a shift register fed by logic
        if not deepest:
            return "top", "?"
        path = [re.sub(r"\$\d+$", "", part) for part in deepest[0].split(".")[:-1]]
        return ".".join(path) or "top", "?"

    memo = {}

    def sink(cname):
        seen, queue = {cname}, collections.deque([cname])
        while queue:
            for bit in outputs(cells[queue.popleft()]):
                for nxt in consumers.get(bit, ()):
                    if cells[nxt]["type"] not in _THROUGH:
                        memo[cname] = place(nxt)
                        return memo[cname]
                    if nxt in memo:
                        memo[cname] = memo[nxt]
                        return memo[cname]
                    if nxt not in seen:
                        seen.add(nxt)
                        queue.append(nxt)
        memo[cname] = ("top", "?")
        return memo[cname]

    out = collections.defaultdict(collections.Counter)
    for cname, cell in cells.items():
        kind = cell["type"]
        if kind.startswith("$") or kind in ("GND", "VCC"):
            continue
        out[sink(cname) if kind in _THROUGH else place(cname)][kind] += 1
    return out


def blocks(attributed, depth=None):
    """Sum :func:`attribute`'s figures per block (a block path cut to ``depth`` names): ``{block: BlockCells}``."""
    out = collections.defaultdict(BlockCells)
    for (block, _), cells in attributed.items():
        out[".".join(block.split(".")[:depth])].add(BlockCells.of(cells))
    return dict(out)


def block_lines(per_block, *, strip="", min_luts=0):
    """Markdown rows, most LUTs first; blocks under ``min_luts`` LUTs in one "others" row."""
    rows = ["| block | LUTs | logic | SRL | LUT RAM | flip-flops | RAMB36 |", "|---|---|---|---|---|---|---|"]
    total, others, small = BlockCells(), BlockCells(), 0
    for name, b in sorted(per_block.items(), key=lambda kv: -kv[1].luts):
        total.add(b)
        if not (b.luts or b.ffs or b.ramb36):
            continue
        if b.luts < min_luts and not b.ramb36:
            others.add(b)
            small += 1
            continue
        label = name[len(strip):] if strip and name.startswith(strip) else name
        rows.append(f"| {label or '(own logic)'} | {b.luts:,} | {b.logic:,} | {b.shift:,} | {b.lut_ram:,} | "
                    f"{b.ffs:,} | {b.ramb36:g} |")
    if small:
        rows.append(f"| {small} smaller blocks | {others.luts:,} | {others.logic:,} | {others.shift:,} | "
                    f"{others.lut_ram:,} | {others.ffs:,} | {others.ramb36:g} |")
    rows.append(f"| **total** | {total.luts:,} | {total.logic:,} | {total.shift:,} | {total.lut_ram:,} | "
                f"{total.ffs:,} | {total.ramb36:g} |")
    return rows


def line_lines(attributed, count=12):
    """The ``count`` source lines whose registers take the most logic LUTs (block, file:line, LUTs)."""
    per_line = collections.Counter()
    for (block, source), cells in attributed.items():
        per_line[(block, source)] += BlockCells.of(cells).logic
    rows = ["| block | register declared at | logic LUTs |", "|---|---|---|"]
    return rows + [f"| {b} | {s} | {n:,} |" for (b, s), n in per_line.most_common(count)]
