"""The one flattening rule (board.export.flat_name, Amaranth's own) against the exported Verilog: a top's ports are
exactly ``flat_ports(top)`` (plus the clocks and resets Amaranth adds for domains it creates), none with a ``$N``
suffix."""

import re

import pytest

from hdl.display_path import DisplayPath
from board.export import amaranth_verilog, flat_name, flat_ports
from spec.video import SMALL_TIMING
from sim.testbench.system.cocotb_routes import InSimulator, PythonModels
from sim.testbench.system.setup import SystemSetup


def top_ports(verilog, name):
    header = re.search(rf"^module {name}\((.*?)\);", verilog, flags=re.M | re.S).group(1)
    return {p.strip().lstrip("\\") for p in header.split(",")}


def test_flat_name_is_the_path_joined_by_double_underscores():
    assert flat_name(("i2c", "dvi", "scl", "oe")) == "i2c__dvi__scl__oe"
    assert flat_name(("cam_a", "data")) == "cam_a__data"


DESIGNS = {
    "display_path": (lambda: DisplayPath(SMALL_TIMING), {"clk", "rst"}),
    "system, python route": (lambda: PythonModels().design(SystemSetup.small()), set()),
    "system, in-simulator route": (lambda: InSimulator().design(SystemSetup.small()), set()),
}


@pytest.mark.parametrize("make, domain_ports", DESIGNS.values(), ids=DESIGNS.keys())
def test_exported_ports_follow_the_rule(make, domain_ports):
    design = make()
    verilog = amaranth_verilog(design, "top")
    ports = top_ports(verilog, "top")
    assert not [p for p in ports if "$" in p]
    assert ports == set(flat_ports(design)) | domain_ports
