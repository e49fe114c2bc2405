"""cocotb test of the depth engine in its testbench (sim/testbench/depth.py; driven by tests/test_depth_engine.py).

The pair is written into the two frame buffers through the testbench's load port, one word of each per clock,
and the row-tag tables (if the ``.npz`` has ``left_tags`` / ``right_tags``: tag | busy << 4 per buffer row, and
``flips``: the rows whose tag flips at the engine's first ask; else all 0, no flip) through the tag load port;
then one ``start`` pulse, and the test waits (as a simulator trigger, no Python per clock) until the testbench has
copied every row of the map out of the engine's result ring. The whole map is read back and compared, bit for
bit, with the golden model's (``golden.depth.depth_map``, computed in the pytest process and handed over in an
``.npz`` file). The clocks from ``start`` to the last row are written to ``result.json`` beside the log.
"""

import json
from pathlib import Path

import numpy as np

try:
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, First, RisingEdge, Timer
except ImportError:          # imported outside a cocotb run
    cocotb = None


if cocotb is not None:
    @cocotb.test()
    async def depth_map_matches_golden(dut):
        """Load the pair, compute one map, read it back, compare with the golden map."""
        from sim.runners.cocotb import test_params

        p = test_params()
        data = np.load(p["data"])
        left, right, expected = data["left"].ravel(), data["right"].ravel(), data["expected"]
        h, w = expected.shape
        Clock(dut.clk, p["clock_ps"], unit="ps").start()
        clk = dut.clk
        dut.rst.value = 1
        dut.load_en.value = 0
        dut.start.value = 0
        dut.grant_mask.value = p["grant_mask"]
        dut.hold.value = 0
        dut.row_offset.value = 0                  # the rectification offset (tests/test_depth_engine.py: Amaranth)
        dut.read_addr.value = 0
        dut.tag_load_en.value = 0
        dut.tag_load_row.value = 0
        dut.tag_load_left.value = 0
        dut.tag_load_right.value = 0
        flips = data["flips"] if "flips" in data else (h, h)
        dut.flip_left.value = int(flips[0])
        dut.flip_right.value = int(flips[1])
        for _ in range(3):
            await FallingEdge(clk)
        dut.rst.value = 0
        if "left_tags" in data:
            dut.tag_load_en.value = 1
            for r in range(h):
                dut.tag_load_row.value = r
                dut.tag_load_left.value = int(data["left_tags"][r])
                dut.tag_load_right.value = int(data["right_tags"][r])
                await FallingEdge(clk)
            dut.tag_load_en.value = 0
        dut.load_en.value = 1
        for a in range(h * w):
            dut.load_addr.value = a
            dut.load_left.value = int(left[a])
            dut.load_right.value = int(right[a])
            await FallingEdge(clk)
        dut.load_en.value = 0
        dut.start.value = 1
        await FallingEdge(clk)
        dut.start.value = 0
        timeout = Timer(p["timeout_clocks"] * p["clock_ps"], unit="ps")
        if not int(dut.done.value):
            fired = await First(RisingEdge(dut.done), timeout)
            assert fired is not timeout, f"no map within {p['timeout_clocks']} clocks"
        await FallingEdge(clk)
        clocks = int(dut.clocks.value)
        got = np.zeros(h * w, dtype=np.int64)
        for a in range(h * w):
            dut.read_addr.value = a
            await FallingEdge(clk)      # the rising edge between reads word a
            got[a] = int(dut.read_data.value)
        got = got.reshape(h, w)
        Path(p["result"]).write_text(json.dumps({"clocks": clocks, "mismatches": int((got != expected).sum())}))
        bad = np.argwhere(got != expected)
        assert bad.size == 0, (f"{len(bad)} pixels differ from the golden map; first (y, x) = {bad[:5].tolist()}, "
                               f"RTL {[int(got[tuple(b)]) for b in bad[:5]]}, golden "
                               f"{[int(expected[tuple(b)]) for b in bad[:5]]}")
