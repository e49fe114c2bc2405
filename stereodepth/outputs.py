"""A command's output directory that never shows a partial or stale result as a complete one.

:class:`RunOutputs` removes, at the start of a run, the files an earlier run of the command left (its named
outputs and any ``*.partial.*``); each output is written under its partial name (``hdmi_frame.partial.png``) and
renamed to its own name only once complete. A run that is interrupted or fails leaves only partial names behind.
"""

import os
from pathlib import Path

__all__ = ["RunOutputs", "partial_name", "write_atomic"]


def partial_name(name):
    """``system.vcd`` -> ``system.partial.vcd`` (the extension kept, so viewers still open it)."""
    path = Path(name)
    return f"{path.stem}.partial{path.suffix}"


def write_atomic(path, writer):
    """``writer(partial path)`` writes the file; renamed to ``path`` once it returns. Returns ``path``."""
    path = Path(path)
    partial = path.with_name(partial_name(path.name))
    writer(partial)
    os.replace(partial, path)
    return path


class RunOutputs:
    """The outputs ``names`` of one command in the directory ``path`` (already checked by
    :func:`stereodepth.errors.prepare_out_dir`); ``stale``: glob patterns of further files of the command that
    :meth:`start` removes."""

    def __init__(self, path, names, *, stale=()):
        self.dir = Path(path)
        self.names = tuple(names)
        self.stale = ("*.partial.*", *stale)

    def start(self):
        """Remove what an earlier run left: the named outputs, every partial file and the ``stale`` patterns."""
        stale = [self.dir / n for n in self.names] + [p for pattern in self.stale for p in self.dir.glob(pattern)]
        for path in stale:
            if path.is_file() or path.is_symlink():
                path.unlink()
        return self

    def partial(self, name):
        """Where to write output ``name`` while it is being made."""
        if name not in self.names:
            raise ValueError(f"{name} is not one of this command's outputs {self.names}")
        return self.dir / partial_name(name)

    def commit(self, name):
        """Output ``name`` is complete: rename it from its partial name; returns its path."""
        final = self.dir / name
        os.replace(self.partial(name), final)
        return final

    def write(self, name, writer):
        """``writer(path)`` writes the file; it is written under the partial name and committed."""
        self.partial(name)                              # one of the outputs
        return write_atomic(self.dir / name, writer)

    def commit_save_file(self, name, vcd_name):
        """Commit the GTKWave save file ``name``, which names its VCD by absolute path: point it at the VCD's
        final name (the VCD is committed first)."""
        text = self.partial(name).read_text()
        text = text.replace(str(self.partial(vcd_name).resolve()), str((self.dir / vcd_name).resolve()))
        self.partial(name).write_text(text)
        return self.commit(name)
