"""The one exception type the command line turns into a one-line error (no traceback, non-zero exit)."""


class UserError(Exception):
    """Bad input from the user: a missing or unreadable file, mismatched images, an out-of-range value."""
