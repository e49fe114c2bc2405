"""RowTagTracker (hdl/row_tags.py) in Amaranth's simulator, against a model of its rules written from the docstring
(tags, busy row, row index saturating at the buffer height), for well-formed and malformed strobe sequences; and
behind a real capture driven by the sensor model: every write of a row is covered by that row's ``busy`` and new
tag within the stated latency."""

import pytest
from amaranth import ClockDomain, DomainRenamer, Elaboratable, Module
from amaranth.sim import Simulator
from hypothesis import given, settings
from hypothesis import strategies as st

from amaranth.lib import wiring

from hdl.frame_pairing import FramePairing
from hdl.row_tags import ROW_TAG_LATENCY, RowTagTracker
from spec.board import CLOCKS
from spec.sensor import SensorGeometry

GEOMETRY = SensorGeometry(width=16, height=20)         # 5 buffer rows: not a power of two
CAM_PERIOD = 1 / CLOCKS.CAM_PCLK_HZ
PIX_PERIOD = 1 / CLOCKS.PIXEL_HZ


class Model:
    """The tracker's rules: frame starts count tags, a row start writes the frame's tag at the row index (row
    starts since the frame start, none beyond the last row) and makes it the row in progress until its end or
    the next frame start."""

    def __init__(self, height, bits):
        self.height, self.mod = height, 1 << bits
        self.frame, self.index, self.busy, self.tags = 0, 0, None, [0] * height

    def event(self, kind):
        if kind == "frame_start":
            self.frame, self.index, self.busy = (self.frame + 1) % self.mod, 0, None
        elif kind == "row_start":
            if self.index < self.height:
                self.tags[self.index], self.busy = self.frame, self.index
                self.index += 1
        else:
            self.busy = None

    def answers(self):
        return [(self.tags[r], int(self.busy == r)) for r in range(self.height)]


def _pair_alone(m, tracker):
    """The tracker as camera A of a pairing whose camera B never starts: every frame start opens a pair, so the
    tags count the frame starts."""
    m.submodules.pairing = pairing = DomainRenamer("pix")(FramePairing(tracker.bits))
    wiring.connect(m, tracker.pair, pairing.a)


class _Bench(Elaboratable):
    def __init__(self, tracker):
        self.tracker = tracker

    def elaborate(self, platform):
        m = Module()
        m.domains += [ClockDomain("cam_a"), ClockDomain("pix")]
        m.submodules.tracker = self.tracker
        _pair_alone(m, self.tracker)
        return m


async def _answers(ctx, tracker, height):
    out = []
    for r in range(height):
        ctx.set(tracker.read.row, r)
        await ctx.tick("pix")
        out.append((ctx.get(tracker.read.tag), ctx.get(tracker.read.busy)))
    return out


def run_events(groups, geometry=GEOMETRY, bits=2, tracker=None):
    """Send each group of strobes (a tuple of kinds, in one camera clock), well apart; after each group read every
    row's answer. Returns the answers and the model's."""
    tracker = tracker or RowTagTracker(geometry, bits=bits)
    height = geometry.buf_height
    model = Model(height, bits)
    got, want = [], []
    sim = Simulator(_Bench(tracker))
    sim.add_clock(CAM_PERIOD, domain="cam_a")
    sim.add_clock(PIX_PERIOD, domain="pix")

    async def bench(ctx):
        for group in groups:
            for order in ("row_end", "frame_start", "row_start"):      # a well-formed stream's order
                if order in group:
                    ctx.set(getattr(tracker, order), 1)
                    model.event(order)
            await ctx.tick("cam_a")
            for kind in ("row_end", "frame_start", "row_start"):
                ctx.set(getattr(tracker, kind), 0)
            await ctx.tick("cam_a").repeat(2)
            await ctx.tick("pix").repeat(ROW_TAG_LATENCY)
            got.append(await _answers(ctx, tracker, height))
            want.append(model.answers())
    sim.add_testbench(bench)
    sim.run()
    return got, want


def _frame(rows, *, end_last=True):
    events = [("frame_start",)]
    for r in range(rows):
        events += [("row_start",), ("row_end",)]
    return events if end_last else events[:-1]


def test_frames_of_rows():
    got, want = run_events(_frame(5) + _frame(5) + _frame(3))
    assert got == want
    assert got[-1] == [(3, 0), (3, 0), (3, 0), (2, 0), (2, 0)]     # frame 3 wrote rows 0..2, frame 2 the rest


def test_malformed_sequences_keep_the_index_in_range():
    """More row starts than rows (the sixth to ninth change nothing), a row end missing, a frame cut mid-row
    (the next frame start ends the row in progress), a row end without a start, strobes in one clock."""
    groups = (_frame(9) + [("frame_start",), ("row_start",), ("row_start",), ("row_end",)]
              + [("frame_start",), ("row_start",), ("frame_start",), ("row_end",), ("row_start",)]
              + [("row_end", "frame_start", "row_start"), ("row_end",), ("frame_start", "row_start")])
    got, want = run_events(groups)
    assert got == want
    assert got[18] == [(1, 0)] * 5                   # after 9 row starts and ends: frame 1 everywhere, none busy


@settings(max_examples=8, deadline=None)
@given(st.lists(st.sampled_from(["frame_start", "row_start", "row_end"]), min_size=1, max_size=30))
def test_random_strobe_sequences(kinds):
    got, want = run_events([(k,) for k in kinds])
    assert got == want


# --- Behind a capture -------------------------------------------------------------------------------------

class _CaptureBench(Elaboratable):
    def __init__(self, path, tracker):
        self.path, self.tracker = path, tracker
        self.cam = ClockDomain("cam_a")

    def elaborate(self, platform):
        m = Module()
        m.domains += [self.cam, ClockDomain("pix")]
        m.submodules.path, m.submodules.tracker = self.path, self.tracker
        _pair_alone(m, self.tracker)
        status = self.path.cam_a.status
        m.d.comb += [self.tracker.frame_start.eq(status.frame_start), self.tracker.row_start.eq(status.row_start),
                     self.tracker.row_end.eq(status.row_end)]
        return m


def capture_and_track(faults):
    """Camera a of a small CapturePath with a tracker, two frames (the first with ``faults``) from the sensor model at
    80 MHz PCLK, pix at 148.5 MHz; the pix side asks every clock for the row of the latest write. Returns the writes
    ``(pix edges done, buffer row, frame starts seen)`` and the answers ``(pix edge, row, tag, busy)``."""
    from golden.stereo_pair import load_default_pair
    from hdl.capture_path import CapturePath
    from sim.models.mt9d112.config import SensorConfig
    from sim.models.mt9d112.sensor import MT9D112, SensorTiming, drive_amaranth
    g = GEOMETRY_CAPTURE
    path, tracker = CapturePath(g, cameras=("a",)), RowTagTracker(g, bits=2)
    images = load_default_pair(g.width, g.height)
    stream = MT9D112(SensorConfig(width=g.width, height=g.height),
                     timing=SensorTiming(h_blank=6, v_blank_lines=1, frame_start=2, frame_end=3),
                     seed=5).stream(list(images), faults=[faults, None])
    bench = _CaptureBench(path, tracker)
    writes, answers, state = [], [], {"row": 0, "done": False, "edges": 0, "frames": 0}
    sim = Simulator(bench)
    sim.add_clock(PIX_PERIOD, domain="pix")
    port = path.cam_a

    async def camera(ctx):
        def on_sample(ctx):
            state["frames"] += ctx.get(port.status.frame_start)
            if ctx.get(port.write.en):           # committed at the rising edge half a period on
                state["row"] = ctx.get(port.write.addr) // g.buf_width
                writes.append((state["edges"], state["row"], state["frames"]))
        await drive_amaranth(ctx, stream, clk=bench.cam.clk, pins=port.pins, pclk_hz=CLOCKS.CAM_PCLK_HZ,
                             on_sample=on_sample)
        await ctx.delay(20 * PIX_PERIOD)
        state["done"] = True

    async def pix(ctx):
        row = 0
        while not state["done"]:
            ctx.set(tracker.read.row, row)
            await ctx.tick("pix")
            state["edges"] += 1
            answers.append((state["edges"], row, ctx.get(tracker.read.tag), ctx.get(tracker.read.busy)))
            row = state["row"]
    sim.add_testbench(camera)
    sim.add_testbench(pix)
    sim.run()
    return writes, answers


GEOMETRY_CAPTURE = SensorGeometry(width=32, height=16)


@pytest.mark.parametrize("faults", ["none", "fv_drop"])
def test_busy_and_tag_cover_every_write(faults):
    """Every write of a row is answered, for that row, busy and with its frame's tag in the pix clocks from
    ROW_TAG_LATENCY to ROW_TAG_LATENCY + 2 after it; after the stream no row is busy."""
    from sim.models.mt9d112.sensor import Faults
    fault = None if faults == "none" else Faults(fv_drop=(9, 20))
    writes, answers = capture_and_track(fault)
    by_edge = {edge: (row, tag, busy) for edge, row, tag, busy in answers}
    checked = 0
    for edge, row, frame in writes:
        for m in range(edge + ROW_TAG_LATENCY, edge + ROW_TAG_LATENCY + 3):
            if m in by_edge and by_edge[m][0] == row:
                assert by_edge[m][1:] == (frame % 4, 1), (edge, row, frame, m, by_edge[m])
                checked += 1
    assert checked >= len(writes)
    assert answers[-1][3] == 0 and answers[-1][2] == 2
