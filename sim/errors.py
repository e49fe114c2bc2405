"""The one exception type for bad input from a user (a missing or unreadable file, mismatched images, an
out-of-range value). Library code raises it; the command line (``stereodepth``, which re-exports it) turns it into
a one-line error and exit code 2, without a traceback."""

__all__ = ["UserError"]


class UserError(Exception):
    """Bad input from the user: a missing or unreadable file, mismatched images, an out-of-range value."""
