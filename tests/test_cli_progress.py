"""The command line's progress bar (stereodepth/progress.py): in a log file (not a terminal) it redraws only at
stage changes and every 30 s, so a CI log gets a few lines per run, not one per update."""

import io
import sys


def test_progress_bar_in_a_log_redraws_only_at_stage_changes(monkeypatch):
    from stereodepth.progress import Progress
    log = io.StringIO()                     # isatty() is False
    monkeypatch.setattr(sys, "stderr", log)
    bar = Progress("verilator")
    for stage, start in (("I2C-init", 0), ("capture", 300), ("display", 700)):
        for done in range(start, start + 300):
            bar.update(done, f"verilator: {stage}")
    bar.close()
    draws = log.getvalue().count("\r")
    assert 3 <= draws <= 8, log.getvalue()
    for stage in ("I2C-init", "capture", "display"):
        assert f"verilator: {stage}" in log.getvalue()
