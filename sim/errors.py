"""The exceptions library code raises for the command line to report: :class:`UserError` for bad input (one-line
error, exit code 2, no traceback; ``stereodepth.errors`` re-exports it) and :class:`SimulationFailed` for a
simulation that ended without a result."""

__all__ = ["UserError", "SimulationFailed"]


class UserError(Exception):
    """Bad input from the user: a missing or unreadable file, mismatched images, an out-of-range value."""


class SimulationFailed(RuntimeError):
    """A simulation ended without a result (build error, crash, I2C failure): the message says why and where the
    log is."""
