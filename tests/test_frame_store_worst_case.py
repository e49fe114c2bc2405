"""The frame store's worst case (docs/frame_store.md, "The worst case"; sim/testbench/frame_store_worst_case.py):
FrameStore on the MIG model at the largest read latency with refreshes, both cameras writing at their full rate,
two engine streams reading as fast as they are granted, four display streams each showing a 400-pixel row on every
2200-clock 1080p line, every domain at its real clock. The display is never refused and each row lands well ahead
of its first pixel; served after the engine instead of first, it is refused. The 800 x 600 build's store (slow): the
half-size panels, the difference map and the depth panel's map stream, the map writer writing, never refused."""

from dataclasses import replace

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


#: The 800 x 600 build's store (the maps in it), short: 4 rows of 800 8-bit pixels (the maps' rows 1600 bytes), one
#: display frame of a blank line, 2 lines of half-size panels, a gap line and 4 lines of the difference map and the
#: depth panel at 1:1; the map writer given its ring's 4 rows at a map's start and then a row every line (five times
#: the design's rate: the engine makes a row a pass, 11,247 pix clocks); MIG's own FIFO depths.
SHORT_800 = WorstCase(build=800, rows=4, frames=1, blank_lines=1, map_row_clocks=2200)


def test_the_800_case_reads_as_the_800_build_shows():
    """The 800 build's case: its camera streams read the half-size panels (every second row and pixel) from the
    screen's columns, then the difference map's rows at 1:1; odd rows (no half-size panel) and other builds are
    refused."""
    left, right = WorstCase(build=800).display_passes
    assert [(p.x0, p.columns, p.row_step, p.column_step) for p in left] == [(540, 400, 2, 2), (100, 800, 1, 1)]
    assert right[0].x0 == 980 and right[1].x0 == 100
    assert left[1].restart_line < left[1].first_line == WorstCase(build=800).maps_line
    with pytest.raises(ValueError, match="even number of rows"):
        WorstCase(build=800, rows=3)
    with pytest.raises(ValueError, match="build must be"):
        WorstCase(build=600)


@pytest.mark.slow
def test_the_800_builds_display_is_never_refused_with_the_maps_in_the_store():
    """The display's camera streams (the half-size panels, then the difference map) and its map stream (the depth
    panel) read every row in time while both cameras write, the engine reads as fast as it is granted and the map
    writer writes its maps."""
    r = run_worst_case(SHORT_800)
    assert r.missed == [0, 0, 0] and r.late == [0, 0, 0], r.report()
    assert all(19 < x < 21 for x in r.camera_mbps), r.report()
    assert r.maps_written >= 1 and min(r.engine_mbps) > 50, r.report()


@pytest.mark.slow
def test_the_800_builds_display_served_after_the_engine_is_refused():
    """A bite kept as a test: the same with four greedy engine streams and the display's camera streams not urgent
    (after the writers and the engine's streams): the difference map's rows come late and its reads are refused
    (the map stream stays urgent). The same load with the display urgent refuses nothing."""
    load = dict(engine_streams=4)
    r = run_worst_case(replace(SHORT_800, **load, display_urgent=False))
    assert min(r.missed[:2]) > 0, r.report()
    r = run_worst_case(replace(SHORT_800, **load))
    assert r.missed == [0, 0, 0] and r.late == [0, 0, 0], r.report()
