"""The one exception type the command line turns into a one-line error (no traceback, non-zero exit): defined in
``sim/__init__.py`` (library code raises it too) and re-exported here."""

from sim import UserError

__all__ = ["UserError", "prepare_out_dir"]


def prepare_out_dir(path):
    """Create the output directory ``path`` (and its parents) and check that a file can be written in it, before
    any work; returns it as a ``Path``. A path that cannot be created, is a file, or is not writable is a
    :class:`UserError`."""
    import tempfile
    from pathlib import Path
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise UserError(f"output path {path} is not a directory")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"cannot create output directory {path}: {exc.strerror or exc}") from None
    try:
        with tempfile.TemporaryFile(dir=path, prefix=".write-check-"):
            pass
    except OSError as exc:
        raise UserError(f"output directory {path} is not writable: {exc.strerror or exc}") from None
    return path
