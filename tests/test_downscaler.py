"""Grey + Downscaler against the golden model: random images, geometries and pixel timing (hypothesis), and
the grey conversion checked for all 2^16 RGB565 inputs against the golden ``//``.

Golden side: golden.capture.downscale (keep (scale*i, scale*j)), grey5 ((R5 + (G6 >> 1) + B5) // 3) and
the address rule A = y * buf_width + x, with pixels past the configured size (reported with a saturated
column/row, as the assembler and row counter do) discarded.
"""


import numpy as np
import pytest
from amaranth import Module
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out
from amaranth.sim import Simulator
from hypothesis import given, settings
from hypothesis import strategies as st

from golden.capture import downscale, grey5
from hdl.downscaler import Downscaler
from hdl.grey import Grey
from hdl.frame_buffer import FrameBufferWriteSignature
from spec.sensor import SensorGeometry


class GreyDownscale(wiring.Component):
    """Test testbench: Grey feeding Downscaler, as CameraCapture wires them."""

    def __init__(self, geometry):
        self.geometry = geometry
        super().__init__({
            "pixel": In(16), "valid": In(1),
            "column": In(geometry.width.bit_length()), "row": In(geometry.height.bit_length()),
            "write": Out(FrameBufferWriteSignature(geometry)),
        })

    def elaborate(self, platform):
        m = Module()
        m.submodules.grey = grey = Grey()
        m.submodules.downscaler = ds = Downscaler(self.geometry)
        wiring.connect(m, wiring.flipped(self.write), ds.write)
        m.d.comb += [
            grey.pixel.eq(self.pixel), ds.grey.eq(grey.grey), ds.valid.eq(self.valid),
            ds.column.eq(self.column), ds.row.eq(self.row),
        ]
        return m


def run_downscaler(geometry, image, extra_cols, extra_rows, idle):
    """Raster ``image`` (plus extra saturated columns/rows of junk) with ``idle[k]`` idle cycles after
    pixel k; return the writes ``(addr, data)``."""
    dut = GreyDownscale(geometry)
    writes = []
    h, w = image.shape
    sequence = []
    for r in range(h + extra_rows):
        for c in range(w + extra_cols):
            value = int(image[r, c]) if r < h and c < w else (r * 131 + c * 17) & 0xFFFF
            sequence.append((value, min(c, geometry.width), min(r, geometry.height)))

    async def bench(ctx):
        for k, (value, column, row) in enumerate(sequence + [(0, 0, 0)]):
            ctx.set(dut.valid, k < len(sequence))
            ctx.set(dut.pixel, value)
            ctx.set(dut.column, column)
            ctx.set(dut.row, row)
            await ctx.tick()
            if ctx.get(dut.write.en):
                writes.append((ctx.get(dut.write.addr), ctx.get(dut.write.data)))
            ctx.set(dut.valid, 0)
            for _ in range(idle[k % len(idle)]):
                await ctx.tick()
                assert not ctx.get(dut.write.en)

    sim = Simulator(dut)
    sim.add_clock(1 / 24e6)
    sim.add_testbench(bench)
    sim.run()
    return writes


def golden_writes(geometry, image):
    kept = grey5(downscale(image, geometry))
    return [(y * geometry.buf_width + x, int(kept[y, x]))
            for y in range(geometry.buf_height) for x in range(geometry.buf_width)]


@st.composite
def cases(draw):
    scale = draw(st.sampled_from([1, 2, 4]))
    width = draw(st.integers(scale, 6 * scale + 3))
    height = draw(st.integers(scale, 4 * scale + 3))
    geometry = SensorGeometry(width=width, height=height, scale=scale)
    seed = draw(st.integers(0, 2**32 - 1))
    image = np.random.default_rng(seed).integers(0, 1 << 16, (height, width), dtype=np.uint16)
    idle = draw(st.lists(st.integers(0, 2), min_size=1, max_size=4))
    return geometry, image, draw(st.integers(0, 3)), draw(st.integers(0, 2)), idle


@settings(max_examples=30, deadline=None)
@given(cases())
def test_random_images_match_golden(case):
    geometry, image, extra_cols, extra_rows, idle = case
    writes = run_downscaler(geometry, image, extra_cols, extra_rows, idle)
    assert all(0 <= a < geometry.buf_depth for a, _ in writes)
    assert writes == golden_writes(geometry, image)


def test_non_power_of_two_scale_is_refused():
    with pytest.raises(ValueError, match="power of two"):
        Downscaler(SensorGeometry(width=30, height=30, scale=3))


def test_grey_all_rgb565_inputs():
    """The RTL grey (a multiply-by-43 reciprocal) equals the golden exact integer division for every one of
    the 65,536 RGB565 values."""
    lanes = 16                                     # 16 Grey instances side by side: 4,096 settles
    m = Module()
    greys = [Grey() for _ in range(lanes)]
    for k, g in enumerate(greys):
        m.submodules[f"grey{k}"] = g
    got = np.zeros(1 << 16, dtype=np.int64)

    async def bench(ctx):
        for base in range(0, 1 << 16, lanes):
            for k, g in enumerate(greys):
                ctx.set(g.pixel, base + k)
            for k, g in enumerate(greys):
                got[base + k] = ctx.get(g.grey)

    sim = Simulator(m)
    sim.add_testbench(bench)
    sim.run()
    expected = grey5(np.arange(1 << 16, dtype=np.uint16)).astype(np.int64)
    np.testing.assert_array_equal(got, expected)
    assert expected.max() == 31 and expected.min() == 0
