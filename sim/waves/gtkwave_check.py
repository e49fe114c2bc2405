"""Open a GTKWave save file in GTKWave itself, headless, and list the signals it shows.

A ``.gtkw`` file names its VCD (``[dumpfile]``) and the signals to display, one per line. GTKWave silently drops
a name that is not in the VCD, so the only real check that a save file works is to open it: :func:`displayed`
runs ``gtkwave -S`` under ``xvfb-run`` (a virtual X display) with a Tcl script that prints
``gtkwave::getDisplayedSignals`` (and the time window it opened on) and quits. :func:`listed` reads the names
the file asks for; a working file shows every one of them.

:func:`screenshot` takes a picture of GTKWave as it opens a save file: GTKWave runs on an ``Xvfb`` display that
keeps its frame buffer in a file (``-fbdir``, X window dump format), which is copied once GTKWave has drawn and
converted to PNG here (no X client tools needed).

Needs the Debian packages ``gtkwave`` and ``xvfb`` (:func:`available`).
"""

import os
import shutil
import struct
import subprocess
import tempfile
import time
from pathlib import Path

__all__ = ["available", "listed", "markers", "displayed", "window", "screenshot"]

_SCRIPT = """\
foreach signal [gtkwave::getDisplayedSignals] { puts "DISPLAYED $signal" }
puts "FACILITIES [gtkwave::getNumFacs]"
puts "WINDOW [gtkwave::getWindowStartTime] [gtkwave::getWindowEndTime]"
gtkwave::/File/Quit
"""


def available():
    """True when GTKWave and ``xvfb-run`` are installed."""
    return shutil.which("gtkwave") is not None and shutil.which("xvfb-run") is not None


def listed(gtkw_path):
    """The signal names a save file asks GTKWave to display, in order (a combined vector ``#{name} a b`` lists
    ``a`` and ``b``; an alias ``+{alias} name`` lists ``name``)."""
    names = []
    for line in Path(gtkw_path).read_text().splitlines():
        line = line.strip()
        if not line or line[0] in "[@-*^":
            continue
        if line.startswith("+{"):
            line = line[line.index("}") + 1:].strip()
        if line.startswith("#{"):
            names += line[line.index("}") + 1:].split()
        else:
            names.append(line)
    return names


def markers(gtkw_path):
    """``{label: time}`` of the named markers a save file sets (``[markername] Xlabel`` and the times on the
    ``*`` line)."""
    lines = Path(gtkw_path).read_text().splitlines()
    times = next(line for line in lines if line.startswith("*")).split()[2:]
    names = [line[len("[markername] "):] for line in lines if line.startswith("[markername] ")]
    return {name[1:]: int(times[ord(name[0]) - ord("A")]) for name in names}


def _open(gtkw_path, timeout_s, env=None):
    with tempfile.TemporaryDirectory(prefix="gtkwave_check_") as tmp:
        script = Path(tmp) / "list.tcl"
        script.write_text(_SCRIPT)
        command = ["xvfb-run", "-a", "-s", "-screen 0 1920x1200x24", "gtkwave", "-S", str(script),
                   str(Path(gtkw_path).resolve())]
        run = subprocess.run(command, capture_output=True, text=True, timeout=timeout_s, cwd=tmp,
                             env={**os.environ, **(env or {})})
    out = {"signals": [], "facilities": None, "window": None}
    for line in run.stdout.splitlines():
        if line.startswith("DISPLAYED "):
            out["signals"].append(line[len("DISPLAYED "):])
        elif line.startswith("FACILITIES "):
            out["facilities"] = int(line.split()[1])
        elif line.startswith("WINDOW "):
            out["window"] = tuple(int(v) for v in line.split()[1:3])
    if run.returncode != 0 or not out["facilities"]:
        raise RuntimeError(f"gtkwave could not open {gtkw_path} (exit {run.returncode}): "
                           f"{(run.stderr or run.stdout).strip()[-500:]}")
    return out


def displayed(gtkw_path, timeout_s=120, env=None):
    """``(signals GTKWave displays, number of facilities in the dump)`` after opening ``gtkw_path``. Raises
    ``RuntimeError`` if GTKWave fails or prints no facility count (the dump did not load). ``env`` adds
    environment variables (seen by the filter programs GTKWave starts)."""
    out = _open(gtkw_path, timeout_s, env)
    return out["signals"], out["facilities"]


def window(gtkw_path, timeout_s=120):
    """``(first, last)`` dump time GTKWave shows when it opens ``gtkw_path``."""
    return _open(gtkw_path, timeout_s)["window"]


def screenshot(gtkw_path, png_path, *, size=(1600, 1000), settle_s=8.0, timeout_s=120):
    """Open ``gtkw_path`` in GTKWave on a virtual screen of ``size`` pixels and save what it shows after
    ``settle_s`` seconds (loading, filter programs, drawing) as ``png_path``. Returns the path."""
    with tempfile.TemporaryDirectory(prefix="gtkwave_shot_") as tmp:
        xvfb = subprocess.Popen(["Xvfb", "-displayfd", "1", "-screen", "0", f"{size[0]}x{size[1]}x24",
                                 "-fbdir", tmp, "-nolisten", "tcp"], stdout=subprocess.PIPE, text=True)
        try:
            display = xvfb.stdout.readline().strip()
            if not display:
                raise RuntimeError("Xvfb did not start")
            viewer = subprocess.Popen(["gtkwave", str(Path(gtkw_path).resolve())], cwd=tmp,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                      env={**os.environ, "DISPLAY": f":{display}"})
            try:
                deadline = time.monotonic() + timeout_s
                time.sleep(settle_s)
                if viewer.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"gtkwave exited (code {viewer.returncode}) before the screenshot")
                frame = (Path(tmp) / "Xvfb_screen0").read_bytes()
            finally:
                viewer.terminate()
                viewer.wait(timeout=30)
        finally:
            xvfb.terminate()
            xvfb.wait(timeout=30)
    return _xwd_to_png(frame, png_path)


def _xwd_to_png(data, png_path):
    """Convert an X window dump (Xvfb's 24-bit TrueColor frame buffer, 32 bits a pixel) to PNG."""
    import numpy as np
    from PIL import Image
    header = struct.unpack(">25I", data[:100])
    header_size, depth, width, height = header[0], header[3], header[4], header[5]
    byte_order, bits_per_pixel, bytes_per_line, ncolours = header[7], header[11], header[12], header[19]
    if depth != 24 or bits_per_pixel != 32:
        raise RuntimeError(f"unexpected frame buffer format: depth {depth}, {bits_per_pixel} bits a pixel")
    pixels = np.frombuffer(data, np.uint8, bytes_per_line * height, header_size + 12 * ncolours)
    pixels = pixels.reshape(height, bytes_per_line)[:, :4 * width].reshape(height, width, 4)
    rgb = pixels[:, :, [2, 1, 0]] if byte_order == 0 else pixels[:, :, [1, 2, 3]]
    png_path = Path(png_path)
    png_path.parent.mkdir(parents=True, exist_ok=True)
    Image.fromarray(np.ascontiguousarray(rgb)).save(png_path)
    return png_path


if __name__ == "__main__":        # python -m sim.waves.gtkwave_check SAVEFILE PNG: the picture in docs/img/waves.png
    import sys
    if len(sys.argv) != 3:
        sys.exit("usage: python -m sim.waves.gtkwave_check SAVEFILE.gtkw OUT.png")
    print(screenshot(sys.argv[1], sys.argv[2]))
