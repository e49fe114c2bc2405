"""cocotb test of the vertical-offset estimator (hdl/vertical_offset.py; driven by tests/test_vertical_offset.py).

Each frame's two images are written into the block's watch ports one pixel of each per clock in raster order,
then the right camera's ``frame_done``, two clocks later the left one's; the test waits for ``done`` (a simulator trigger) and reads the outputs. They are compared,
frame by frame, with the golden model's (``golden.vertical_offset``, computed in the pytest process and handed
over in an ``.npz`` file); the mismatches and the clocks from the later ``frame_done`` to ``done`` go to
``result.json``.
"""

import json
import math
from pathlib import Path

import numpy as np

try:
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, First, RisingEdge, Timer
except ImportError:          # imported outside a cocotb run
    cocotb = None

#: The outputs compared, in the column order of the expected array.
OUTPUTS = ("offset", "confident", "held", "locked", "best", "cost_best", "cost_second", "texture")
SIGNED = ("offset", "best")


if cocotb is not None:
    @cocotb.test()
    async def estimator_matches_golden(dut):
        from sim.runners.cocotb import test_params

        p = test_params()
        data = np.load(p["data"])
        frames, expected = data["frames"], data["expected"]
        _, _, h, w = frames.shape
        clk = dut.clk
        Clock(clk, p["clock_ps"], unit="ps").start()
        dut.rst.value = 1
        for side in ("left", "right"):
            getattr(dut, f"{side}__en").value = 0
            getattr(dut, f"{side}__frame_done").value = 0
        for _ in range(3):
            await FallingEdge(clk)
        dut.rst.value = 0
        got, clocks = [], []
        for left, right in frames:
            for a in range(h * w):
                for side, image in (("left", left), ("right", right)):
                    getattr(dut, f"{side}__en").value = 1
                    getattr(dut, f"{side}__addr").value = a
                    getattr(dut, f"{side}__data").value = int(image[a // w, a % w])
                await FallingEdge(clk)
            for side in ("left", "right"):
                getattr(dut, f"{side}__en").value = 0
            dut.right__frame_done.value = 1
            await FallingEdge(clk)
            dut.right__frame_done.value = 0
            await FallingEdge(clk)
            await FallingEdge(clk)
            dut.left__frame_done.value = 1
            await FallingEdge(clk)
            dut.left__frame_done.value = 0
            start = cocotb.utils.get_sim_time("ps")
            timeout = Timer(p["timeout_clocks"] * p["clock_ps"], unit="ps")
            fired = await First(RisingEdge(dut.done), timeout)
            assert fired is not timeout, f"no result within {p['timeout_clocks']} clocks"
            # done rises on a rising edge, half a clock after a falling edge: ceil, since round() rounds a
            # half to even and so miscounted every other search length by one.
            clocks.append(math.ceil((cocotb.utils.get_sim_time("ps") - start) / p["clock_ps"]) + 1)
            await FallingEdge(clk)
            got.append([getattr(dut, n).value.to_signed() if n in SIGNED else int(getattr(dut, n).value)
                        for n in OUTPUTS])
        got = np.array(got)
        bad = np.argwhere(got != expected)
        Path(p["result"]).write_text(json.dumps({"mismatches": int(len(bad)), "clocks": clocks}))
        assert bad.size == 0, (f"{len(bad)} outputs differ; first (frame, output) {bad[:4].tolist()}: RTL "
                               f"{got[tuple(bad[0])]}, golden {expected[tuple(bad[0])]}")
