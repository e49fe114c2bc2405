# amaranth: UnusedElaboratable=no
"""hdl.forward.forward: the owner's member object is handed down to the child (checked against the child's member),
reaches the innermost child however deep and in whatever order the forwards happen, and no signal is renamed."""

import re

import pytest
from amaranth import Module, Signal, Value
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from board.export import amaranth_verilog, flat_ports
from hdl.forward import forward
from sim.testbench.system.cocotb_routes import PythonModels
from sim.testbench.system.setup import SystemSetup

Pair = wiring.Signature({"data": Out(8), "valid": Out(1), "ready": In(1, init=1)})


class Leaf(wiring.Component):
    """Drives ``out`` from ``inp`` (plus one), sets ``flag``."""

    def __init__(self):
        super().__init__({"inp": In(Pair), "out": Out(Pair), "flag": Out(1)})

    def elaborate(self, platform):
        m = Module()
        m.d.sync += [self.out.data.eq(self.inp.data + 1), self.out.valid.eq(self.inp.valid)]
        m.d.comb += [self.inp.ready.eq(self.out.ready), self.flag.eq(self.inp.valid)]
        return m


class Box(wiring.Component):
    """A component with the members ``members`` and nothing inside but ``children``."""

    def __init__(self, members, **children):
        self.children = children
        super().__init__(members)

    def elaborate(self, platform):
        m = Module()
        for name, child in self.children.items():
            m.submodules[name] = child
        return m


PORT = wiring.Signature({"inp": In(Pair), "out": Out(Pair)})


def middle(leaf):
    """Passes ``leaf``'s members through: ``port.inp``, ``port.out`` and ``flag``."""
    box = Box({"port": Out(PORT), "flag": Out(1)}, leaf=leaf)
    forward(box, ("port", "inp"), leaf)
    forward(box, ("port", "out"), leaf)
    forward(box, "flag", leaf)
    return box


def outer(mid):
    """Passes ``mid``'s members through under other names: ``a`` (its ``port``) and ``led`` (its ``flag``)."""
    box = Box({"a": Out(PORT), "led": Out(1)}, middle=mid)
    forward(box, "a", mid, "port")
    forward(box, "led", mid, "flag")
    return box


@pytest.fixture
def renamed(monkeypatch):
    """Every ``Signal.name`` assignment after a signal's first, as ``(old, new)``."""
    renames = []

    def get(signal):
        return signal.__dict__["name"]

    def put(signal, name):
        if "name" in signal.__dict__:
            renames.append((signal.__dict__["name"], name))
        signal.__dict__["name"] = name

    monkeypatch.setattr(Signal, "name", property(get, put), raising=False)
    return renames


def test_the_rename_recorder_sees_a_rename(renamed):
    s = Signal(name="first")
    assert s.name == "first" and renamed == []
    s.name = "second"
    assert renamed == [("first", "second")]


def test_forwarding_twice_up_reaches_the_innermost_child(renamed):
    leaf = Leaf()
    top = outer(middle(leaf))
    assert leaf.inp is top.a.inp and leaf.out is top.a.out and leaf.flag is top.led
    assert top.children["middle"].port is top.a
    assert leaf.inp.data.name == "a__inp__data" and leaf.flag.name == "led"
    assert renamed == []


def test_forwarding_top_down_reaches_the_child_as_well():
    leaf = Leaf()
    mid = Box({"port": Out(PORT), "flag": Out(1)}, leaf=leaf)
    top = outer(mid)                            # the owner's member is forwarded first ...
    forward(mid, ("port", "inp"), leaf)         # ... then the owner forwards it on
    assert leaf.inp is top.a.inp and leaf.inp.data.name == "a__inp__data"


def test_a_member_inside_a_forwarded_one_reaches_the_child():
    leaf = Leaf()
    top = outer(middle(leaf))
    holder = Box({"other": Out(Pair)}, top=top)
    forward(holder, "other", top, ("a", "out"))
    assert leaf.out is holder.other and top.a.out is holder.other
    assert leaf.inp is top.a.inp


def test_the_exported_top_has_the_owners_flat_names_and_no_duplicates():
    top = outer(middle(Leaf()))
    verilog = amaranth_verilog(top, "top")
    header = re.search(r"^module top\((.*?)\);", verilog, flags=re.M | re.S).group(1)
    ports = {p.strip().lstrip("\\") for p in header.split(",")}
    assert ports == set(flat_ports(top)) | {"clk", "rst"}
    assert "a__out__data" in ports and "led" in ports
    assert re.findall(r"\\([A-Za-z_]\w*\$\d+)", verilog) == []      # no named signal with a $N suffix
    leaf_module = verilog[verilog.index("module \\top.middle.leaf"):]
    assert re.search(r"input \[7:0\] a__inp__data;", leaf_module)


def test_siblings_of_opposite_flows_get_the_object_flipped():
    source, sink = Leaf(), Leaf()
    forward(sink, "inp", source, "out")
    assert source.out.data is sink.inp.data
    assert source.out.signature == Pair and sink.inp.signature == Pair.flip()


def test_all_members_of_a_child():
    leaf = Leaf()
    owner = Box({"whole": Out(leaf.signature)}, leaf=leaf)
    forward(owner, "whole", leaf, ())
    assert leaf.inp is owner.whole.inp and leaf.flag is owner.whole.flag


@pytest.mark.parametrize("members, child_path, message", [
    ({"flag": Out(2)}, "flag", r"cannot forward Box\.flag to Leaf\.flag: .*unsigned\(2\)"),
    ({"flag": Out(1, init=1)}, "flag", r"cannot forward Box\.flag to Leaf\.flag: .*init=1"),
    ({"flag": Out(Pair)}, "flag", r"cannot forward Box\.flag to Leaf\.flag: .*PureInterface"),
    ({"out": Out(wiring.Signature({"data": Out(8)}))}, "out", r"cannot forward Box\.out to Leaf\.out: "
                                                              r"'out\.signature' is expected to be equal"),
    ({"flag": Out(1)}, "nothing", r"Leaf has no member nothing"),
    ({"flag": Out(1)}, ("inp", "nothing"), r"Leaf has no member inp\.nothing"),
])
def test_a_mismatch_is_a_type_error(members, child_path, message):
    leaf = Leaf()
    owner = Box(members, leaf=leaf)
    name = next(iter(members))
    with pytest.raises(TypeError, match=message):
        forward(owner, name, leaf, child_path)


def test_an_unknown_owner_member_is_a_type_error():
    with pytest.raises(TypeError, match=r"Box has no member absent"):
        leaf = Leaf()
        forward(Box({"flag": Out(1)}, leaf=leaf), "absent", leaf, "flag")


def test_the_system_bench_renames_no_signal_and_its_ports_are_its_own(renamed):
    design = PythonModels().design(SystemSetup.small())
    assert renamed == []
    for name, value in flat_ports(design).items():
        assert Value.cast(value).name == name
    system = design.system
    assert system.capture_path.captures["a"].pins is design.cam_a
    assert system.sequencers["dvi"].master.i2c is system.i2c.dvi
    assert system.display.compositor.video is design.video
