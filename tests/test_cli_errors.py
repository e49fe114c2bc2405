"""Bad input to the command line, run as a user runs it (a subprocess, from a working directory holding the files):
every case exits with its code, prints exactly one error line on stderr (a usage line before it for a usage error;
nothing else but progress-bar lines), no traceback, and leaves an earlier run's outputs alone.

``python tests/test_cli_errors.py`` runs the same cases and prints the table of docs/running.md.
"""

import os
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0
#: Root without capabilities (no CAP_DAC_OVERRIDE): file permissions apply to it as to any user.
UNPRIVILEGED = ["setpriv", "--bounding-set=-all", "--inh-caps=-all"] if IS_ROOT else []

#: (what, arguments after ``stereodepth``, exit code, text the error line contains). ``readonly/`` is an existing
#: directory the user cannot write to (as root, those cases run without root's capabilities).
CASES = [
    ("unknown option", ["--bogus"], 2, "stereodepth: error: unrecognized option '--bogus'"),
    ("no command", [], 2, "stereodepth: error: a command is required"),
    ("unknown command", ["bogus"], 2, "stereodepth: error: unknown command 'bogus'"),
    ("unknown option of a command", ["run", "left.png", "right.png", "--bogus"], 2,
     "unrecognized arguments: --bogus"),
    ("missing image", ["run", "missing.png", "right.png"], 2, "no such image file: missing.png"),
    ("directory given as an image", ["run", "adir", "right.png"], 2, "adir is a directory, not an image file"),
    ("not an image", ["run", "text.png", "right.png"], 2, "cannot read image text.png: not an image file Pillow"),
    ("truncated image", ["run", "truncated.png", "right.png"], 2, "cannot read image truncated.png"),
    ("unreadable image (no permission)", ["run", "secret.png", "right.png"], 2,
     "cannot read image secret.png: Permission denied"),
    ("32-bit float image", ["run", "float.tif", "right.png"], 2, "has pixel format 'F', which has no defined 8-bit"),
    ("pair of different sizes", ["run", "left.png", "narrow.png"], 2, "a stereo pair must be the same size"),
    ("1x1 pair", ["run", "one.png", "one.png"], 2, "smaller than the least usable 400x300"),
    ("depth maps in the store without the DDR2", ["run", "left.png", "right.png", "--small", "--maps", "store"], 2,
     "--maps store: maps='store' keeps the depth maps in the frame store: it needs memory='ddr2'"),
    ("the small 800 x 600 build's segmentation band beyond its engine",
     ["run", "left.png", "right.png", "--build", "800", "--small", "--segment", "--disparity", "18"], 2,
     "--segment: the band 18 +-2 pixels holds no disparity the engine gives (0..15): use --disparity 0..17"),
    ("the 800 x 600 build in block RAM", ["run", "left.png", "right.png", "--build", "800", "--memory", "bram"], 2,
     "--build 800 keeps its frames and maps in the DDR2: drop --memory bram"),
    ("the demo's 800 x 600 build in block RAM", ["demo", "--build", "800", "--memory", "bram", "--out", "earlier"],
     2, "--build 800 keeps its frames and maps in the DDR2: drop --memory bram"),
    ("the 800 x 600 build's resources with the maps in the ring", ["resources", "--build", "800", "--maps", "ring"], 2,
     "--build 800 keeps its frames and maps in the DDR2: drop --maps ring"),
    ("the small 800 x 600 build's timing with the frames in block RAM",
     ["timing", "--build", "800", "--small", "--memory", "bram"], 2,
     "--build 800 keeps its frames and maps in the DDR2: drop --memory bram"),
    ("pair smaller than the small buffers", ["run", "one.png", "one.png", "--small"], 2,
     "smaller than the least usable 16x12"),
    ("10000x10000 image", ["run", "huge.png", "huge.png"], 2,
     "huge.png is 10000x10000 = 100,000,000 pixels, more than the limit of 25,000,000"),
    ("20000x10000 image (Pillow's bomb limit)", ["run", "bomb.png", "bomb.png"], 2, "Pillow refuses to decode it"),
    ("switch value out of range", ["run", "left.png", "right.png", "--disparity", "200"], 2,
     "--disparity must be 0..127"),
    ("rectification given up to the segmentation code", ["run", "left.png", "right.png", "--rectification", "-63"],
     2, "--rectification must be -62..63"),
    ("--segment with a manual rectification", ["run", "left.png", "right.png", "--segment", "--rectification", "3"],
     2, "--segment selects the automatic rectification (switches 1000001): drop --rectification 3"),
    ("--segment band beyond the engine", ["run", "left.png", "right.png", "--segment", "--disparity", "66"], 2,
     "--segment: the band 66 +-2 pixels holds no disparity the engine gives (0..63): use --disparity 0..65"),
    ("--vcd without the Amaranth simulator", ["run", "left.png", "right.png", "--vcd"], 2,
     "--vcd is written by the Amaranth route"),
    ("Icarus not installed (PATH without it)", ["run", "left.png", "right.png", "--simulator", "icarus",
                                                 "--out", "earlier"], 2, "icarus is not installed"),
    ("ground truth not a 16-bit PNG", ["run", "left.png", "right.png", "--ground-truth", "narrow.png", "--out",
                                       "earlier"], 2, "narrow.png: a PNG ground truth must be 16-bit grey"),
    ("ground truth missing", ["run", "left.png", "right.png", "--ground-truth", "missing.pfm", "--out", "earlier"],
     2, "no such ground-truth file: missing.pfm"),
    ("read-only output directory", ["run", "left.png", "right.png", "--out", "readonly"], 2,
     "output directory readonly is not writable: Permission denied"),
    ("output path is a file", ["run", "left.png", "right.png", "--out", "left.png"], 2,
     "output path left.png is not a directory"),
    ("output path below a file", ["run", "left.png", "right.png", "--out", "left.png/sub"], 2,
     "cannot create output directory left.png/sub"),
    ("read-only output directory, demo", ["demo", "--out", "readonly"], 2,
     "output directory readonly is not writable"),
    ("read-only output directory, waves", ["waves", "--out", "readonly"], 2,
     "output directory readonly is not writable"),
    ("read-only output directory, verilog", ["verilog", "--out", "readonly"], 2,
     "output directory readonly is not writable"),
    ("verilog: a design with the DDR2, no MIG core", ["verilog", "--memory", "ddr2"], 2,
     "this design uses the DDR2 behind Xilinx MIG, whose core is not in the repository"),
    ("run: the DDR2 build on Amaranth at full size", ["run", "left.png", "right.png", "--simulator", "amaranth",
                                                      "--memory", "ddr2"], 2,
     "the DDR2 build runs along the Amaranth python route only: add --small, or use verilator"),
    ("verilog: no such MIG core folder", ["verilog", "--mig", "nothere"], 2,
     "--mig nothere: no such MIG core folder: nothere"),
    ("verilog: a folder without a MIG core", ["verilog", "--mig", "adir"], 2,
     "--mig adir: adir has no user_design/rtl/ (the core's RTL"),
    ("verilog: --mig-name without --mig", ["verilog", "--mig-name", "ddr"], 2,
     "--mig-name names the core of --mig DIR: give --mig too"),
    ("verilog: a MIG core for the block-RAM build", ["verilog", "--memory", "bram", "--mig", "adir"], 2,
     "--mig gives the board the DDR2 frame store: it contradicts --memory bram"),
    ("image over depth's limit", ["depth", "big.png", "big.png"], 2,
     "is 2001x2001 = 4,004,001 pixels, more than the limit of 4,000,000"),
    ("depth: window larger than the image", ["depth", "left.png", "right.png", "--window", "500"], 2,
     "--window 500 is larger than the 480x360 image"),
]


def make_files(d):
    """The input files of :data:`CASES` in directory ``d``."""
    d = Path(d)
    rng = np.random.default_rng(18)
    rgb = rng.integers(0, 256, (360, 480, 3), dtype=np.uint8)
    Image.fromarray(rgb).save(d / "left.png")
    Image.fromarray(rgb).save(d / "right.png")
    Image.fromarray(rgb[:, :400]).save(d / "narrow.png")
    Image.fromarray(rgb[:1, :1]).save(d / "one.png")
    Image.fromarray(rgb[:, :, 0].astype(np.float32)).save(d / "float.tif")
    (d / "text.png").write_text("not a picture\n")
    (d / "truncated.png").write_bytes((d / "left.png").read_bytes()[:2000])
    shutil.copy(d / "left.png", d / "secret.png")
    (d / "adir").mkdir()
    (d / "empty-bin").mkdir()
    Image.new("1", (10000, 10000)).save(d / "huge.png")             # 100 M pixels in a few kB
    Image.new("1", (20000, 10000)).save(d / "bomb.png")
    Image.new("L", (2001, 2001)).save(d / "big.png")
    (d / "readonly").mkdir()
    (d / "readonly" / "result.json").write_text("{}\n")             # an earlier run's result: must stay
    (d / "earlier").mkdir()
    (d / "earlier" / "result.json").write_text("{}\n")
    (d / "readonly").chmod(0o555)
    (d / "secret.png").chmod(0o000)


def stereodepth(args, cwd, what=""):
    """Run ``python -m stereodepth args`` in ``cwd``; a case about permissions runs without root's power to read and
    write anything, one about a missing simulator with an empty PATH."""
    prefix = UNPRIVILEGED if unprivileged(what) else []
    env = dict(os.environ, PATH=str(Path(cwd) / "empty-bin")) if "not installed" in what else None
    return subprocess.run([*prefix, sys.executable, "-m", "stereodepth", *args], cwd=cwd, capture_output=True,
                          text=True, timeout=120, env=env,
                          preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def unprivileged(what):
    return "read-only" in what or "no permission" in what


def error_lines(stderr):
    """stderr without progress-bar lines and the usage line of a usage error."""
    return [line for line in stderr.splitlines() if line.strip() and "%|" not in line
            and not line.startswith("usage: ")]


@pytest.fixture(scope="module")
def files():
    d = Path(tempfile.mkdtemp(prefix="cli_errors_"))
    make_files(d)
    yield d
    (d / "readonly").chmod(0o755)
    shutil.rmtree(d)


@pytest.mark.parametrize("what, args, code, message", CASES, ids=[c[0] for c in CASES])
def test_bad_input_is_one_line_and_an_exit_code(files, what, args, code, message):
    if unprivileged(what) and IS_ROOT and not shutil.which("setpriv"):
        pytest.skip("root, and no setpriv to drop its capabilities")
    run = stereodepth(args, files, what)
    assert run.returncode == code, run.stderr
    assert "Traceback" not in run.stderr and "Warning" not in run.stderr, run.stderr
    lines = error_lines(run.stderr)
    assert len(lines) == 1 and message in lines[0], run.stderr
    assert lines[0].startswith("stereodepth"), lines
    assert run.stdout == ""
    assert (files / "readonly" / "result.json").read_text() == (files / "earlier" / "result.json").read_text() \
        == "{}\n"


def test_version_names_the_release_and_the_commit(files):
    from stereodepth.provenance import git_commit
    run = stereodepth(["--version"], files)
    assert run.returncode == 0 and run.stderr == ""
    from importlib.metadata import version
    assert run.stdout.startswith(f"stereodepth {version('stereo-fpga')}")
    commit = git_commit()
    if commit:
        assert f"(git {commit[:12]}" in run.stdout


def table(d):
    """The markdown table of docs/running.md: each case run, its exit code and error line."""
    rows = ["| case | command | exit | message (stderr) |", "|---|---|---|---|"]
    for what, args, _, _ in CASES:
        run = stereodepth(args, d, what)
        message = " / ".join(error_lines(run.stderr)).replace("|", "\\|")
        rows.append(f"| {what} | `stereodepth {' '.join(args)}` | {run.returncode} | {message} |")
    return "\n".join(rows)


if __name__ == "__main__":
    work = Path(tempfile.mkdtemp(prefix="cli_errors_"))
    try:
        make_files(work)
        print(table(work))
    finally:
        (work / "readonly").chmod(0o755)
        shutil.rmtree(work)
