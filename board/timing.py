"""Static timing estimate of the board design: the Yosys ``synth_xilinx -family xc5v`` netlist (``board/resources.py``
makes it) walked with the Virtex-5 -1 delay model of ``board/virtex5_delays.py`` (what ``stereodepth timing`` and
``make timing`` print).

Per clock domain: every register-to-register path, launched and captured by sequential cells on that domain's
clock (slice flip-flops, IOB flip-flops, block RAM ports, DSP48E registers, ODDR inputs), with

    delay = clock-to-out + sum over the cells on the path of (net + cell delay) + net + setup,
    slack = period - delay (half a period for an ODDR D2 in OPPOSITE_EDGE mode),

a fixed routing figure per net (``net_ns``) except on the slice's dedicated connections (see the delay model and
:func:`_net_ns`: a LUT reaches one slice position free; its other carry and F7 inputs are routed, and the carry
select and F7 inputs from anything but their own LUT go through a route-through LUT).
The period of each domain is the clock plan's (:func:`clock_periods`: the figures the UCF's PERIOD
constraints carry). Paths from one domain to another are not timed (they end in synchronisers or
the dual-clock RAMs, and the UCF declares them TIG); neither are pad-to-register or register-to-pad paths (the
UCF's OFFSET constraints), clock skew, jitter, or hold.

The DDR2 build (``clock_periods("ddr2")``) adds the ``mem`` domain at MIG's ``clk0``; the MIG core, a black box
in the netlist (``board.resources.board_rtlil``), launches its user-interface outputs and captures its inputs on
``clk0_tb`` with the delays of what drives them in its RTL (:data:`MIG_CORE_OUTPUTS`, :data:`MIG_CORE_INPUTS`);
its memory side is the core's own UCF's business.

Limits: no placement (every net costs the same, whatever its fanout or length), Yosys's mapping and not XST's (XST
packs, replicates and maps carry chains differently), a delay model whose values are assumptions (the data sheet
could not be read): an estimate that shows where the margin is, not a sign-off -- ISE's trce is.
"""

import re
from dataclasses import dataclass, field
from pathlib import Path as _FilePath

from board.resources import bit_names, domain_of_clock, top_module

from .virtex5_delays import MODEL, NET_NS

__all__ = ["analyse", "estimate", "clock_periods", "cell_timing", "TimingReport", "DomainTiming", "Path",
           "ModelError", "is_mig_core", "MIG_CORE_OUTPUTS", "MIG_CORE_INPUTS"]

LUTS = {f"LUT{i}" for i in range(1, 7)} | {"INV"}
LEVELS = LUTS | {"MUXF7", "MUXF8"}
FLIP_FLOPS = {"FDRE": "R", "FDSE": "S", "FDCE": "CLR", "FDPE": "PRE"}
RAMS = {"RAMB36", "RAMB18", "RAMB36SDP", "RAMB18SDP"}
#: Shift registers in LUTs: D/CE captured and Q launched by CLK; the tap address (A) to Q like a LUT.
SHIFT_REGISTERS = {"SRL16E", "SRLC16E", "SRLC32E"}
#: Distributed (LUT) RAM primitives: read combinational from the address, written on WCLK.
LUT_RAMS = {"RAM32M", "RAM64M", "RAM32X1D", "RAM64X1D", "RAM128X1D", "RAM32X1S", "RAM64X1S", "RAM128X1S",
            "RAM256X1S"}
#: Cells with no register-to-register timing: pads, clock buffers and clock generators, constants.
UNTIMED = {"IBUF", "IBUFG", "OBUF", "OBUFT", "IOBUF", "BUFG", "BUFGCE", "BUFGMUX", "BUFGCTRL", "BUFR", "BUFIO",
           "DCM_ADV", "PLL_ADV", "PLL_BASE", "GND", "VCC", "$scopeinfo"}
#: The MIG core's user-interface outputs as its RTL drives them (MIG 3.6.1, ECC off: freecores/genesys_ddr2
#: ``ddr2_usr_addr_fifo.v``, ``ddr2_usr_wr.v``, ``ddr2_usr_rd.v``): the FIFO36 ALMOSTFULL flags straight out, the
#: rest from flip-flops. Its inputs go straight into the FIFOs' DI/DIP and WREN.
MIG_CORE_OUTPUTS = {"app_af_afull": "bram_cko", "app_wdf_afull": "bram_cko", "rd_data_fifo_out": "ff_cko",
                    "rd_data_valid": "ff_cko", "phy_init_done": "ff_cko"}
MIG_CORE_INPUTS = {"app_af_cmd": "bram_di", "app_af_addr": "bram_di", "app_af_wren": "bram_en",
                   "app_wdf_data": "bram_di", "app_wdf_mask_data": "bram_di", "app_wdf_wren": "bram_en"}
OUTPUT_BUFFERS = {"OBUF", "OBUFT", "IOBUF"}
#: Global clock buffers (their output ``O``).
_GLOBAL_BUFFERS = {"BUFG", "BUFGCE", "BUFGMUX", "BUFGCTRL"}


class ModelError(ValueError):
    """The netlist holds a cell the delay model has no figures for."""


def clock_periods(memory="bram"):
    """``{domain: period in ns}`` from the board's clock plan (``board.clocking.PLAN``; the camera domains at the PCLK
    frequency the UCF constrains, ``board.vmodcam.CAM_PCLK_MAX_HZ``; with ``memory="ddr2"`` the ``mem`` domain at
    MIG's ``clk0``, ``board.clocking.MIG_PLAN``): the figures the PERIOD constraints carry."""
    from board.clocking import MIG_PLAN, PLAN
    from board.vmodcam import CAM_PCLK_MAX_HZ
    from hdl.system import CAMERAS
    periods = {domain: 1e9 / float(hz) for domain, _, hz, _, _ in PLAN.table()}
    periods.update({f"cam_{c}": 1e9 / CAM_PCLK_MAX_HZ for c in CAMERAS})
    if memory == "ddr2":
        periods["mem"] = 1e9 / float(MIG_PLAN.clk0_hz)
    return periods


def _param(cell, name, default=0):
    value = cell.get("parameters", {}).get(name, default)
    if isinstance(value, str) and value and set(value) <= {"0", "1"}:
        return int(value, 2)
    return value


@dataclass
class _CellTiming:
    """A cell's timing arcs, by net bit: ``arcs`` (in_port, in_bit, out_bit, ns) through it, ``launches``
    (out_port, out_bit, clock_bit, ns) of its registers, ``captures`` (in_port, in_bit, clock_bit, setup_ns,
    fraction of the period)."""
    arcs: list = field(default_factory=list)
    launches: list = field(default_factory=list)
    captures: list = field(default_factory=list)


def _bits(cell, port):
    return [b for b in cell["connections"].get(port, ()) if isinstance(b, int)]


def _inputs(cell):
    dirs = cell.get("port_directions", {})
    return [p for p in cell["connections"] if dirs.get(p) == "input"]


def _outputs(cell):
    dirs = cell.get("port_directions", {})
    return [p for p in cell["connections"] if dirs.get(p) == "output"]


def _all_to_all(timing, cell, ins, outs, ns):
    for port in ins:
        for b in _bits(cell, port):
            timing.arcs += [(port, b, o, ns) for out in outs for o in _bits(cell, out)]


def _carry4(cell, t, m):
    co, o = cell["connections"].get("CO", []), cell["connections"].get("O", [])
    for port in ("S", "DI"):
        for i, b in enumerate(cell["connections"].get(port, [])):
            if isinstance(b, int):
                t.arcs += [(port, b, x, m["carry_in"].ns) for x in co[i:] + o[i:] if isinstance(x, int)]
    for port, to_co in (("CI", m["carry_ci"].ns), ("CYINIT", m["carry_in"].ns)):
        for b in _bits(cell, port):
            t.arcs += [(port, b, x, to_co) for x in co if isinstance(x, int)]
            t.arcs += [(port, b, x, max(to_co, m["carry_ci_o"].ns)) for x in o if isinstance(x, int)]


def _flip_flop(cell, t, m, drives_pad):
    clk = _bits(cell, "C")[0]
    iob = str(cell.get("attributes", {}).get("IOB", "")).upper() == "TRUE"
    for q in _bits(cell, "Q"):
        t.launches.append(("Q", q, clk, m["iob_in_cko" if iob and not drives_pad else "ff_cko"].ns))
    d_setup = m["iob_out_setup" if iob and drives_pad else "ff_d"].ns
    for port, setup in (("D", d_setup), ("CE", m["ff_ce"].ns), (FLIP_FLOPS[cell["type"]], m["ff_sr"].ns)):
        t.captures += [(port, b, clk, setup, 1.0) for b in _bits(cell, port)]


def _ram_setup(port, m):
    for prefix, key in (("ADDR", "bram_addr"), ("WRADDR", "bram_addr"), ("RDADDR", "bram_addr"),
                        ("DI", "bram_di"), ("WE", "bram_we"), ("EN", "bram_en"), ("WREN", "bram_en"),
                        ("RDEN", "bram_en"), ("SSR", "bram_ssr"), ("REGCE", "bram_regce")):
        if re.fullmatch(prefix + r"P?[AB]?", port):
            return m[key].ns
    return None


def _ram(cell, t, m):
    """Block RAM: each port's inputs captured and its outputs launched by that port's clock."""
    sdp = cell["type"].endswith("SDP")
    for port in _inputs(cell) + _outputs(cell):
        if port.startswith(("CLK", "RDCLK", "WRCLK", "CASCADE")):
            continue                                    # the cascade pair's link is inside the column
        if sdp:
            read = port.startswith(("RD", "DO", "REGCE", "SSR"))
            side, clock, reg = "", "RDCLK" if read else "WRCLK", _param(cell, "DO_REG")
        else:
            side = port[-1]
            clock, reg = f"CLK{side}", _param(cell, f"DO{side}_REG")
        clocks = _bits(cell, clock)
        if not clocks:
            continue
        if port in _outputs(cell):
            cascaded = bool(_bits(cell, f"CASCADEINLAT{side}"))
            ns = m["bram_cko_reg" if reg else "bram_cko"].ns + (m["bram_cascade"].ns if cascaded else 0.0)
            t.launches += [(port, b, clocks[0], ns) for b in _bits(cell, port)]
        else:
            setup = _ram_setup(port, m)
            if setup is None:
                raise ModelError(f"no delay model for block RAM port {cell['type']}.{port}")
            t.captures += [(port, b, clocks[0], setup, 1.0) for b in _bits(cell, port)]


_DSP_GROUPS = {"A": "AREG", "ACIN": "AREG", "B": "BREG", "BCIN": "BREG", "C": "CREG", "PCIN": None,
               "CARRYIN": "CARRYINREG", "OPMODE": "OPMODEREG", "ALUMODE": "ALUMODEREG",
               "CARRYINSEL": "CARRYINSELREG"}


def _dsp(cell, t, m):
    """DSP48E: each input registered (captured, setup into its register), into M or P (captured with the setup
    through the multiplier or ALU) or combinational to P; P launched by the P, M or input registers."""
    preg, mreg = _param(cell, "PREG"), _param(cell, "MREG")
    clk = (_bits(cell, "CLK") or [None])[0]
    outs = _bits(cell, "P") + _bits(cell, "PCOUT")
    inreg_used = False
    for port in _inputs(cell):
        if port not in _DSP_GROUPS:
            continue
        mult = port in ("A", "ACIN", "B", "BCIN")
        reg = _DSP_GROUPS[port] and _param(cell, _DSP_GROUPS[port])
        if clk is not None and reg:
            setup, inreg_used = m["dsp_setup_inreg"].ns, True
        elif clk is not None and mreg and mult:
            setup = m["dsp_setup_mreg"].ns
        elif clk is not None and preg:
            setup = m["dsp_setup_preg_ab" if mult else "dsp_setup_preg_c"].ns
        else:
            through = m["dsp_ab_p" if mult else "dsp_c_p" if port in ("C", "PCIN", "CARRYIN") else "dsp_ctrl_p"].ns
            t.arcs += [(port, b, o, through) for b in _bits(cell, port) for o in outs]
            continue
        t.captures += [(port, b, clk, setup, 1.0) for b in _bits(cell, port)]
    if clk is not None and (preg or mreg or inreg_used):
        cko = m["dsp_cko_preg" if preg else "dsp_cko_mreg" if mreg else "dsp_cko_inreg"].ns
        t.launches += [("P", o, clk, cko) for o in outs]


def _lut_clocked(cell, t, clock, read_ns, setup_ns, cko_ns, *, capture_address):
    """A clocked primitive built from LUTs (distributed RAM, shift register): its address inputs reach the outputs
    as through a LUT (``read_ns``); the other inputs -- and the address too where it is also the write address
    (``capture_address``) -- are captured by ``clock`` (``setup_ns``), and the outputs launched by it (``cko_ns``)."""
    clocks = _bits(cell, clock)
    outs = [b for port in _outputs(cell) for b in _bits(cell, port)]
    for port in _inputs(cell):
        if port == clock:
            continue
        address = port.startswith(("ADDR", "A", "DPRA"))
        if address:
            t.arcs += [(port, b, o, read_ns) for b in _bits(cell, port) for o in outs]
        if clocks and (capture_address or not address):
            t.captures += [(port, b, clocks[0], setup_ns, 1.0) for b in _bits(cell, port)]
    if clocks:
        t.launches += [(port, b, clocks[0], cko_ns) for port in _outputs(cell) for b in _bits(cell, port)]


def _oddr(cell, t, m):
    clk = _bits(cell, "C")[0]
    opposite = str(_param(cell, "DDR_CLK_EDGE", "OPPOSITE_EDGE")) == "OPPOSITE_EDGE"
    for port in ("D1", "D2", "CE", "R", "S"):
        fraction = 0.5 if port == "D2" and opposite else 1.0
        t.captures += [(port, b, clk, m["oddr_setup"].ns, fraction) for b in _bits(cell, port)]


def _mig_core(cell, t, m):
    """The MIG core (a black box in the estimate): its user interface launched and captured by its ``clk0_tb``
    (the ``mem`` domain's clock) as :data:`MIG_CORE_OUTPUTS` / :data:`MIG_CORE_INPUTS` say; the memory pins and
    the clock inputs are not timed here (the core's own UCF constrains them)."""
    clk = _bits(cell, "clk0_tb")[0]
    for port, key in MIG_CORE_OUTPUTS.items():
        t.launches += [(port, b, clk, m[key].ns) for b in _bits(cell, port)]
    for port, key in MIG_CORE_INPUTS.items():
        t.captures += [(port, b, clk, m[key].ns, 1.0) for b in _bits(cell, port)]


def is_mig_core(cell):
    """Whether a netlist cell is the MIG core's black box (it has MIG's user-interface ports)."""
    return set(MIG_CORE_OUTPUTS) | set(MIG_CORE_INPUTS) | {"clk0_tb"} <= set(cell["connections"])


def cell_timing(cell, m=MODEL, *, drives_pad=False):
    """The :class:`_CellTiming` of one Yosys JSON cell under the delay model ``m`` (``drives_pad``: its output
    feeds an output buffer, i.e. an IOB output flip-flop). Raises :class:`ModelError` for an unknown cell type."""
    kind, t = cell["type"], _CellTiming()
    if kind in UNTIMED:
        pass
    elif kind in LUTS:
        _all_to_all(t, cell, _inputs(cell), ["O"], m["lut"].ns)
    elif kind in ("MUXF7", "MUXF8"):
        _all_to_all(t, cell, ("I0", "I1", "S"), ["O"], m[kind.lower()].ns)
    elif kind == "CARRY4":
        _carry4(cell, t, m)
    elif kind == "MUXCY":
        _all_to_all(t, cell, ("S", "DI"), ["O"], m["muxcy_s"].ns)
        _all_to_all(t, cell, ("CI",), ["O"], m["muxcy_ci"].ns)
    elif kind == "XORCY":
        _all_to_all(t, cell, ("LI", "CI"), ["O"], m["xorcy"].ns)
    elif kind in FLIP_FLOPS:
        _flip_flop(cell, t, m, drives_pad)
    elif kind in RAMS:
        _ram(cell, t, m)
    elif kind in SHIFT_REGISTERS:                   # the tap address is not captured: it only selects
        _lut_clocked(cell, t, "CLK", m["lut"].ns, m["srl_setup"].ns, m["srl_cko"].ns, capture_address=False)
    elif kind in LUT_RAMS:                          # the address is also the write address
        _lut_clocked(cell, t, "WCLK", m["lutram_read"].ns, m["lutram_setup"].ns, m["lutram_cko"].ns,
                     capture_address=True)
    elif kind == "DSP48E":
        _dsp(cell, t, m)
    elif kind == "ODDR":
        _oddr(cell, t, m)
    elif is_mig_core(cell):
        _mig_core(cell, t, m)
    else:
        raise ModelError(f"no delay model for cell type {kind}")
    return t


#: The inputs a LUT reaches inside its own slice (UG190 ch. 5: a LUT's O6/O5 into its carry-chain bit, S and DI,
#: and into the F7 multiplexer): free of routing when the LUT can sit there, i.e. when all such loads of its output
#: are one slice position (:meth:`_Netlist.slice_position`).
_IN_SLICE = {"CARRY4": ("S", "DI"), "MUXF7": ("I0", "I1"), "MUXCY": ("S", "DI"), "XORCY": ("LI",)}
#: The inputs only a LUT of the same slice drives (the carry multiplexer's select and the XOR's input are the LUT's
#: O6, the F7 multiplexer's data inputs two LUTs' outputs): any other driver, or a LUT placed for another position,
#: reaches them through a route-through LUT (a net and TILO).
_LUT_ONLY = {"CARRY4": ("S",), "MUXCY": ("S",), "XORCY": ("LI",), "MUXF7": ("I0", "I1")}
#: (driver cell type, driver port, its bit index or None) -> sink (type, port) pairs wired inside the slice or
#: column without general routing: CARRY4 CO3 (the slice's COUT) into the next CARRY4's CI, MUXCY into the next
#: carry bit, F7 into F8, DSP48E PCOUT into PCIN.
_CASCADES = (
    ({"CARRY4"}, "CO", 3, {"CARRY4": ("CI",)}),
    ({"MUXCY"}, "O", None, {"MUXCY": ("CI",), "XORCY": ("CI",)}),
    ({"MUXF7"}, "O", None, {"MUXF8": ("I0", "I1")}),
    ({"DSP48E"}, "PCOUT", None, {"DSP48E": ("PCIN",)}),
)


def _net_ns(nl, bit, sink, sink_port, net_ns, model=MODEL):
    """The routing cost of net ``bit`` into ``sink``'s ``sink_port``: ``net_ns``; nothing on a connection inside
    the slice or column (a LUT into the one slice position it feeds, :data:`_CASCADES`); ``net_ns`` + TILO into an
    input only a LUT of the slice drives (:data:`_LUT_ONLY`) from anything else (a route-through LUT)."""
    sink_type = nl.cells[sink]["type"]
    driver = nl.driver.get(bit)
    if driver is not None:
        name, port = driver
        kind = nl.cells[name]["type"]
        if kind in LUTS and sink_port in _IN_SLICE.get(sink_type, ()) and nl.in_slice(bit, sink, sink_port):
            return 0.0
        for kinds, out, index, sinks in _CASCADES:
            if (kind in kinds and port == out and sink_port in sinks.get(sink_type, ())
                    and (index is None or _bits(nl.cells[name], out).index(bit) == index)):
                return 0.0
    if sink_port in _LUT_ONLY.get(sink_type, ()):
        return net_ns + model["lut"].ns
    return net_ns


def _clean(name):
    return re.sub(r"^\$flatten\\", "", name.lstrip("\\")).replace("\\", "")


class _Netlist:
    """The top module of a Yosys JSON netlist with its drivers, loads and readable names."""

    def __init__(self, netlist):
        module = top_module(netlist)
        self.cells = module["cells"]
        self.names = bit_names(module["netnames"])
        self.driver, self.sinks, self._label, self._position = {}, {}, {}, {}
        for name, info in module["netnames"].items():
            if name.startswith("$") or info.get("hide_name"):
                continue
            width = len(info["bits"])
            for i, bit in enumerate(info["bits"]):
                label = _clean(name) + (f"[{i}]" if width > 1 else "")
                if isinstance(bit, int) and (bit not in self._label or len(label) < len(self._label[bit])):
                    self._label[bit] = label
        for name, cell in self.cells.items():
            for port in _outputs(cell):
                for b in _bits(cell, port):
                    self.driver[b] = (name, port)
            if cell["type"] != "$scopeinfo":
                for port in _inputs(cell):
                    for b in _bits(cell, port):
                        self.sinks.setdefault(b, []).append((name, port))

    def _carry_places(self, bit, name, port):
        """The CARRY4 bits whose ``port`` net ``bit`` drives, as ``(name, index)``; for DI only the bits where its
        LUT can be the bit's own (its O5 beside the select's O6: the select a constant, the same net, or a LUT with
        which it shares at most 5 inputs): any other DI comes through the slice's bypass input, i.e. routing."""
        conn = self.cells[name]["connections"]
        bits = [i for i, b in enumerate(conn[port]) if b == bit]
        if port == "DI":
            bits = [i for i in bits if self._lut_inputs(bit) is not None and (
                conn["S"][i] == bit or not isinstance(conn["S"][i], int)
                or self._lut_inputs(conn["S"][i]) is not None
                and len(self._lut_inputs(bit) | self._lut_inputs(conn["S"][i])) <= 5)]
        return {(name, i) for i in bits}

    def _lut_inputs(self, bit):
        """The input nets of the LUT driving ``bit`` (None if a LUT does not drive it)."""
        driver = self.driver.get(bit)
        if driver is None or self.cells[driver[0]]["type"] not in LUTS:
            return None
        cell = self.cells[driver[0]]
        return {b for port in _inputs(cell) for b in cell["connections"][port]}

    def slice_position(self, bit):
        """The one slice position whose in-slice inputs (:data:`_IN_SLICE`) net ``bit`` feeds: ``(CARRY4, bit
        index)``, ``(MUXF7, input)`` or a MUXCY with the XORCY of its bit; None when it feeds several (a LUT sits in
        one place: it reaches the others by routing) or none."""
        if bit not in self._position:
            places, cy = set(), {"MUXCY": set(), "XORCY": set()}
            for name, port in self.sinks.get(bit, ()):
                kind = self.cells[name]["type"]
                if port not in _IN_SLICE.get(kind, ()):
                    continue
                if kind == "CARRY4":
                    places |= self._carry_places(bit, name, port)
                elif kind == "MUXF7":
                    places.add((name, port))
                else:
                    cy[kind].add(name)
            if any(len(names) > 1 for names in cy.values()):
                places.add(None)                        # two carry bits of the older primitives
            if cy["MUXCY"] or cy["XORCY"]:
                places.add(tuple(sorted(cy["MUXCY"] | cy["XORCY"])))
            self._position[bit] = next(iter(places)) if len(places) == 1 else None
        return self._position[bit]

    def in_slice(self, bit, sink, port):
        """Whether net ``bit`` reaches ``sink``'s ``port`` inside the slice: it feeds one slice position
        (:meth:`slice_position`) and this input is that position's."""
        place = self.slice_position(bit)
        if place is None:
            return False
        kind = self.cells[sink]["type"]
        if kind == "CARRY4":
            return self._carry_places(bit, sink, port) == {place}
        if kind == "MUXF7":
            return place == (sink, port)
        return sink in place

    def driver_type(self, bit):
        d = self.driver.get(bit)
        return None if d is None else (self.cells[d[0]]["type"], d[1])

    def net_label(self, bit):
        return self._label.get(bit)

    def cell_label(self, name, port=None):
        """``TYPE name.PORT``: a flip-flop by the register its Q drives (or the port its output buffer drives), any
        other cell by its instance name."""
        cell = self.cells[name]
        label = None
        if cell["type"] in FLIP_FLOPS:
            q = (_bits(cell, "Q") or [None])[0]
            pads = [_bits(self.cells[s], "O") for s, _ in self.sinks.get(q, ())
                    if self.cells[s]["type"] in OUTPUT_BUFFERS]
            label = self.net_label(q) or next((self.net_label(o[0]) for o in pads if o), None)
        label = label or _clean(name)
        return f"{cell['type']} {label}" + (f".{port}" if port else "")

    def describe(self, bit):
        """The net's name; an unnamed net by its driver: a LUT (or other combinational cell) by its inputs."""
        label = self.net_label(bit)
        if label:
            return label
        name, port = self.driver[bit]
        cell = self.cells[name]
        if cell["type"] not in LEVELS:
            return f"{_clean(name)}.{port}"
        ins = [self.net_label(b) or self.driver_type(b)[0] if b in self.driver else "?"
               for p in _inputs(cell) for b in _bits(cell, p)]
        return f"{cell['type']} of ({', '.join(ins)})"

    def drives_pad(self, name):
        cell = self.cells[name]
        return any(self.cells[s]["type"] in OUTPUT_BUFFERS
                   for port in _outputs(cell) for b in _bits(cell, port) for s, _ in self.sinks.get(b, ()))


def _collect(nl, periods, model):
    """Every cell's arcs, launches and captures, the last two with their clock domain."""
    fanin, launches, captures, unclocked, unknown, domain_of = {}, {}, [], set(), {}, {}
    driver_name = {b: d[0] for b, d in nl.driver.items()}

    def domain(clk):
        if clk not in domain_of:
            found = domain_of_clock(clk, nl.names, periods, driver_name, nl.cells)
            # a clock a black box drives (the MIG core's clk0_tb): Yosys puts a BUFG on it, named after the domain
            for name, _ in nl.sinks.get(clk, ()) if found is None else ():
                if nl.cells[name]["type"] in _GLOBAL_BUFFERS and found is None:
                    found = domain_of_clock(_bits(nl.cells[name], "O")[0], nl.names, periods, driver_name, nl.cells)
            domain_of[clk] = found
        return domain_of[clk]

    for name, cell in nl.cells.items():
        try:
            t = cell_timing(cell, model, drives_pad=cell["type"] in FLIP_FLOPS and nl.drives_pad(name))
        except ModelError as exc:
            unknown[str(exc)] = unknown.get(str(exc), 0) + 1
            continue
        for port, b, o, ns in t.arcs:
            fanin.setdefault(o, []).append((b, name, port, ns))
        for port, b, clk, ns in t.launches:
            if domain(clk) is None:
                unclocked.add(name)
            else:
                launches.setdefault(b, []).append((domain(clk), ns, name, port))
        for port, b, clk, setup, fraction in t.captures:
            if domain(clk) is None:
                unclocked.add(name)
            else:
                captures.append((domain(clk), b, name, port, setup, fraction))
    if unknown:
        raise ModelError("; ".join(f"{what} ({n} cells)" for what, n in sorted(unknown.items())))
    return fanin, launches, captures, unclocked


def _propagate(nl, fanin, launches, net_ns, model=MODEL):
    """Latest arrival per net bit and launching domain: ``{bit: {domain: (ns, from_bit, cell, port, cell_ns,
    net_ns)}}`` (``from_bit`` None at a launch), in topological order; returns it and the bits left in loops."""
    arrival = {}
    for b, items in launches.items():
        for d, ns, name, port in items:
            if ns > arrival.setdefault(b, {}).get(d, (-1.0,))[0]:
                arrival[b][d] = (ns, None, name, port, ns, 0.0)
    succ, indeg = {}, {o: 0 for o in fanin}
    for o, arcs in fanin.items():
        for b, *_ in arcs:
            if b in fanin:
                succ.setdefault(b, []).append(o)
                indeg[o] += 1
    ready = [o for o, n in indeg.items() if n == 0]
    done = 0
    while ready:
        o = ready.pop()
        done += 1
        best = arrival.setdefault(o, {})
        for b, name, port, ns in fanin[o]:
            net = _net_ns(nl, b, name, port, net_ns, model)
            for d, (t, *_) in arrival.get(b, {}).items():
                if t + net + ns > best.get(d, (-1.0,))[0]:
                    best[d] = (t + net + ns, b, name, port, ns, net)
        for s in succ.get(o, ()):
            indeg[s] -= 1
            if indeg[s] == 0:
                ready.append(s)
    return arrival, len(fanin) - done


@dataclass
class Path:
    """One register-to-register path: ``through`` the combinational cells (``TYPE net``), in order."""
    start: str
    end: str
    levels: int             # LUT and MUXF7/MUXF8 cells
    carry4: int
    through: list
    delay_ns: float         # clock-to-out + cells + nets + setup
    slack_ns: float
    logic_ns: float
    route_ns: float

    def to_json(self):
        return {k: (round(v, 3) if isinstance(v, float) else v) for k, v in self.__dict__.items()}


@dataclass
class DomainTiming:
    period_ns: float
    endpoints: int = 0                              # timed endpoint pins
    paths: list = field(default_factory=list)       # the worst, one per endpoint, worst first
    fanout: list = field(default_factory=list)      # (loads, net, driver, {pin: loads}), largest first

    @property
    def worst_slack_ns(self):
        return self.paths[0].slack_ns if self.paths else None


def _trace(nl, arrival, bit, domain):
    """The launch and the cells of the latest path into ``bit`` from ``domain``'s registers."""
    steps = []
    while True:
        _, prev, name, port, cell_ns, net = arrival[bit][domain]
        if prev is None:
            return (name, port, cell_ns), steps[::-1]
        steps.append((name, bit, cell_ns, net))
        bit = prev


def _path(nl, arrival, end):
    """A :class:`Path` from one timed endpoint ``(slack, delay, domain, bit, cell, port, net, setup)``."""
    slack, delay, domain, bit, name, port, net, setup = end
    (start, start_port, cko), steps = _trace(nl, arrival, bit, domain)
    kinds = [nl.cells[s]["type"] for s, *_ in steps]
    through = [f"{k} {nl.net_label(b) or ''}".rstrip() for k, (_, b, *_) in zip(kinds, steps)]
    return Path(
        start=nl.cell_label(start, start_port), end=nl.cell_label(name, port),
        levels=sum(k in LEVELS for k in kinds), carry4=kinds.count("CARRY4"), through=through,
        delay_ns=delay, slack_ns=slack, logic_ns=cko + sum(s[2] for s in steps) + setup,
        route_ns=sum(s[3] for s in steps) + net)


def _fanouts(nl, arrival, domain, count):
    """The ``count`` nets of ``domain`` with the most loads, as ``(loads, net, driver, {load pin: count})``: the
    nets its registers' paths reach (a clock net, driven by a clock buffer, carries no such path)."""
    rows = []
    for b, loads in nl.sinks.items():
        d = nl.driver.get(b)
        if d is None or domain not in arrival.get(b, {}):
            continue
        pins = {}
        for _, port in loads:
            pins[port] = pins.get(port, 0) + 1
        rows.append((len(loads), nl.describe(b), nl.cell_label(*d), dict(sorted(pins.items(), key=lambda x: -x[1]))))
    return sorted(rows, key=lambda r: (-r[0], r[1]))[:count]


def analyse(netlist, periods, *, net_ns=NET_NS, model=MODEL, paths=10, fanout=5):
    """Time every register-to-register path of a Yosys JSON ``netlist`` (a flattened ``synth_xilinx`` result)
    whose launching and capturing clocks are the same domain of ``periods`` (``{domain: ns}``); returns a
    :class:`TimingReport` with the ``paths`` worst endpoints and the ``fanout`` largest nets per domain.

    Raises
    ------
    ModelError
        The netlist holds cell types the delay model has no figures for (all of them are named).
    """
    nl = _Netlist(netlist)
    fanin, launches, captures, unclocked = _collect(nl, periods, model)
    arrival, loops = _propagate(nl, fanin, launches, net_ns, model)
    ends = {d: [] for d in periods}
    for domain, bit, name, port, setup, fraction in captures:
        a = arrival.get(bit, {}).get(domain)
        if a is None:
            continue
        net = _net_ns(nl, bit, name, port, net_ns, model)
        delay = a[0] + net + setup
        ends[domain].append((periods[domain] * fraction - delay, delay, domain, bit, name, port, net, setup))
    domains = {}
    for domain, items in ends.items():
        items.sort(key=lambda e: (e[0], e[4], e[5]))
        domains[domain] = DomainTiming(
            period_ns=periods[domain], endpoints=len(items),
            paths=[_path(nl, arrival, e) for e in items[:paths]], fanout=_fanouts(nl, arrival, domain, fanout))
    return TimingReport(net_ns=net_ns, domains=domains, unclocked=sorted(_clean(n) for n in unclocked),
                        loops=loops, model=model)


@dataclass
class TimingReport:
    net_ns: float
    domains: dict                                   # domain -> DomainTiming
    unclocked: list = field(default_factory=list)   # sequential cells whose clock is no known domain
    loops: int = 0                                  # net bits on combinational loops (not timed)
    model: dict = field(default_factory=lambda: dict(MODEL))

    def failing(self):
        """The domains with negative worst slack."""
        return [d for d, t in sorted(self.domains.items()) if t.worst_slack_ns is not None and t.worst_slack_ns < 0]

    def summary_lines(self):
        out = [f"{'domain':8} {'clock':>12} {'period':>10} {'worst delay':>12} {'worst slack':>12} "
               f"{'endpoints':>10}"]
        for d, t in sorted(self.domains.items()):
            mhz = f"{1e3 / t.period_ns:.3f} MHz"
            if not t.paths:
                out.append(f"{d:8} {mhz:>12} {t.period_ns:>7.3f} ns   (no register-to-register paths)")
                continue
            worst = t.paths[0]
            out.append(f"{d:8} {mhz:>12} {t.period_ns:>7.3f} ns {worst.delay_ns:>9.3f} ns {worst.slack_ns:>9.3f} ns "
                       f"{t.endpoints:>10}{'   NEGATIVE SLACK' if worst.slack_ns < 0 else ''}")
        return out

    def domain_lines(self, domain):
        t = self.domains[domain]
        what = f"{len(t.paths)} worst register-to-register paths" if t.paths else "no register-to-register paths"
        out = [f"== {domain}: {what} (period {t.period_ns:.3f} ns) =="]
        if t.paths:
            out.append(f"  {'slack':>7} {'delay':>7} {'logic':>6} {'route':>6} {'levels':>6} {'carry4':>6}  "
                       "start -> end")
        for p in t.paths:
            out.append(f"  {p.slack_ns:>7.3f} {p.delay_ns:>7.3f} {p.logic_ns:>6.2f} {p.route_ns:>6.2f} "
                       f"{p.levels:>6} {p.carry4:>6}  {p.start} -> {p.end}")
        if t.fanout:
            out.append(f"  largest fanout nets ({domain}):")
            for loads, net, driver, pins in t.fanout:
                kinds = ", ".join(f"{p} {n}" for p, n in list(pins.items())[:3]) + (", ..." if len(pins) > 3 else "")
                out.append(f"  {loads:>7} loads ({kinds})  {net}  (driven by {driver})")
        return out

    def lines(self):
        out = [f"static timing estimate: Yosys synth_xilinx -family xc5v netlist, Virtex-5 -1 delay model "
               f"(board/virtex5_delays.py, values assumed), {self.net_ns:.2f} ns per net, no placement", ""]
        out += self.summary_lines()
        for d in sorted(self.domains):
            out += [""] + self.domain_lines(d)
        if self.unclocked:
            out += ["", f"not timed: {len(self.unclocked)} sequential cells on a clock of no known domain "
                        f"(first: {', '.join(self.unclocked[:3])})"]
        if self.loops:
            out += ["", f"not timed: {self.loops} net bits on combinational loops"]
        failing = self.failing()
        out += ["", f"negative slack in: {', '.join(failing)}" if failing else "every domain meets its period"]
        return out

    def to_json(self):
        return {
            "net_ns": self.net_ns,
            "model": {k: {"ns": c.ns, "symbol": c.symbol, "what": c.what, "table": c.table, "named_in": c.named_in,
                          "source": c.source}
                      for k, c in self.model.items()},
            "domains": {d: {"period_ns": round(t.period_ns, 4), "endpoints": t.endpoints,
                            "worst_slack_ns": None if t.worst_slack_ns is None else round(t.worst_slack_ns, 3),
                            "paths": [p.to_json() for p in t.paths],
                            "fanout": [{"loads": n, "net": net, "driver": drv, "pins": pins}
                                       for n, net, drv, pins in t.fanout]}
                        for d, t in sorted(self.domains.items())},
            "unclocked": self.unclocked, "loops": self.loops, "failing": self.failing(),
        }


def estimate(out, *, top_kwargs=None, net_ns=NET_NS, paths=10, fanout=5, keep_netlist=False):
    """Synthesise the board design ``GenesysTop(**top_kwargs)`` (none: the board's; a DDR2 build with the MIG core
    a black box, ``board.resources.board_rtlil``) with Yosys in ``out`` and time it; returns ``(TimingReport,
    yosys_seconds)``. ``net.json`` (tens of MB) is removed unless ``keep_netlist``."""
    from board.resources import board_black_boxes, board_memory, board_rtlil, run_yosys
    top_kwargs = top_kwargs or {}
    _, netlist, seconds = run_yosys(board_rtlil(**top_kwargs), out, black_boxes=board_black_boxes(top_kwargs))
    if not keep_netlist:
        (_FilePath(out) / "net.json").unlink()
    periods = clock_periods(board_memory(top_kwargs))
    return analyse(netlist, periods, net_ns=net_ns, paths=paths, fanout=fanout), seconds
