"""Open a GTKWave save file in GTKWave itself, headless, and list the signals it shows.

A ``.gtkw`` file names its VCD (``[dumpfile]``) and the signals to display, one per line. GTKWave silently drops
a name that is not in the VCD, so the only real check that a save file works is to open it: :func:`displayed`
runs ``gtkwave -S`` under ``xvfb-run`` (a virtual X display) with a Tcl script that prints
``gtkwave::getDisplayedSignals`` and quits. :func:`listed` reads the names the file asks for; a working file
shows every one of them.

Needs the Debian packages ``gtkwave`` and ``xvfb`` (:func:`available`).
"""

import shutil
import subprocess
import tempfile
from pathlib import Path

__all__ = ["available", "listed", "displayed"]

_SCRIPT = """\
foreach signal [gtkwave::getDisplayedSignals] { puts "DISPLAYED $signal" }
puts "FACILITIES [gtkwave::getNumFacs]"
gtkwave::/File/Quit
"""


def available():
    """True when GTKWave and ``xvfb-run`` are installed."""
    return shutil.which("gtkwave") is not None and shutil.which("xvfb-run") is not None


def listed(gtkw_path):
    """The signal names a save file asks GTKWave to display, in order."""
    names = []
    for line in Path(gtkw_path).read_text().splitlines():
        line = line.strip()
        if line and line[0] not in "[@-*":
            names.append(line)
    return names


def displayed(gtkw_path, timeout_s=120):
    """``(signals GTKWave displays, number of facilities in the dump)`` after opening ``gtkw_path``. Raises
    ``RuntimeError`` if GTKWave fails or prints no facility count (the dump did not load)."""
    with tempfile.TemporaryDirectory(prefix="gtkwave_check_") as tmp:
        script = Path(tmp) / "list.tcl"
        script.write_text(_SCRIPT)
        run = subprocess.run(["xvfb-run", "-a", "gtkwave", "-S", str(script), str(gtkw_path)],
                             capture_output=True, text=True, timeout=timeout_s, cwd=tmp)
    signals, facilities = [], None
    for line in run.stdout.splitlines():
        if line.startswith("DISPLAYED "):
            signals.append(line[len("DISPLAYED "):])
        elif line.startswith("FACILITIES "):
            facilities = int(line.split()[1])
    if run.returncode != 0 or not facilities:
        raise RuntimeError(f"gtkwave could not open {gtkw_path} (exit {run.returncode}): "
                           f"{(run.stderr or run.stdout).strip()[-500:]}")
    return signals, facilities
