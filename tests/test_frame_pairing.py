# amaranth: UnusedElaboratable=no
"""FramePairing (hdl/frame_pairing.py) in Amaranth's simulator against the golden rule (golden/frame_pairing.py),
and the golden rule against the cases docs/capture.md ("Frame pairs") states."""

import pytest
from amaranth.sim import Simulator
from hypothesis import given, settings
from hypothesis import strategies as st

from golden.frame_pairing import pair_tags
from hdl.frame_pairing import FramePairing


def run_rtl(clocks, bits=2):
    """The tags the block gives, per clock, to the cameras that start in it (as :func:`pair_tags` returns them),
    and its ``pair`` after the last clock."""
    dut = FramePairing(bits)
    got = []
    sim = Simulator(dut)
    sim.add_clock(1e-8)

    async def bench(ctx):
        for starts in clocks:
            ctx.set(dut.a.started, "a" in starts)
            ctx.set(dut.b.started, "b" in starts)
            given = {c: ctx.get(getattr(dut, c).tag) for c in "ab" if c in starts}
            got.append(given)
            await ctx.tick()
        ctx.set(dut.a.started, 0)
        ctx.set(dut.b.started, 0)
        got.append(ctx.get(dut.pair))
    sim.add_testbench(bench)
    sim.run()
    return got[:-1], got[-1]


def _last_tags(clocks, bits=4):
    """Each camera's tag after ``clocks`` (the tag of its latest frame; 0 before any)."""
    last = {"a": 0, "b": 0}
    for given in pair_tags(clocks, bits):
        last.update(given)
    return last


@settings(max_examples=25, deadline=None)
@given(st.lists(st.sampled_from(["", "", "a", "b", "ab"]), min_size=1, max_size=40), st.sampled_from([1, 2, 3]))
def test_rtl_equals_golden(clocks, bits):
    got, pair = run_rtl(clocks, bits)
    want = pair_tags(clocks, bits)
    assert got == want
    given = [g.get("b", g.get("a")) for g in want if g]
    assert pair == (given[-1] if given else 0)          # the open pair's tag is the last one given


@pytest.mark.parametrize("clocks", [
    ["a", "", "b"] * 3,                   # A leads B by two clocks
    ["b", "a"] * 3,                       # B leads
    ["a", "b", "b", "a", "ab", "a", "", "b"],   # the order changes from frame to frame, and once both at once
])
def test_synchronised_cameras_share_each_frame_tag(clocks):
    tags = pair_tags(clocks)
    per_camera = {c: [g[c] for g in tags if c in g] for c in "ab"}
    assert per_camera["a"] == per_camera["b"] == list(range(1, len(per_camera["a"]) + 1))
    assert run_rtl(clocks, 4)[0] == tags


def test_a_dropped_frame_differs_until_the_next_one():
    """B drops its second frame: after A's third start the tags differ (B's buffer still holds pair 1), B's next
    start joins A's pair 3 and they agree again; a camera that stops stays behind."""
    clocks = ["a", "b", "a", "", "a"]
    assert _last_tags(clocks[:2]) == {"a": 1, "b": 1}
    assert _last_tags(clocks) == {"a": 3, "b": 1}
    assert _last_tags(clocks + ["b"]) == {"a": 3, "b": 3}
    assert _last_tags(["a", "b"] + ["a"] * 5) == {"a": 6, "b": 1}
    assert run_rtl(clocks + ["b"], 4)[0] == pair_tags(clocks + ["b"])


def test_tags_wrap_and_bad_arguments_are_rejected():
    assert [g["a"] for g in pair_tags(["a"] * 5, bits=2)] == [1, 2, 3, 0, 1]
    with pytest.raises(ValueError, match="bits"):
        FramePairing(0)
    with pytest.raises(ValueError, match="bits"):
        pair_tags(["a"], bits=0)
    with pytest.raises(ValueError, match="cameras are"):
        pair_tags(["c"])
