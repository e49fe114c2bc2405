"""The board build as XST and ngdbuild read it: constraints only on names that exist after XST, and a ``top.v``
both XST Verilog parsers take (board/export.py ``xst_verilog``, board/genesys.py's UCF).

* Every ``NET`` of the UCF names a top-level port (bit) or a net that a cell output drives inside the module the
  path names, never a net that is only an ``assign`` alias of another (XST keeps one name per net: a constraint
  on the alias stops ngdbuild with "NET not found"); every ``INST`` a cell instance; every group a ``TIMEGRP``,
  ``PERIOD``, ``FROM``/``TO`` or ``OFFSET`` uses is defined by a ``TNM``/``TNM_NET`` on such a net.
* ``top.v``: no statement attributes, no attribute XST does not document, no source paths, no ``init`` on alias
  wires, plain module names, ``ASYNC_REG`` and ``SHREG_EXTRACT`` on the synchroniser ``reg`` declarations,
  ``ROM_STYLE`` on the I2C ROMs (distributed) and the readout ROM (block). Each step of ``xst_verilog`` has a
  test that fails without it.
* The ISE scripts: trce after par, bitgen only after a timing check, map/par options stated, a second run works.
"""

import re

import pytest

from board.export import XST_ATTRIBUTES, attributes_onto_registers, xst_module_name, xst_yosys_script

#: Output pins of the Xilinx primitives the board instantiates (UG190 / the unisim models): a net on one of
#: these is driven by a cell.
PRIMITIVE_OUTPUTS = {
    "BUFG": {"O"}, "IBUF": {"O"}, "OBUF": set(), "OBUFT": set(), "IOBUF": {"O"}, "FDCE": {"Q"}, "FDPE": {"Q"},
    "ODDR": {"Q"}, "DCM_ADV": {"CLK0", "CLK90", "CLK180", "CLK270", "CLK2X", "CLK2X180", "CLKDV", "CLKFX",
                               "CLKFX180", "LOCKED", "PSDONE", "DRDY", "DO"},
    "PLL_ADV": {"CLKOUT0", "CLKOUT1", "CLKOUT2", "CLKOUT3", "CLKOUT4", "CLKOUT5", "CLKFBOUT", "CLKFBDCM",
                "CLKOUTDCM0", "LOCKED", "DRDY", "DO"},
    "PLL_BASE": {"CLKOUT0", "CLKOUT1", "CLKOUT2", "CLKOUT3", "CLKOUT4", "CLKOUT5", "CLKFBOUT", "LOCKED"},
}


@pytest.fixture(scope="module")
def build(board_build):
    return dict(board_build[1])         # the board build of tests/conftest.py, made once per worker


# --- a small reader of the netlist ----------------------------------------------------------------------------

def modules(verilog):
    """``{module name: body}``."""
    return {m[1]: m[2] for m in re.finditer(r"^module (\S+?) ?\((?:.*?)\);\n(.*?)^endmodule", verilog, re.S | re.M)}


def instances(body, names):
    """``[(type, instance name, {pin: net})]`` of the instances in ``body`` whose type is in ``names``."""
    out = []
    # an instance name may be escaped (`\\clocking `: Yosys escapes SystemVerilog keywords); Verilog-2001
    # 3.7.1: the escaped and the plain identifier are the same name
    pattern = r"^[ \t]*(\S+)[ \t]+(?:#\((?:.*?)\)\s*)?(\\\S+ |\S+) +\((.*?)\n\s*\);"
    for m in re.finditer(pattern, body, re.S | re.M):
        if m[1] in names:
            pins = dict(re.findall(r"\.(\w+)\(([^()]*)\)", m[3]))
            out.append((m[1], m[2].strip().lstrip("\\"), {p: n.strip() for p, n in pins.items()}))
    return out


def top_ports(verilog):
    header = re.search(r"^module top\((.*?)\);", verilog, re.S | re.M)[1]
    return {p.strip() for p in header.replace("\n", " ").split(",")}


def resolve_net(verilog, path):
    """Why the UCF net ``path`` exists after XST, or raise AssertionError: a top-level port (bit), or a net a
    cell output drives in the module the hierarchical path leads to, and no ``assign`` alias."""
    name = re.sub(r"<\d+>$", "", path)
    parts = name.split("/")
    mods = modules(verilog)
    if len(parts) == 1 and name in top_ports(verilog):
        return "port"
    module = "top"
    for inst in parts[:-1]:
        children = {i: t for t, i, _ in instances(mods[module], set(mods))}
        assert inst in children, f"{path}: no instance {inst} in {module}"
        module = children[inst]
    net, body = parts[-1], mods[module]
    assert not re.search(rf"^\s*assign {re.escape(net)} = ", body, re.M), f"{path}: only an alias (assign)"
    for kind, inst, pins in instances(body, set(PRIMITIVE_OUTPUTS) | set(mods)):
        outputs = PRIMITIVE_OUTPUTS.get(kind, set())
        if any(pins.get(pin) == net for pin in outputs):
            return f"{kind} {inst} output"
    raise AssertionError(f"{path}: no cell output drives it in {module}")


def resolve_inst(verilog, path):
    parts = path.split("/")
    mods, module = modules(verilog), "top"
    for inst in parts:
        children = {i: t for t, i, _ in instances(mods.get(module, ""), set(mods) | set(PRIMITIVE_OUTPUTS))}
        assert inst in children, f"INST {path}: no cell {inst} in {module}"
        module = children[inst]
    return module


def check_ucf_names(ucf, verilog):
    """Every NET, INST and group of ``ucf`` (see the module docstring); returns the number of names checked. A
    path starting with ``*`` names cells inside a black-box core (the MIG core's UCF, board/mig_ucf.py), which
    this netlist does not hold: not checked here, its group counts as defined."""
    lines = [raw.split("#", 1)[0].strip() for raw in ucf.splitlines()]
    lines = [line for line in lines if line]
    groups, checked = set(), 0
    for line in lines:
        if re.match(r'^(NET|INST) "\*', line):
            groups.update(re.findall(r'TNM(?:_NET)? = "([^"]+)"', line))
            continue
        m = re.match(r'^NET "([^"]+)"', line)
        if m:
            resolve_net(verilog, m[1])
            checked += 1
            g = re.search(r'TNM(?:_NET)? = "([^"]+)"', line)
            if g:
                groups.add(g[1])
        m = re.match(r'^INST "([^"]+)"', line)
        if m:
            resolve_inst(verilog, m[1])
            checked += 1
            g = re.search(r'TNM = "([^"]+)"', line)
            if g:
                groups.add(g[1])
    for line in lines:
        used = re.findall(r'(?:PERIOD|FROM|TO|TIMEGRP) "([^"]+)"', line)
        for group in used:
            assert group in groups, f"group {group} is not defined on a net or cell of the netlist: {line}"
            checked += 1
        for pad in re.findall(r'(?:BEFORE|AFTER|REFERENCE_PIN) "([^"]+)"', line):
            assert resolve_net(verilog, pad) == "port", f"{pad} must be a pad: {line}"
            checked += 1
    return checked


# --- constraints ------------------------------------------------------------------------------------------------

def test_every_ucf_name_exists_after_xst(build):
    assert check_ucf_names(build["top.ucf"], build["top.v"]) > 100


def test_the_check_rejects_an_alias_a_missing_net_and_an_undefined_group(build):
    """The checker itself bites: the old PERIOD on the alias ``clocking/sync_bufg`` (``assign sync_bufg = clk``),
    a net nothing drives, an instance that does not exist and a TIG on an undefined group all fail."""
    verilog, ucf = build["top.v"], build["top.ucf"]
    for bad in ('NET "clocking/sync_bufg" TNM_NET = "PRDsync";',
                'NET "clocking/no_such_net" TNM_NET = "X";',
                'INST "clocking/no_such_bufg" TNM = "X";',
                'TIMESPEC "TS_X" = FROM "TIG_pix" TO "TIG_nowhere" TIG;'):
        with pytest.raises(AssertionError):
            check_ucf_names(ucf + "\n" + bad + "\n", verilog)


def test_periods_on_pads_only_and_tigs_on_the_pll_outputs(build):
    ucf = build["top.ucf"]
    periods = re.findall(r'PERIOD "PRD([^"]+)" ([\d.]+) ns', ucf)
    assert sorted(periods) == sorted([("clk100_0__io", "10.0000"), ("vmodcam_0__pclk__io", "12.5000"),
                                      ("vmodcam_1__pclk__io", "12.5000")])
    # a PERIOD group used in anything else is not traced through a DCM/PLL (AR 6905): each used exactly once
    for group in ("PRDclk100_0__io", "PRDvmodcam_0__pclk__io", "PRDvmodcam_1__pclk__io"):
        assert len(re.findall(rf'"{group}"', ucf)) == 2, group         # its TNM_NET and its PERIOD
    nets = dict(re.findall(r'NET "([^"]+)" TNM_NET = "(TIG_\w+)";', ucf))
    assert nets == {"clocking/pll_cam_clkout0": "TIG_mclk", "clocking/pll_pix_clkout0": "TIG_pix",
                    "clocking/pll_pix_clkout1": "TIG_pix90", "vmodcam_0__pclk__io": "TIG_cam_a",
                    "vmodcam_1__pclk__io": "TIG_cam_b"}
    tigs = set(re.findall(r'FROM "(\w+)" TO "(\w+)" TIG;', ucf))
    assert ("TIG_pix", "TIG_pix90") not in tigs and ("TIG_pix90", "TIG_pix") not in tigs     # one PLL: related
    assert len(tigs) == 5 * 4 - 2 and ("TIG_cam_a", "TIG_cam_b") in tigs and ("TIG_mclk", "TIG_pix") in tigs


def test_ch7301c_offset_out_against_the_forwarded_clock(build):
    ucf = build["top.ucf"]
    group = re.findall(r'NET "(ch7301c_0__\w+(?:<\d+>)?)" TNM = "DVI_OUT";', ucf)
    assert sorted(group) == sorted([f"ch7301c_0__d__io<{i}>" for i in range(12)]
                                   + ["ch7301c_0__h__io", "ch7301c_0__v__io", "ch7301c_0__de__io"])
    for edge in ("RISING", "FALLING"):
        assert (f'TIMEGRP "DVI_OUT" OFFSET = OUT 6.734 ns AFTER "clk100_0__io" REFERENCE_PIN '
                f'"ch7301c_0__xclk_p__io" {edge};') in ucf


# --- top.v ------------------------------------------------------------------------------------------------------

def attributes(verilog):
    return re.findall(r"\(\* (\w+)(?: = [^*]*)? \*\)", verilog)


def test_only_documented_attributes_and_none_on_statements(build):
    verilog = build["top.v"]
    assert set(attributes(verilog)) == set(XST_ATTRIBUTES) - {"RAM_STYLE"}
    # an attribute line is followed by a declaration or an instance, never by a statement
    for m in re.finditer(r"\(\* [^\n]* \*\)\n\s*(\S+)", verilog):
        assert not m[1].startswith(("if", "case", "casez", "always", "assign", "begin")), m.group(0)
    assert "src" not in re.findall(r"\(\* (\w+)", verilog) and "/work/" not in verilog


def test_no_source_locations_from_the_platform(build):
    """The platform writes its RTLIL without source locations (absolute paths of the building machine), so
    neither top.v nor top.il carries any."""
    assert "attribute \\src" not in build["top.il"]


def test_plain_module_names(build):
    names = list(modules(build["top.v"]))
    assert len(names) > 100 and all(re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", n) for n in names)
    assert "top__system__switches__sw_synchroniser" in names
    assert xst_module_name("top.x.cost$190") == "top__x__cost_190"


def test_synchroniser_registers_carry_async_reg_and_shreg_extract(build):
    verilog = build["top.v"]
    regs = re.findall(r'\(\* ASYNC_REG = "TRUE" \*\)\n\s*\(\* SHREG_EXTRACT = "no" \*\)\n\s*reg (?:\[\d+:0\] )?(\w+)',
                      verilog)
    # 6 I2C line synchronisers (scl, sda per bus), the switch synchroniser, the frame-skew meter's two frame-start
    # pulse synchronisers, the vertical-offset search's two frame-done ones and the two row-tag trackers' three each
    # (frame start, row start, row end), 2 stages each
    assert sorted(regs) == sorted(["stage0", "stage1"] * 17)
    assert not re.search(r"\(\* (?:ASYNC_REG|SHREG_EXTRACT)[^\n]*\*\)\n(?:\s*\(\*[^\n]*\*\)\n)*\s*(?:output|wire|input)",
                         verilog)
    # the reset synchronisers are FDPE instances with ASYNC_REG (6 domains, 2 stages)
    assert len(re.findall(r'\(\* ASYNC_REG = "TRUE" \*\)\n\s*FDPE', verilog)) == 12


def test_no_init_attribute_and_register_initial_values_kept(build):
    verilog = build["top.v"]
    assert "(* init" not in verilog
    assert re.search(r"reg stage1 = 1'h1;", verilog)          # the I2C line synchronisers start released


def test_i2c_roms_are_distributed_and_the_readout_rom_block(build):
    roms = re.findall(r'\(\* ROM_STYLE = "distributed" \*\)\n\s*reg \[\d+:0\] (\w+) \[', build["top.v"])
    assert roms == ["rom"]                          # the one init sequencer's tables
    roms = re.findall(r'\(\* ROM_STYLE = "block" \*\)\n\s*reg \[\d+:0\] (\w+) \[', build["top.v"])
    assert roms == ["readout_rom"]


def test_the_yosys_script_removes_what_the_rtlil_has(build):
    """Without the attrmap step the RTLIL's enum/keep/generator attributes (and Yosys's full_case) would reach
    top.v: the script removes each of them, keeps the XST ones, and renames every escaped module."""
    rtlil = build["top.il"]
    script = xst_yosys_script(rtlil)
    present = set(re.findall(r"^\s*attribute \\(\S+) ", rtlil, re.M))
    assert {"enum_base_type", "generator"} <= present
    general = [line + " " for line in script.splitlines() if line.startswith("attrmap ") and "@" not in line]
    assert len(general) == 2                                   # objects and modules
    for name in (present | {"full_case"}) - set(XST_ATTRIBUTES) - {"init"}:
        assert all(f"-remove {name} " in line for line in general), name
    for name in XST_ATTRIBUTES:
        assert not any(f"-remove {name} " in line for line in general), name
    assert script.count("chtype -map ") == len(re.findall(r"^module \\top\.", rtlil, re.M))


def test_attributes_move_from_the_output_declaration_onto_the_reg():
    """Yosys writes a register's attributes on its ``output`` declaration when it is a port; the rewrite moves
    them onto the ``reg`` and touches nothing else."""
    text = ('  (* ASYNC_REG = "TRUE" *)\n  (* SHREG_EXTRACT = "no" *)\n  output [7:0] stage1;\n'
            "  reg [7:0] stage1 = 8'h00;\n  output q;\n  reg q;\n  (* IOB = \"TRUE\" *)\n  output z;\n  wire z;\n")
    moved, names = attributes_onto_registers(text)
    assert names == ["stage1"]
    assert moved.startswith('  output [7:0] stage1;\n  (* ASYNC_REG = "TRUE" *)\n  (* SHREG_EXTRACT = "no" *)\n'
                            "  reg [7:0] stage1 = 8'h00;")
    assert moved.endswith('  (* IOB = "TRUE" *)\n  output z;\n  wire z;\n')    # not a register: unchanged


# --- the ISE scripts ---------------------------------------------------------------------------------------------

def test_build_script_times_before_bitgen_and_states_its_options(build):
    for name, check in (("build_top.sh", 'grep -q "All constraints were met." top.twr'),
                        ("build_top.bat", 'findstr /C:"All constraints were met." top.twr')):
        script = build[name]
        order = [script.index(tool) for tool in ('XST%" -ifn' if name.endswith(".bat") else '"$XST" -ifn',
                                                  "-uc top.ucf", "-o top_map.ncd", "top_map.ncd top_par.ncd",
                                                  "-o top.twr top_par.ncd top.pcf", check, "top_par.ncd top.bit")]
        assert order == sorted(order), name
        assert "-w -ol high -timing -o top_map.ncd" in script and "-w -ol high top_map.ncd" in script
        assert "-v 10 -u 10 -o top.twr" in script
    sh = build["build_top.sh"]
    gate = sh[sh.index("if ! grep"):sh.index('"$BITGEN"')]
    assert "exit 1" in gate


def test_project_tcl_runs_twice_in_the_same_folder(build):
    tcl = build["top_ise_project.tcl"]
    delete = tcl.index("if {[file exists top.xise]} { file delete -force top.xise top.gise }")
    assert delete < tcl.index("project new top.xise")
    options = [line for line in build["top.xst"].splitlines()
               if line.startswith("-") and not line.startswith(("-ifn", "-ofn", "-top", "-p "))]
    assert options == ["-hierarchy_separator /", "-bus_delimiter <>", "-keep_hierarchy no"]
    assert f'"Other XST Command Line Options" "{" ".join(options)}"' in tcl
