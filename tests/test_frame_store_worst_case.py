"""The frame store's worst case (docs/frame_store.md, "The worst case"; sim/testbench/frame_store_worst_case.py):
FrameStore on the MIG model at the largest read latency with refreshes, both cameras writing at their full rate,
two engine streams reading as fast as they are granted, four display streams each showing a 400-pixel row on every
2200-clock 1080p line, every domain at its real clock. The display is never refused and each row lands well ahead
of its first pixel; served after the engine instead of first, it is refused."""

import pytest

from sim.testbench.frame_store_worst_case import WorstCase, run_worst_case

#: Short: 3 buffer rows (the full 400-pixel width) shown on a 4-line display frame, one frame measured.
SHORT = WorstCase(rows=3, frames=1, blank_lines=1, mig_fifo_depth=64)


def test_the_display_is_never_refused_in_the_worst_case():
    r = run_worst_case(SHORT)
    assert r.missed == [0, 0, 0, 0], r.report()
    assert r.late == [0, 0, 0, 0], r.report()
    # every row landed at least half a line before its first pixel (it was asked for one line before it)
    assert r.least_slack > r.line_clocks // 2, r.report()
    assert r.refreshes >= 2, r.report()
    # the cameras' writes all reached MIG at their rate (13 bursts every 40 us row each: 10.4 MB/s)
    assert all(9.5 < x < 11 for x in r.camera_mbps), r.report()
    # the engine's streams take what the display and the cameras leave: the bus is busy, its efficiency that of
    # buffers spread over the banks (60 %; all in bank 0: 30 %)
    assert r.efficiency > 0.55 and min(r.engine_mbps) > 100, r.report()


@pytest.mark.slow
def test_a_display_served_after_the_engine_is_refused():
    """A bite kept as a test: four greedy engine streams (twice the design's; a stream's ring takes a word every
    4 pix clocks, so two leave the interface room to spare) with the display's streams not urgent (after the
    writers and, listed later, after the engine's): their rows come late and the display is refused. The same
    load with the display urgent, as designed, refuses nothing."""
    load = dict(rows=3, frames=1, blank_lines=1, mig_fifo_depth=64, engine_streams=4)
    r = run_worst_case(WorstCase(**load, display_urgent=False))
    assert max(r.missed) > 0 and max(r.late) > 0, r.report()
    r = run_worst_case(WorstCase(**load))
    assert r.missed == [0] * 4 and r.late == [0] * 4, r.report()


@pytest.mark.slow
def test_a_read_latency_of_a_line_makes_the_display_refused():
    """A bite kept as a test: a read latency of 2000 clk0 (16 us, beyond a line's 14.8 us; the model's range
    widened for it): the rows land after their first pixel, the display is refused."""
    r = run_worst_case(WorstCase(rows=3, frames=1, blank_lines=1, mig_fifo_depth=64, latency=2000,
                                 latency_range=(16, 2000)))
    assert min(r.missed) > 0 and min(r.late) > 0, r.report()
