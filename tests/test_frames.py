"""Multi-frame whole-system runs at the small size: a moving card, frame after frame, through
``sim.system.simulate`` on every backend (Verilator's C++ testbench, Amaranth's simulator, cocotb); the per-row frame
sources the run's verdict gives, the settled frame against the golden model of the last pair, the frame-start skew
the design measures against the simulation's; the command line's input errors.
"""

import numpy as np
import pytest

from sim.analysis.frame_sources import (EMPTY, frame_sources, source_summary, tear_candidates, torn_depth_rows,
                                        torn_summary)
from sim.system import Amaranth, Cocotb, Verilator, simulate
from sim.testbed.sequence import card_distances, moving_card
from sim.testbench.system.setup import SystemSetup

FRAMES = 3


def _simulate(setup, sequence, backend=None):
    """``simulate`` on ``backend`` (default Verilator); checks that ``on_frame`` saw every display frame, judged,
    in order. Returns the result."""
    shown = []
    result = simulate(setup, sequence, backend or Verilator(), on_frame=shown.append)
    assert shown == result.frames and all(s.verdict is not None for s in shown)
    return result


def _run_verilator(setup, frames=FRAMES):
    sequence = moving_card(setup, frames)
    result = _simulate(setup, sequence)
    return sequence, result.frames, result.status


def _frames_of(key):
    """The camera frames a ``*_rows_by_frame`` key names: ``"k"``, ``"j..k"`` or ``"k|k'"``."""
    return [int(k) for k in key.replace("..", "|").split("|")]


def _goldens(setup, sequence):
    black = np.zeros_like(sequence.pairs[0][0])
    return {EMPTY: setup.golden_frame(black, black),
            **{k: setup.golden_frame(*pair) for k, pair in enumerate(sequence.pairs)}}


def _summaries(setup, sequence, shown):
    goldens = _goldens(setup, sequence)
    return [source_summary(frame_sources(s.frame, goldens, setup.display_layout, setup.geometry)) for s in shown]


@pytest.fixture(scope="module")
def card_run():
    setup = SystemSetup.small()
    return (setup, *_run_verilator(setup))


def test_moving_card_frames_on_verilator(card_run):
    setup, sequence, shown, status = card_run
    assert status["violations"] == []
    assert [s.index for s in shown] == list(range(len(shown)))
    assert len(shown) == status["settled_frame"] + 1 >= FRAMES
    summaries = [s.verdict for s in shown]
    # the settled frame (no capture writes any more) is the golden frame of the last pair, bit for bit
    assert summaries[-1]["equals_pair"] == FRAMES - 1
    assert np.array_equal(shown[-1].golden, setup.golden_frame(*sequence.pairs[-1]))
    # every pair reached the screen: each camera frame is the source of some depth rows of some display frame
    sources = {k for s in summaries for key in s["depth_rows_by_frame"] for k in _frames_of(key)}
    assert set(range(FRAMES)) <= sources
    for s in summaries:     # an image row is at most torn where the capture writes it while it is shown
        assert s["left_rows_mixed"] <= 1 and s["right_rows_mixed"] <= 1
    # the captures counted every frame, and the display frames came in order of time
    assert all(len(status["capture_events_s"][c]["frame_done"]) == FRAMES for c in "ab")
    assert all(b.t_start_s > a.t_start_s for a, b in zip(shown, shown[1:]))


def _buffers(setup, sequence):
    from golden.capture import capture_frame
    g = setup.geometry
    zeros = np.zeros((g.buf_height, g.buf_width), np.uint8)
    return {EMPTY: (zeros, zeros), **{k: (capture_frame(setup.fit(left), g), capture_frame(setup.fit(right), g))
                                      for k, (left, right) in enumerate(sequence.pairs)}}


def _torn(setup, sequence, shown):
    """Per display frame with a mixed depth row (against the untorn goldens), its rows against the torn golden."""
    goldens, buffers = _goldens(setup, sequence), _buffers(setup, sequence)
    out = []
    for s in shown:
        if source_summary(frame_sources(s.frame, goldens, setup.display_layout, setup.geometry))["depth_rows_mixed"]:
            out.append(torn_summary(torn_depth_rows(s.frame, buffers, setup.display_layout, setup.geometry,
                                                    setup.depth, rectification=setup.rectification)))
    return out


def test_torn_maps_have_no_mixed_rows(card_run):
    """The display frames whose depth map was computed across the tear (rows of two camera frames) equal the
    golden torn map (docs/depth.md "Rows from different camera frames") in every row: each depth row from one
    camera frame or invalid at the tear, none mixed (with the tracker's tags tied to 0 in the system, the rows
    below the tear are mixed again)."""
    setup, sequence, shown, _ = card_run
    torn = _torn(setup, sequence, shown)
    assert torn, "the run has no display frame computed across a tear"
    for t in torn:
        assert t["tear"] is not None and t["depth_rows_mixed_at_tear"] == 0, t
        assert 0 < t["depth_rows_invalid_at_tear"] <= setup.depth.census_height


def test_torn_rows_classified_from_the_definition():
    """A depth panel drawn from a torn map (rows 0..4 of frame 1, row 5 torn, 6.. of frame 0) is found as that
    tear; its rows come from frame 1 above, frame 0 below, the rule's invalid rows at the tear; a row changed in
    the panel is mixed."""
    from golden.depth import depth_map
    from golden.depth_display import draw_depth_display
    from golden.disparity import rgb24_to_bytes
    setup = SystemSetup.small()
    g, layout = setup.geometry, setup.display_layout
    rng = np.random.default_rng(4)
    base = [rng.integers(0, 32, (g.buf_height, g.buf_width + 8), dtype=np.uint8) for _ in range(2)]
    buffers = {k: (b[:, 4:4 + g.buf_width], b[:, 4 - 2 * k:4 - 2 * k + g.buf_width]) for k, b in enumerate(base)}
    c = 5
    left = np.concatenate([buffers[1][0][:c], buffers[0][0][c:]])
    right = np.concatenate([buffers[1][1][:c], buffers[0][1][c:]])
    tags = [1] * c + [None] + [0] * (g.buf_height - c - 1)
    codes = depth_map(left, right, setup.depth, row_tags=(tags, tags))
    frame = np.zeros((setup.timing.v_active, setup.timing.h_active), np.int64)
    draw_depth_display(frame, codes, layout, g, setup.depth)
    frame = rgb24_to_bytes(frame)
    found = torn_depth_rows(frame, buffers, layout, g, setup.depth)
    assert found["tear"] == (c, 1, 0, True)
    h = setup.depth.census_height // 2
    invalid = range(c - h, c + h + 1)           # docs/depth.md: a torn row c makes rows c - h .. c + h invalid
    assert found["rows"] == [("invalid" if y in invalid else 1 if y < c else 0) for y in range(g.buf_height)]
    quick = torn_depth_rows(frame, buffers, layout, g, setup.depth,
                            candidates=tear_candidates(list(invalid), g.buf_height, setup.depth))
    assert quick == found                       # the tear the withheld rows point to, without the search
    region = layout.region("depth")
    frame[region.y1 - 1, region.x0] ^= 0xFF                   # one pixel of the last depth row changed
    assert torn_depth_rows(frame, buffers, layout, g, setup.depth)["rows"][-1] is None


def test_half_size_panel_rows_classified_as_shown():
    """A camera panel at half size (the small 800 x 600 build's screen) shows every second buffer row, one line
    each: its rows are those 12 lines of the 32 x 24 buffers (not 24 lines reaching into the maps below), and a
    line of another pair's image is classified as that pair's."""
    setup = SystemSetup.small_800()
    g, layout = setup.geometry, setup.display_layout
    rng = np.random.default_rng(8)
    pairs = [tuple(rng.integers(0, 256, (g.height, g.width, 3), dtype=np.uint8) for _ in range(2)) for _ in range(2)]
    goldens = {k: setup.golden_frame(*pair) for k, pair in enumerate(pairs)}
    frame = goldens[0].copy()
    left = layout.region("left")
    frame[left.y0:left.y0 + 3] = goldens[1][left.y0:left.y0 + 3]
    rows = frame_sources(frame, goldens, layout, g)["left"]
    assert rows == [{1}] * 3 + [{0}] * (g.buf_height // 2 - 3)


def test_a_map_overtaken_twice_is_classified_from_the_definition():
    """Rows 0..7 of frame 0, 8..15 of frame 1, 16.. of frame 0 again in both images (the engine reads its first rows
    at the display frame's start and the rest after the captures moved on): no single tear explains the panel,
    the rows the withheld runs point to do; every other row comes from its frame, none is mixed."""
    from golden.depth import depth_map
    from golden.depth_display import draw_depth_display
    from golden.disparity import rgb24_to_bytes
    import dataclasses
    setup = SystemSetup.small()
    layout, g = setup.display_layout, setup.geometry
    depth = dataclasses.replace(setup.depth, census_height=3)     # h = 1: two bands and rows between in 12 rows
    rng = np.random.default_rng(9)
    base = [rng.integers(0, 32, (g.buf_height, g.buf_width + 8), dtype=np.uint8) for _ in range(2)]
    buffers = {k: (b[:, 4:4 + g.buf_width], b[:, 4 - 2 * k:4 - 2 * k + g.buf_width]) for k, b in enumerate(base)}
    h = depth.census_height // 2
    changes = (3, 8)
    row_frames = [(0, 1)[sum(1 for c in changes if c <= r) % 2] for r in range(g.buf_height)]
    left = np.stack([buffers[row_frames[r]][0][r] for r in range(g.buf_height)])
    right = np.stack([buffers[row_frames[r]][1][r] for r in range(g.buf_height)])
    codes = depth_map(left, right, depth, row_tags=(row_frames, row_frames))
    frame = np.zeros((setup.timing.v_active, setup.timing.h_active), np.int64)
    draw_depth_display(frame, codes, layout, g, depth)
    frame = rgb24_to_bytes(frame)
    found = torn_depth_rows(frame, buffers, layout, g, depth)
    assert found["tear"] == ("rows", tuple((c, False) for c in changes), 0, 1)
    invalid = set(range(changes[0] - h, changes[0] + h)) | set(range(changes[1] - h, changes[1] + h))
    assert found["rows"] == [("invalid" if y in invalid else row_frames[y]) for y in range(g.buf_height)]
    assert torn_summary(found)["depth_rows_mixed_at_tear"] == 0


def test_tear_candidates_follow_the_rule():
    """docs/depth.md with h = 3: a tag change at c withholds c - 3 .. c + 2, a torn row c withholds c - 3 .. c + 3,
    tears at c < c' in the two images c - 3 .. c' + 2; each run of withheld rows points back to its tear."""
    from spec.depth import DepthConfig
    depth = DepthConfig(disparities=8, lanes=4, census_height=7)
    assert 6 in tear_candidates(range(3, 9), 40, depth)                 # a tag change at 6
    assert 6 in tear_candidates(range(3, 10), 40, depth)                # row 6 torn
    assert (6, 11) in tear_candidates(range(3, 14), 40, depth)          # left at 6, right at 11
    assert (11, 6) in tear_candidates(range(3, 14), 40, depth)
    assert 2 in tear_candidates(range(0, 5), 40, depth)                 # clamped at the top: c = b1 - h + 1
    both = tear_candidates(list(range(3, 9)) + list(range(20, 26)), 40, depth)
    assert 6 in both and 23 in both
    assert tear_candidates([], 40, depth) == []


def test_the_design_measures_the_skew_the_simulation_shows(card_run):
    setup, _, _, status = card_run
    events, hardware = status["capture_events_s"], status["hardware_skew"]
    assert len(hardware) == FRAMES
    for k, measured in enumerate(hardware):
        simulated = (events["b"]["frame_start"][k] - events["a"]["frame_start"][k]) * setup.sys_hz
        assert abs(measured["skew_sync_clocks"] - simulated) <= 3 and measured["aligned"]
    assert not status["leds"] >> 7          # LD7: the heartbeat (off after 3 frames), not the misalignment


def test_start_delay_and_clock_offset_are_measured():
    """Camera B 12 us late (about 7 sensor lines) with a PCLK 2000 ppm fast: the meter sees the delay, not
    aligned, shrinking by 2000 ppm of a frame period every frame."""
    setup = SystemSetup.small(cam_phase_s={"a": 0.0, "b": 12e-6}, cam_clock_ppm={"b": 2000.0})
    _, _, status = _run_verilator(setup, frames=2)
    events, hardware = status["capture_events_s"], status["hardware_skew"]
    skews = [m["skew_sync_clocks"] for m in hardware]
    assert len(skews) == 2 and not any(m["aligned"] for m in hardware)
    assert abs(skews[0] - 1200) < 60                              # 12 us, less the drift up to the first start
    period_clocks = (events["a"]["frame_start"][1] - events["a"]["frame_start"][0]) * setup.sys_hz
    assert abs((skews[0] - skews[1]) - 2000e-6 * period_clocks) <= 4
    assert status["leds"] >> 7 == 1          # LD7 steady on: the frame starts are more than a line apart


def test_the_barrier_keeps_the_cameras_in_step_after_a_retry():
    """Camera B's sensor NACKs one write of its table: its sequencer waits the retry delay (20 us in the small
    preset, 11 sensor lines) and repeats it; the barrier before the start of streaming brings the two tables
    back in step, so the frame starts stay within a line (without it, B would start a retry delay late)."""
    setup = SystemSetup.small(i2c_faults={"cam_b": {"nack_write_byte": 2, "nack_times": 1}})
    _, _, status = _run_verilator(setup, frames=2)
    hardware = status["hardware_skew"]
    assert len(hardware) == 2 and all(m["aligned"] for m in hardware), hardware
    assert all(abs(m["skew_sync_clocks"]) <= 3 for m in hardware)


def test_faults_mid_stream_recover_within_a_frame():
    """Frame to frame faults in one run of five camera frames: camera A's frame 1 is cut short (FV falls mid-frame),
    camera B drops frame 2 (FV low for a frame period), the disparity switches change from 0 to 3 after the second
    display frame. The system recovers within one camera frame: the settled display frame (after pair 4, one good
    frame after the last fault) is the golden frame of pair 4 at the new disparity, bit for bit, and every other
    display frame still has whole image rows from the camera frames (at most the one row being written torn)."""
    from sim.models.mt9d112.sensor import Faults
    from sim.testbed.sequence import DROP
    setup = SystemSetup.small()
    g = setup.geometry
    sequence = moving_card(setup, 5)
    sequence.faults = {"a": [None, Faults(fv_drop=(g.height // 2, 5)), None, None, None],
                       "b": [None, None, DROP, None, None]}
    result = _simulate(setup, sequence, Verilator(switch_changes={2: [0x80 | 3, 0]}))
    status, shown = result.status, result.frames
    assert status["violations"] == []
    events = status["capture_events_s"]
    assert len(events["a"]["frame_done"]) == 5 and len(events["b"]["frame_done"]) == 4
    after = SystemSetup.small(disparity=3)
    assert np.array_equal(shown[-1].frame, after.golden_frame(*sequence.pairs[-1]))
    summaries = _summaries(after, sequence, shown[3:])
    assert all(s["left_rows_mixed"] <= 1 and s["right_rows_mixed"] <= 1 for s in summaries)


def test_a_sensor_restarted_mid_run_is_seen_and_written_whole():
    """Camera B restarts during its frame 1 (FV falls in its last line, then 10 silent line times: a reset or a
    standby and wake-up that keeps its registers), so its frames 2 and 3 start about 9 sensor lines after camera
    A's. The design does not re-align a running pair (only a reset runs the init barrier again, docs/capture.md):
    it writes every later frame whole, never outside the buffers, and shows the new skew: the meter measures what
    the simulation shows, frame starts 0 and 1 aligned, 2 and 3 not, LD7 on; the settled display frame is the
    golden frame of the last pair bit for bit."""
    from sim.models.mt9d112.sensor import Faults
    setup = SystemSetup.small()
    sequence = moving_card(setup, 4)
    sequence.faults = {"b": [None, Faults(fv_drop=(setup.geometry.height - 1, 0), silence_lines=10), None, None]}
    result = _simulate(setup, sequence)
    status, shown = result.status, result.frames
    assert status["violations"] == []
    events, hardware = status["capture_events_s"], status["hardware_skew"]
    assert len(events["a"]["frame_done"]) == 4 and len(events["b"]["frame_done"]) == 4
    assert len(hardware) == 4
    for k, measured in enumerate(hardware):
        simulated = (events["b"]["frame_start"][k] - events["a"]["frame_start"][k]) * setup.sys_hz
        assert abs(measured["skew_sync_clocks"] - simulated) <= 3
    assert [m["aligned"] for m in hardware] == [True, True, False, False]
    assert hardware[-1]["skew_sync_clocks"] > 0                     # camera B late
    assert status["leds"] >> 7 == 1
    assert np.array_equal(shown[-1].frame, setup.golden_frame(*sequence.pairs[-1]))


@pytest.mark.slow
def test_moving_card_frames_on_amaranth():
    """About a minute: the Python sensor drivers run per PCLK for two camera frames and five display frames."""
    setup = SystemSetup.small()
    sequence = moving_card(setup, 2)
    result = _simulate(setup, sequence, Amaranth())
    status, shown = result.status, result.frames
    assert status["violations"] == [] and len(shown) == status["settled_frame"] + 1 and result.ok
    summaries = [s.verdict for s in shown]
    assert summaries[-1]["equals_pair"] == 1
    assert len(status["hardware_skew"]) == 2 and all(m["aligned"] for m in status["hardware_skew"])


@pytest.mark.slow
def test_moving_card_frames_on_cocotb(simulator, tmp_path):
    """The same scenario in cocotb (Python sensor drivers and sink inside the simulator), on Verilator and Icarus
    (40 s on Icarus; Verilator's build about 90 s more)."""
    setup = SystemSetup.small()
    sequence = moving_card(setup, 2)
    result = _simulate(setup, sequence, Cocotb(simulator, out_dir=tmp_path))
    status, shown = result.status, result.frames
    assert status["violations"] == [] and len(shown) == status["settled_frame"] + 1 and result.ok
    summaries = [s.verdict for s in shown]
    assert summaries[-1]["equals_pair"] == 1
    assert all(s["left_rows_mixed"] <= 1 and s["right_rows_mixed"] <= 1 for s in summaries)
    assert len(status["hardware_skew"]) == 2 and all(m["aligned"] for m in status["hardware_skew"])


def test_card_distances_even_in_inverse_distance():
    z = card_distances(4, 3.0, 0.5)
    assert z[0] == 3.0 and abs(z[-1] - 0.5) < 1e-12
    steps = np.diff(1 / np.array(z))
    assert np.allclose(steps, steps[0])


@pytest.mark.parametrize("case, message", [
    ("count", "the left folder has 2 images, the right folder 1"),
    ("size", "all frames must have one size"),
    ("empty", "no image files"),
    ("too_many", "--frames 5, but the folders hold 2 pairs"),
])
def test_sequence_folder_errors(tmp_path, capsys, case, message):
    from PIL import Image
    from stereodepth.cli import main
    left, right = tmp_path / "L", tmp_path / "R"
    left.mkdir(), right.mkdir()
    sizes = [(160, 120), (200, 150) if case == "size" else (160, 120)]
    if case != "empty":
        for i, size in enumerate(sizes):
            Image.new("RGB", size, (i * 40, 90, 10)).save(left / f"{i:02d}.png")
            if case != "count" or i == 0:
                Image.new("RGB", size, (i * 40, 90, 10)).save(right / f"{i:02d}.png")
    frames = "5" if case == "too_many" else "2"
    code = main(["run", str(left), str(right), "--small", "--frames", frames, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def _write_video(path, frames, fourcc="FFV1"):
    """``frames`` (RGB uint8 arrays) as a video file; FFV1 is lossless, so the frames read back exactly."""
    import cv2
    height, width = frames[0].shape[:2]
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*fourcc), 15, (width, height))
    assert writer.isOpened()
    for frame in frames:
        writer.write(cv2.cvtColor(frame, cv2.COLOR_RGB2BGR))
    writer.release()


def _moving_pair(frames, size=(160, 120)):
    rng = np.random.default_rng(7)
    base = rng.integers(0, 256, (size[1], size[0] + 8 * frames, 3), dtype=np.uint8)
    return ([base[:, 4 * k + 4:4 * k + 4 + size[0]] for k in range(frames)],
            [base[:, 4 * k:4 * k + size[0]] for k in range(frames)])


def test_video_files_give_the_pairs_their_frames_give_as_a_folder(tmp_path):
    """Two lossless video files and two folders of the same frames: one sequence, pair for pair."""
    from PIL import Image
    from sim.testbed.sequence import sequence_from_folders, sequence_from_videos
    setup = SystemSetup.small()
    left, right = _moving_pair(3)
    for side, frames in (("L", left), ("R", right)):
        _write_video(tmp_path / f"{side}.avi", frames)
        (tmp_path / side).mkdir()
        for k, frame in enumerate(frames):
            Image.fromarray(frame).save(tmp_path / side / f"{k:02d}.png")
    videos = sequence_from_videos(tmp_path / "L.avi", tmp_path / "R.avi", setup, 2)
    folders = sequence_from_folders(tmp_path / "L", tmp_path / "R", setup, 2)
    assert len(videos) == 2 and len(sequence_from_videos(tmp_path / "L.avi", tmp_path / "R.avi", setup)) == 3
    for (vl, vr), (fl, fr) in zip(videos.pairs, folders.pairs):
        assert np.array_equal(vl, fl) and np.array_equal(vr, fr)
    assert not np.array_equal(videos.pairs[0][0], videos.pairs[1][0])


def test_a_video_pair_runs_to_a_video(tmp_path):
    """``stereodepth run L.avi R.avi --small --frames 2`` on Verilator: the settled frame passes, every display
    frame's depth rows come from a camera frame or are withheld at a tear (none mixed: the torn golden map,
    ``FrameWriter.tear``), and hdmi_video.mp4 holds every display frame."""
    import json
    import cv2
    from stereodepth.cli import main
    left, right = _moving_pair(2, (256, 192))
    _write_video(tmp_path / "L.avi", left)
    _write_video(tmp_path / "R.avi", right)
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "L.avi"), str(tmp_path / "R.avi"), "--small", "--frames", "2",
                 "--out", str(out)]) == 0
    rows = json.loads((out / "result.json").read_text())["frames"]
    assert all(r["depth_rows_mixed"] == 0 and r["consistent"] for r in rows)
    assert any(r["depth_rows_withheld"] and r["tear"] for r in rows)
    video = cv2.VideoCapture(str(out / "hdmi_video.mp4"))
    assert int(video.get(cv2.CAP_PROP_FRAME_COUNT)) == len(rows) >= 3


@pytest.mark.slow
def test_a_video_pair_on_the_ddr2_build_shows_whole_pairs_only(tmp_path):
    """``stereodepth run L.avi R.avi --small --frames 2 --memory ddr2`` on Verilator (the small DDR2 build, about a
    minute to build): every display frame equals the golden frame of one camera-frame pair (or of the empty
    buffers), none with a withheld or mixed depth row, the last shows the last pair."""
    import json
    from stereodepth.cli import main
    left, right = _moving_pair(2, (256, 192))
    _write_video(tmp_path / "L.avi", left)
    _write_video(tmp_path / "R.avi", right)
    out = tmp_path / "out"
    assert main(["run", str(tmp_path / "L.avi"), str(tmp_path / "R.avi"), "--small", "--frames", "2",
                 "--memory", "ddr2", "--out", str(out)]) == 0
    result = json.loads((out / "result.json").read_text())
    rows = result["frames"]
    assert result["display_frames_from_one_pair"] and result["pairs_shown"][-1] == 1, result["pairs_shown"]
    assert len(rows) == len(result["pairs_shown"]) >= 3
    assert all(r["depth_rows_mixed"] == 0 and not r["depth_rows_withheld"] and r["consistent"] for r in rows)


@pytest.mark.parametrize("case, message", [
    ("count", "the left video has 3 frames, the right video 2"),
    ("size", "the left video is 160x120, the right video 200x150"),
    ("too_many", "--frames 5, but the videos hold 3 frames"),
    ("not_a_video", "is not a video file OpenCV can read"),
    ("missing", "does not exist"),
    ("mixed", "both be video files or both be image files"),
    ("no_frames", "video files run frame after frame: add --frames N"),
])
def test_sequence_video_errors(tmp_path, capsys, case, message):
    from stereodepth.cli import main
    left, right = _moving_pair(3)
    if case == "size":
        right = _moving_pair(3, (200, 150))[1]
    _write_video(tmp_path / "L.mp4", left, "mp4v")
    _write_video(tmp_path / "R.mp4", right[:2] if case == "count" else right, "mp4v")
    paths = [tmp_path / "L.mp4", tmp_path / "R.mp4"]
    if case == "not_a_video":
        paths[1].write_text("not a video\n")
    elif case == "missing":
        paths[1].unlink()
    elif case == "mixed":
        paths[1] = tmp_path / "R.png"
    frames = [] if case == "no_frames" else ["--frames", "5" if case == "too_many" else "2"]
    code = main(["run", *map(str, paths), "--small", *frames, "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1 and "Traceback" not in err


def test_scene_needs_no_images_and_frames(tmp_path, capsys):
    from stereodepth.cli import main
    assert main(["run", "--small", "--scene", "card", "--out", str(tmp_path)]) == 2
    assert "--scene card needs --frames N" in capsys.readouterr().err
    assert main(["run", "a.png", "b.png", "--small", "--scene", "card", "--frames", "2", "--out", str(tmp_path)]) == 2
    assert "give no LEFT/RIGHT" in capsys.readouterr().err


def test_ctrl_c_keeps_the_finished_frames(tmp_path):
    """SIGINT in the middle of a multi-frame run: exit 130, every display frame finished so far readable under its
    own name, the table, the animations (the MP4 too) and result.json of those frames under their partial names."""
    import json
    import signal
    import subprocess
    import sys
    import time
    from pathlib import Path
    from PIL import Image
    out = tmp_path / "out"
    run = subprocess.Popen([sys.executable, "-m", "stereodepth", "run", "--small", "--scene", "card", "--frames",
                            "60", "--out", str(out)], cwd=Path(__file__).resolve().parents[1],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                           preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 300
    while not (out / "frames" / "hdmi_003.png").exists():
        assert run.poll() is None and time.monotonic() < deadline, run.communicate()
        time.sleep(0.05)
    run.send_signal(signal.SIGINT)
    _, stderr = run.communicate(timeout=120)
    assert run.returncode == 130 and "Traceback" not in stderr, stderr
    frames = sorted((out / "frames").glob("hdmi_*.png"))
    assert len(frames) >= 4 and not list((out / "frames").glob("*.partial.*"))
    for path in frames:
        assert Image.open(path).size == (112, 52)
    result = json.loads((out / "result.partial.json").read_text())
    assert result["interrupted"] and len(result["frames"]) == len(frames)
    assert (out / "frames.partial.csv").read_text().count("\n") == len(frames) + 1
    assert Image.open(out / "hdmi_video.partial.png").n_frames == len(frames)
    import cv2
    video = cv2.VideoCapture(str(out / "hdmi_video.partial.mp4"))
    assert int(video.get(cv2.CAP_PROP_FRAME_COUNT)) == len(frames)
    assert (int(video.get(cv2.CAP_PROP_FRAME_WIDTH)), int(video.get(cv2.CAP_PROP_FRAME_HEIGHT))) == (112, 52)
    assert not (out / "result.json").exists() and not (out / "hdmi_video.png").exists()


@pytest.mark.slow
def test_moving_card_full_size_on_verilator():
    """Full size (1600 x 1200 sensors, 1080p): the card 3 m -> 0.5 m over 3 camera frames; every display frame
    rebuilt, the settled one bit-exact with the last pair's golden frame, the frame starts in step; the centre
    distance shown on the last frame is the card's (50 cm). Minutes: ``python -m bench frames`` prints the same."""
    from sim.analysis.depth_panel import depth_summary
    setup = SystemSetup.full(disparity=20)
    sequence, shown, status = _run_verilator(setup, frames=3)
    assert status["violations"] == [] and len(shown) == status["settled_frame"] + 1 >= 9
    summaries = [s.verdict for s in shown]
    assert summaries[-1]["equals_pair"] == 2
    assert all(m["aligned"] and m["skew_sync_clocks"] == 0 for m in status["hardware_skew"])
    centre = depth_summary(shown[-1].frame, setup.display_layout, setup.geometry, setup.depth)
    assert centre["centre_distance_cm"] == 50


def _knocked_card(setup, frames=4, offsets=(0, 12)):
    from sim.testbed.sequence import offset_schedule
    return moving_card(setup, frames, vertical_offsets=offset_schedule(frames, list(offsets)))


def test_auto_rectification_relocks_after_a_knock_on_verilator():
    """Automatic rectification over four camera frames with the rig knocked halfway (0, then +12 sensor rows = +3
    buffer rows, the small search's edge): the golden estimator over the captured buffers expects the new offset
    after stable_frames frames; the design's display frames show, by the golden frame each equals, only the
    offset in use before or after the knock (never another), the new one within stable_frames + 1 camera frames,
    and the settled display frame is the golden frame of the last pair with +3 in use, bit for bit."""
    from sim.analysis.auto_rectification import AutoGoldens, State
    setup = SystemSetup.small(rectification="auto")
    sequence = _knocked_card(setup)
    auto = AutoGoldens(setup, sequence)
    knock, stable = 2, setup.auto_rectification.stable_frames
    assert [s.offset for s in auto.states] == [0, 0, 0, 3]           # the golden expectation, from the spec
    result = _simulate(setup, sequence)
    status, shown = result.status, result.frames
    assert status["violations"] == [] and len(shown) == status["settled_frame"] + 1
    rows = [s.verdict for s in shown]
    assert rows == [auto.row(s.frame, setup.display_layout, setup.geometry, min(s.captured.values())) for s in shown]
    assert result.verdict["auto_rectification_run"]["settled_shows_expected"] and result.ok
    assert np.array_equal(shown[-1].frame, setup.golden_frame(*sequence.pairs[-1], in_use=3, held=False))
    assert rows[-1]["equals_pair"] == 3 and rows[-1]["rectification_shown"] == "+3 auto"
    assert {r["rectification_shown"] for r in rows} <= {None, "+0 auto", "+3 auto"}
    first = next(i for i, r in enumerate(rows) if r["rectification_shown"] == "+3 auto")
    assert all(r["rectification_shown"] in (None, "+3 auto") for r in rows[first:])
    assert min(shown[first].captured.values()) - knock <= stable + 1      # camera frames done since the knock
    assert all(r["rectification_shown"] in (None, r["rectification_expected"]) for r in rows)
    assert auto.changes() == [(3, State(0, False), State(3, False))]


def test_the_knock_schedule_and_its_errors(tmp_path, capsys):
    from sim.testbed.sequence import offset_schedule
    from stereodepth.cli import main
    assert offset_schedule(6, [0, 12]) == [0, 0, 0, 12, 12, 12]
    assert offset_schedule(5, [0, 4, 8]) == [0, 0, 4, 4, 8]
    for extra, message in ((["--frames", "2", "--scene", "card", "--vertical-offset", "0,4,8"], "3 vertical offsets"),
                           (["--frames", "2", "--scene", "card", "--vertical-offset", "x"], "takes integers"),
                           (["--frames", "2", "--scene", "card", "--vertical-offset", "99"], "at most +-12"),
                           (["a.png", "b.png", "--frames", "2", "--vertical-offset", "4"], "is for --scene card"),
                           (["a.png", "b.png", "--vertical-offset", "4"], "is for --frames N --scene card")):
        assert main(["run", "--small", *extra, "--out", str(tmp_path)]) == 2
        err = capsys.readouterr().err
        assert message in err and len(err.strip().splitlines()) == 1, err


def test_ground_truth_with_frames_is_for_an_image_pair(tmp_path, capsys):
    """``--ground-truth`` with ``--frames`` gives the repeated pair of two image files its truth; the test bed's card
    has its own, folders and videos none: one line, exit code 2."""
    from stereodepth.cli import main
    assert main(["run", "--small", "--scene", "card", "--frames", "2", "--ground-truth", str(tmp_path / "t.pfm"),
                 "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "--ground-truth with --frames is for two image files" in err and len(err.strip().splitlines()) == 1
