"""The command line's progress bar: a tqdm bar on stderr with the current stage as its description.

Written to a terminal it redraws several times a second; to a file or pipe (a CI log) only every 30 s and at
stage changes, so a log gets a few lines per run.
"""

import sys

__all__ = ["Progress"]


class Progress:
    """``update(done, stage)`` moves the bar to ``done`` of ``total`` (never backwards) and, when ``stage``
    changes, shows it as the description. ``unit``: shown with a count (e.g. ``"clk"``); without it, a
    percentage."""

    def __init__(self, desc, *, total=1000, unit=None, enabled=True):
        from tqdm import tqdm
        kwargs = dict(unit=unit, unit_scale=True) if unit else \
            dict(bar_format="{desc:<28} {percentage:3.0f}%|{bar}| [{elapsed}]")
        self.bar = tqdm(total=total, desc=desc, disable=not enabled, file=sys.stderr, leave=True,
                        mininterval=0.1 if sys.stderr.isatty() else 30, **kwargs)
        self.stage = None

    def update(self, done, stage=None):
        if stage and stage != self.stage:            # set_description redraws: only at a stage change
            self.stage = stage
            self.bar.set_description(stage)
        done = max(self.bar.n, min(self.bar.total, done))
        self.bar.update(done - self.bar.n)

    def close(self):
        self.bar.close()
