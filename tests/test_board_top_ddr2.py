"""The DDR2 board build (``stereodepth verilog --memory ddr2 --mig DIR``) simulated as built: its ``top.v`` with the
Virtex-5 primitive models and, in place of the user's MIG core, the MIG model behind MIG's port names
(``sim.board.top.mig_core_verilog``), at the small sizes of ``SystemSetup.small()`` as tests/test_board_top.py
runs the block-RAM build.

Default run: the design as the board build elaborates it (the system of the board top is the DDR2 build, its
``mig`` port on the core's user interface) and the build's refusal without the core. Slow: the whole board top
under cocotb on Verilator, the display frame bit-exact to the golden model with no tear, at both ends of the
model's read-latency range (about 2.5 minutes each here)."""

import re

import pytest

from sim.board.top import board_primitives, board_setup, board_top_kwargs, board_verilog, mig_core_verilog
from sim.models.mig import LATENCY_PLUSARG, READ_LATENCY_RANGE
from test_board_top import SMALL, run_board_cocotb, _skip_unless

SMALL_DDR2 = {**SMALL, "memory": "ddr2"}


def ddr2_kwargs(**overrides):
    return board_top_kwargs(board_setup(SMALL_DDR2), **overrides)


def _rtlil_cells(rtlil, module):
    """``{cell name: (type, {port: signal text})}`` of ``module`` in Amaranth's RTLIL text."""
    body = re.search(rf"^module \\{re.escape(module)}\n(.*?)^end\n", rtlil, re.S | re.M)
    assert body, f"no module {module}"
    cells = {}
    for m in re.finditer(r"^  cell \\?(\S+) \\?(\S+)\n(.*?)^  end\n", body[1], re.S | re.M):
        ports = dict(re.findall(r"^    connect \\(\S+) (.+)$", m[3], re.M))
        cells[m[2]] = (m[1], ports)
    return cells


def test_ddr2_board_top_has_the_frame_store_on_the_core():
    """GenesysTop(memory="ddr2") as the board build elaborates it: its system is the DDR2 build, and each of the
    system's ``mig`` ports and the MIG core's user-side port of the same member are one net of the top."""
    from board.mig import MIG_USER_PORTS
    from board.top import board_plan
    _, plan = board_plan(files=(".il",), allow_unconfirmed=True, mig_black_box=True, **ddr2_kwargs())
    rtlil = plan.files["top.il"]
    top = _rtlil_cells(rtlil, "top")
    system = top["system"][1]
    ddr2 = top["ddr2"][1]
    core = _rtlil_cells(rtlil, "top.ddr2")["mig"]
    assert core[0] == "mig_ddr2"
    for name, member in MIG_USER_PORTS.items():
        path = "__".join(member)
        assert system[f"mig__{path}"] == ddr2[f"user__{path}"], name        # one net in the top
        assert core[1][name].split(" [")[0] == f"\\user__{path}", name      # the core's port in ddr2


def test_ddr2_board_top_needs_the_core_or_its_stand_in():
    from board.top import MIGCoreMissing, board_plan
    with pytest.raises(MIGCoreMissing, match="--mig DIR"):
        board_plan(files=(".il",), **ddr2_kwargs())
    with pytest.raises(ValueError, match="with the DDR2"):
        mig_core_verilog(board_top_kwargs(board_setup(SMALL)))


@pytest.mark.slow
@pytest.mark.parametrize("latency", [READ_LATENCY_RANGE[0], READ_LATENCY_RANGE[1]])
def test_ddr2_board_top_small(latency, tmp_path):
    """The DDR2 board top at the small sizes on Verilator: the frame store in the MIG model behind MIG's ports,
    the model's read latency at either end of its range (one build, the latency a plusarg); the display frame
    equals the golden frame bit for bit, with no tear, and the parts end in their golden states."""
    _skip_unless("verilator")
    kwargs = ddr2_kwargs()
    verilog = board_verilog(kwargs) + mig_core_verilog(kwargs)
    r = run_board_cocotb(verilog, "verilator", spec=SMALL_DDR2, out_dir=tmp_path, primitives=board_primitives("ddr2"),
                         plusargs=[f"+{LATENCY_PLUSARG}={latency}"])
    assert r.status["tear"] is None
    assert r.status["mismatched_pixels"] == 0 and (r.frame == r.golden).all()
    assert not any(r.status["state_diff"].values())
