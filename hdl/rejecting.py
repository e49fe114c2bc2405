"""``rejecting(component)``: a constructor's argument checks, without Amaranth's "created but never used" warning
when they fail.

Amaranth warns (``UnusedElaboratable``) about every Elaboratable that is garbage-collected without having been
elaborated, including one whose constructor raised. Wrapping the checks in ``with rejecting(self):`` marks the
object as deliberately unused when an exception leaves the block, then lets the exception go on. This is the
only place that touches Amaranth's private ``_MustUse__silence`` flag.
"""

from contextlib import contextmanager

__all__ = ["rejecting"]


@contextmanager
def rejecting(component):
    try:
        yield
    except BaseException:
        component._MustUse__silence = True
        raise
