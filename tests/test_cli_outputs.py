"""``stereodepth run`` into a directory holding an earlier run, as a user runs it (a subprocess): a complete run
replaces every output and records what produced it; a run stopped with Ctrl-C (SIGINT) leaves nothing that looks
complete, only files named ``*.partial.*``. And stereodepth/outputs.py's own rules."""

import hashlib
import json
import os
import re
import signal
import subprocess
import sys
import time
from datetime import datetime
from pathlib import Path

import numpy as np
import pytest

from golden.image_file import read_image
from golden.stereo_pair import load_default_pair
from sim.testbench.system.run_cocotb import DEFAULT_PAIR
from stereodepth.outputs import RunOutputs, partial_name
from test_system import check_golden_is_interesting, check_status

ROOT = Path(__file__).resolve().parents[1]
EARLIER = ("result.json", "hdmi_frame.png", "golden_frame.png", "difference.png", "system.vcd", "system.gtkw",
           "hdmi_frame.partial.png")


def earlier_run(out):
    """``out`` as an earlier (interrupted) run left it; returns the files' contents."""
    out.mkdir(parents=True, exist_ok=True)
    for name in EARLIER:
        (out / name).write_text(f"earlier run: {name}\n")
    (out / "notes.txt").write_text("the user's own file\n")


def start_run(out, *extra, vcd=True, simulator="amaranth"):
    return subprocess.Popen([sys.executable, "-m", "stereodepth", "run", *map(str, DEFAULT_PAIR), "--small",
                             "--simulator", simulator, *(["--vcd"] if vcd else []), "--out", str(out), *extra],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def test_ctrl_c_leaves_only_partial_names(tmp_path):
    out = tmp_path / "out"
    earlier_run(out)
    run = start_run(out)
    vcd = out / "system.partial.vcd"
    deadline = time.monotonic() + 120
    while not (vcd.exists() and vcd.stat().st_size > 200_000):        # the simulation is under way
        assert run.poll() is None and time.monotonic() < deadline, run.communicate()
        time.sleep(0.1)
    run.send_signal(signal.SIGINT)
    stdout, stderr = run.communicate(timeout=60)
    assert run.returncode == 130, stderr
    assert "Traceback" not in stderr
    assert stderr.strip().splitlines()[-1] == "stereodepth run: interrupted; files named *.partial.* are incomplete"
    left = sorted(p.name for p in out.iterdir() if not p.name.startswith("."))
    assert left == ["notes.txt", "system.partial.vcd"], left           # earlier outputs gone, nothing complete
    assert vcd.stat().st_size > 200_000


def _sha256(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


@pytest.mark.parametrize("vcd", [False, pytest.param(True, marks=pytest.mark.slow)])
def test_complete_run_replaces_every_output_and_records_its_provenance(tmp_path, vcd):
    """... and, with ``--vcd``, its GTKWave save file opens on its VCD with every signal it lists (where GTKWave
    is installed; slow: the VCD writer more than doubles the run's time. The default suite's waveform checks are
    the interrupted run above, which writes the CLI's VCD, and tests/test_gtkw_files.py's save file of the same
    system). It is also the default suite's end-to-end run of Amaranth's simulator along the Python-model route:
    the checks of tests/test_system.py::test_end_to_end_amaranth on what result.json and the frames hold (that
    test's ``python`` route is slow: the same simulation in-process with other switch settings, one display
    frame fewer)."""
    from sim.waves import gtkwave_check
    out = tmp_path / "out"
    earlier_run(out)
    before = datetime.now().astimezone()
    run = start_run(out, "--disparity", "3", vcd=vcd)
    stdout, stderr = run.communicate(timeout=600)
    assert run.returncode == 0, stderr
    names = sorted(p.name for p in out.iterdir() if not p.name.startswith("."))
    waves = ["system.gtkw", "system.vcd"] if vcd else []
    assert names == ["depth_map.png", "golden_frame.png", "hdmi_frame.png", "notes.txt", "result.json", *waves], \
        names
    if vcd:
        assert f'[dumpfile] "{(out / "system.vcd").resolve()}"' in (out / "system.gtkw").read_text()
        if gtkwave_check.available():
            want = gtkwave_check.listed(out / "system.gtkw")
            assert len(want) >= 30
            assert gtkwave_check.displayed(out / "system.gtkw")[0] == want
    result = json.loads((out / "result.json").read_text())
    record = result["provenance"]
    assert [i["path"] for i in record["inputs"]] == [str(p.resolve()) for p in DEFAULT_PAIR]
    assert [i["sha256"] for i in record["inputs"]] == [_sha256(p) for p in DEFAULT_PAIR]
    params = record["parameters"]
    assert (params["disparity"], params["rectification"], params["simulator"], params["small"], params["vcd"]) \
        == (3, 0, "amaranth", True, vcd)
    assert params["out"] == str(out) and params["setup"]["preset"] == "small"
    assert result["segmentation"] == {"on": False}
    import amaranth
    import cocotb
    assert record["tools"]["amaranth"] == amaranth.__version__ and record["tools"]["cocotb"] == cocotb.__version__
    assert set(record["tools"]) >= {"verilator", "iverilog", "numpy", "pillow", "python"}
    git = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True)
    if git.returncode == 0:
        assert record["git_commit"].startswith(git.stdout.strip())
    started, ended = (datetime.fromisoformat(record[k].replace("Z", "+00:00")) for k in ("started_utc", "ended_utc"))
    assert re.fullmatch(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ", record["ended_utc"])
    assert before.replace(microsecond=0) <= started <= ended <= datetime.now().astimezone()
    _check_end_to_end(out, result)


def _check_end_to_end(out, status):
    """tests/test_system.py::test_end_to_end_amaranth's checks on a run's outputs: the frame shown is the golden
    frame of the pair (no depth row withheld), the parts end configured, the buses clean."""
    from sim.models.mt9d112.config import expected_sensor_config
    from sim.testbench.system.setup import SystemSetup
    setup = SystemSetup.small(disparity=3, rectification=0)
    check_status(status, (3, 0))
    golden = read_image(out / "golden_frame.png")
    check_golden_is_interesting(golden, setup)
    assert status["violations"] == [] and status["verdict"]["ok"] and status["mismatched_pixels"] == 0
    np.testing.assert_array_equal(read_image(out / "hdmi_frame.png"), golden)
    np.testing.assert_array_equal(golden, setup.golden_frame(*load_default_pair(setup.geometry.width,
                                                                                 setup.geometry.height)))
    for bus in ("cam_a", "cam_b"):
        assert status["sensor_config"][bus] == repr(expected_sensor_config(setup.geometry))
        assert status["mt9d112_problems"][bus] == []
    dvi = status["dvi_config"]
    assert dvi["dvi_on"] and dvi["idf"] == 0 and dvi["hsync_positive"] and dvi["vsync_positive"] \
        and dvi["pll_range"] == "high"
    for bus, errors in status["i2c_protocol_errors"].items():
        assert not errors and status["i2c_transactions"][bus], (bus, errors[:3])


def test_segment_run_records_its_band(tmp_path):
    """``--segment``: the switches on 1000001 (automatic rectification), the frame equal to the golden model's with
    the segmentation view, the band in result.json and the summary (the small layout has no room for its text).
    The frame shown is also rebuilt here from the golden model (the offset in use and the tear that result.json
    records): the segmentation view differs from the difference map it replaces, and nothing else changes (the
    checks of tests/test_system.py::test_end_to_end_amaranth_segmentation, slow: the same run in Amaranth's
    simulator). On Verilator (the command line's default simulator: seconds; Amaranth's simulator runs the whole
    system in the complete run above)."""
    out = tmp_path / "out"
    run = start_run(out, "--disparity", "3", "--segment", vcd=False, simulator="verilator")
    stdout, stderr = run.communicate(timeout=600)
    assert run.returncode == 0, stderr
    result = json.loads((out / "result.json").read_text())
    assert result["segmentation"] == {"on": True, "band_disparity_px": [1, 5], "band_text": " 5.46-27.28m",
                                      "text_shown": False}
    params = result["provenance"]["parameters"]
    assert (params["rectification"], params["segment"], params["setup"]["segment"]) == ("auto", True, True)
    assert "segmentation view: band 5.46-27.28m (disparities 1..5 px)" in stdout
    assert "equals the golden model's frame bit for bit" in stdout
    assert result["auto_rectification"]["auto"] == 1
    assert result["mismatched_pixels"] == 0 and result["violations"] == []
    _check_segmentation_frame(read_image(out / "hdmi_frame.png"), result, disparity=3)


def _check_segmentation_frame(shown, result, disparity):
    """``shown`` is the golden frame with the segmentation view, which differs from the plain frame (same offset,
    same tear) in the difference map's place only."""
    from sim.testbench.system.result import tear_tags
    from sim.testbench.system.setup import SystemSetup
    setup = SystemSetup.small(disparity=disparity, rectification="auto", segment=True)
    assert setup.switch_words() == [0x80 | disparity, 0b1000001]
    left, right = load_default_pair(setup.geometry.width, setup.geometry.height)
    same = dict(in_use=result["rectification"], row_tags=tear_tags(setup.geometry.buf_height, result["tear"]))
    golden = setup.golden_frame(left, right, **same)
    np.testing.assert_array_equal(shown, golden)
    plain = SystemSetup.small(disparity=disparity, rectification="auto").golden_frame(left, right, **same)
    r = setup.display_layout.region("disparity")
    assert (plain[r.y0:r.y1, r.x0:r.x1] != golden[r.y0:r.y1, r.x0:r.x1]).any()
    outside = golden.copy()
    outside[r.y0:r.y1, r.x0:r.x1] = plain[r.y0:r.y1, r.x0:r.x1]
    np.testing.assert_array_equal(outside, plain)      # nothing else changes (the small layout has no band text)


def test_outputs_are_renamed_only_when_complete_and_stale_ones_removed(tmp_path):
    earlier_run(tmp_path)
    outputs = RunOutputs(tmp_path, ("result.json", "system.vcd", "system.gtkw"), stale=("hdmi_*.png",)).start()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["difference.png", "golden_frame.png", "notes.txt"]
    assert partial_name("system.vcd") == "system.partial.vcd"
    outputs.partial("system.vcd").write_text("$enddefinitions $end\n")
    assert not (tmp_path / "system.vcd").exists()
    outputs.commit("system.vcd")
    assert (tmp_path / "system.vcd").exists() and not (tmp_path / "system.partial.vcd").exists()
    outputs.partial("system.gtkw").write_text(f'[dumpfile] "{(tmp_path / "system.partial.vcd").resolve()}"\n')
    outputs.commit_save_file("system.gtkw", "system.vcd")
    assert (tmp_path / "system.gtkw").read_text() == f'[dumpfile] "{(tmp_path / "system.vcd").resolve()}"\n'
    with pytest.raises(ZeroDivisionError):
        outputs.write("result.json", lambda p: p.write_text("{") and 1 / 0)    # a writer that fails half-way
    assert not (tmp_path / "result.json").exists() and (tmp_path / "result.partial.json").exists()
    with pytest.raises(ValueError, match="not one of this command's outputs"):
        outputs.partial("other.png")


@pytest.fixture
def sigint_handler():
    """SIGINT's handler set for the test (whatever the process was started with: a background job ignores SIGINT),
    and the process's own put back after it."""
    started_with = signal.getsignal(signal.SIGINT)
    yield lambda handler: signal.signal(signal.SIGINT, handler)
    signal.signal(signal.SIGINT, started_with)


def test_ctrl_c_waits_for_the_whole_step(sigint_handler):
    """A SIGINT inside :func:`whole_step` lets the block finish and raises KeyboardInterrupt after it; outside,
    Ctrl-C works as before."""
    from stereodepth.interrupts import whole_step
    sigint_handler(signal.default_int_handler)
    done = []
    with pytest.raises(KeyboardInterrupt):
        with whole_step():
            os.kill(os.getpid(), signal.SIGINT)
            done.append("after the signal")
    assert done == ["after the signal"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    with whole_step():
        done.append("no signal")
    assert done[-1] == "no signal"


def test_whole_step_keeps_an_ignored_sigint_ignored(sigint_handler):
    """A process that ignores SIGINT (a job started in the background) is not interrupted by a whole step."""
    from stereodepth.interrupts import whole_step
    sigint_handler(signal.SIG_IGN)
    try:
        with whole_step():
            os.kill(os.getpid(), signal.SIGINT)
    except KeyboardInterrupt:
        pytest.fail("a whole step turned an ignored SIGINT into KeyboardInterrupt")
    assert signal.getsignal(signal.SIGINT) is signal.SIG_IGN
