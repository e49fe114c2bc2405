"""The one exception type the command line turns into a one-line error (no traceback, non-zero exit): defined in
``sim/errors.py`` (library code raises it too) and re-exported here."""

from sim.errors import UserError

__all__ = ["UserError", "prepare_out_dir"]


def prepare_out_dir(path):
    """Create the output directory ``path`` (and its parents) and return it as a ``Path``; a path that cannot be
    created, or is a file, is a :class:`UserError`."""
    from pathlib import Path
    path = Path(path)
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"cannot create output directory {path}: {exc.strerror or exc}") from None
    if not path.is_dir():
        raise UserError(f"output path {path} is not a directory")
    return path
