"""Ctrl-C held back while a step that must not be cut in half runs (one display frame's files and table row)."""

import contextlib
import signal
import threading

__all__ = ["whole_step"]


@contextlib.contextmanager
def whole_step():
    """Run the block with SIGINT held: a Ctrl-C that arrives meanwhile raises :class:`KeyboardInterrupt` when the
    block has finished, so the block's outputs are either all written or not started. Outside the main thread
    (where Python cannot take signals), or where SIGINT is ignored (a background job), the block runs as it is."""
    if (threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGINT) is signal.SIG_IGN):
        yield
        return
    arrived = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: arrived.append(signum))
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
    if arrived:
        raise KeyboardInterrupt
