"""The project as a user installs it: ``pip install .`` (not editable) and run from a folder outside the checkout.

The wheel is installed into a folder of its own (``pip install --no-deps --target``) that comes first on the path,
beside this environment's third-party packages, so nothing of the checkout is importable: every file a command
needs (the C++ testbench, the Xilinx models, the bundled pair) must be in the package, and no path may lead back
to the source tree or to tests/.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """The wheel built from a copy of the sources (setuptools builds in the source tree and reuses its ``build/lib``
    and ``*.egg-info``: a file a stale build left there would hide one the package no longer has)."""
    target = tmp_path_factory.mktemp("site")
    source = tmp_path_factory.mktemp("source") / "stereo-fpga"
    shutil.copytree(ROOT, source, ignore=shutil.ignore_patterns(".git", ".venv", "build", "*.egg-info", "__pycache__",
                                                                ".pytest_cache", ".hypothesis", "tests"))
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps",
                    "--target", str(target), str(source)], check=True, capture_output=True, text=True,
                   cwd=tmp_path_factory.mktemp("build"))
    return target


def _stereodepth(installed, cwd, *args, build_dir=None):
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "STEREO_BUILD_DIR")}
    env["PYTHONPATH"] = str(installed)
    if build_dir is not None:
        env["STEREO_BUILD_DIR"] = str(build_dir)
    return subprocess.run([sys.executable, "-m", "stereodepth", *args], cwd=cwd, env=env, capture_output=True,
                          text=True, timeout=1200)


def test_the_installed_package_is_not_the_checkout(installed, tmp_path):
    run = _stereodepth(installed, tmp_path, "--version")
    assert run.returncode == 0, run.stderr
    probe = subprocess.run([sys.executable, "-c", "import sim, hdl, board, spec; print(sim.__file__)"], cwd=tmp_path,
                           env={**os.environ, "PYTHONPATH": str(installed)}, capture_output=True, text=True)
    assert probe.stdout.strip().startswith(str(installed)), probe.stdout + probe.stderr
    assert not (installed / "tests").exists()


def test_the_package_data_is_installed(installed, tmp_path):
    """The files product code reads from its packages: the bundled pair, the C++ testbench, the Xilinx models."""
    probe = ("from sim.board.xilinx import model_sources\n"
             "from sim.runners.verilator import build\n"
             "from golden.stereo_pair import DATA_DIR\n"
             "pair = [DATA_DIR / f'motorcycle_{side}.png' for side in ('left', 'right')]\n"
             "files = [*model_sources(), *(build.SOURCE_DIR / n for n in build.BUILD_SOURCES), *pair]\n"
             "print(sorted(str(f) for f in files if not f.is_file()))\n")
    run = subprocess.run([sys.executable, "-c", probe], cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(installed)},
                         capture_output=True, text=True)
    assert run.returncode == 0 and run.stdout.strip() == "[]", run.stdout + run.stderr


def test_verilog_from_outside_the_checkout(installed, tmp_path):
    out = tmp_path / "genesys"
    run = _stereodepth(installed, tmp_path, "verilog", "--allow-unconfirmed", "--out", str(out))
    assert run.returncode == 0, run.stdout + run.stderr
    assert (out / "top.v").stat().st_size > 0 and (out / "top.ucf").exists()


def test_small_demo_from_outside_the_checkout(installed, tmp_path):
    """The installed copy's small demo, from another folder, on the block-RAM build (whose small Verilator build
    the default suite makes anyway; the DDR2 one only the slow tests make). Its simulator builds go to the
    checkout's build directory (``STEREO_BUILD_DIR``): the installed files are the checkout's, so the builds the
    other tests made are found by their content and reused (the build key holds module names and texts, not
    paths)."""
    out = tmp_path / "demo"
    run = _stereodepth(installed, tmp_path, "demo", "--small", "--no-waves", "--memory", "bram", "--out", str(out),
                       build_dir=ROOT / "build")
    assert run.returncode == 0, run.stdout[-2000:] + run.stderr[-2000:]
    assert (out / "hdmi_frame.png").exists() and (out / "result.json").exists()
    assert not (tmp_path / "build").exists()          # nothing written beside the working directory


def test_build_directory_defaults_to_the_working_directory(installed, tmp_path):
    probe = subprocess.run([sys.executable, "-c", "from sim.runners import build_dir; print(build_dir('x'))"],
                           cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(installed), "STEREO_BUILD_DIR": ""},
                           capture_output=True, text=True)
    assert probe.stdout.strip() == str((tmp_path / "build" / "x").resolve()), probe.stdout + probe.stderr
