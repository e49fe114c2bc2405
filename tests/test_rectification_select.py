"""RectificationSelect: the manual settings pass through; the switch value 1000000 selects the estimator's offset,
sampled at the frame start, so the settings in use still change only in the clock after a frame start; 1000001
does the same and selects the segmentation view."""

import random

from hdl.rectification_select import AUTO_CODE, SEGMENT_CODE, RectificationSelect
from sim.runners.amaranth import simulate
from spec.rectification import RECTIFICATION


def test_manual_and_automatic_modes():
    dut = RectificationSelect(RECTIFICATION)
    rng = random.Random(27)
    r = RECTIFICATION.search_rows
    log = []

    async def bench(ctx):
        manual, estimate, sampled = (0, 0), 0, 0
        for clock in range(1500):
            frame_start = clock % 37 == 0
            if clock % 91 == 1:                              # the switch registers change after a frame start
                rect = rng.choice([AUTO_CODE, AUTO_CODE, SEGMENT_CODE, 0, 3, -1, -62, 63])
                manual = (rng.randrange(128), rect)
            if rng.random() < 0.2:                           # the estimate changes at any time
                estimate = rng.randrange(-r, r + 1)
            ctx.set(dut.manual.disparity, manual[0])
            ctx.set(dut.manual.rectification, manual[1])
            ctx.set(dut.estimate, estimate)
            ctx.set(dut.frame_start, frame_start)
            auto = manual[1] in (AUTO_CODE, SEGMENT_CODE)
            expected = (manual[0], sampled if auto else manual[1])
            assert (ctx.get(dut.settings.disparity), ctx.get(dut.settings.rectification)) == expected, clock
            assert ctx.get(dut.auto) == auto
            assert ctx.get(dut.segment) == (manual[1] == SEGMENT_CODE)
            log.append((clock, auto, expected, manual[1] == SEGMENT_CODE))
            await ctx.tick()
            if frame_start:
                sampled = estimate

    simulate(dut, clocks={"sync": 100e6}, testbenches=[bench])
    assert {a for _, a, _, _ in log} == {True, False} and {s for *_, s in log} == {True, False}
    assert len({e[1] for _, a, e, _ in log if a}) > 3       # several estimates were taken up in auto mode
