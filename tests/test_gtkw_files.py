"""The GTKWave save files the tools write open in GTKWave with every listed signal found in the VCD.

Checked by opening them in GTKWave itself, headless (``sim/gtkwave_check.py``); skipped where GTKWave or
xvfb-run is missing (``.ci/run`` installs both). The whole system's save file is checked in
tests/test_system.py's Amaranth run, which writes it.
"""

import shutil

import pytest

from hdl.params import SMALL_TIMING
from sim import gtkwave_check

needs_gtkwave = pytest.mark.skipif(not gtkwave_check.available(), reason="gtkwave or xvfb-run not installed")


@pytest.fixture(scope="module")
def display_waves(tmp_path_factory):
    from stereodepth.cmd_display import write_display_waves
    return write_display_waves(SMALL_TIMING, tmp_path_factory.mktemp("waves") / "display.vcd")


@needs_gtkwave
def test_display_save_file_shows_every_signal(display_waves):
    gtkw = display_waves["GTKWave"]
    want = gtkwave_check.listed(gtkw)
    shown, facilities = gtkwave_check.displayed(gtkw)
    assert len(want) >= 16 and facilities >= len(want)
    assert shown == want


@needs_gtkwave
def test_a_missing_signal_is_caught(display_waves, tmp_path):
    """The check can fail: a save file naming a signal the VCD lacks shows one signal fewer."""
    gtkw = tmp_path / "bad.gtkw"
    shutil.copy(display_waves["VCD"], tmp_path / "display.vcd")
    text = display_waves["GTKWave"].read_text().replace(str(display_waves["VCD"]), str(tmp_path / "display.vcd"))
    first = gtkwave_check.listed(display_waves["GTKWave"])[0]
    gtkw.write_text(text.replace(first + "\n", first + "\nbench.no_such_signal\n", 1))
    want = gtkwave_check.listed(gtkw)
    shown, _ = gtkwave_check.displayed(gtkw)
    assert "bench.no_such_signal" in want and "bench.no_such_signal" not in shown
    assert len(shown) == len(want) - 1
