"""``rejecting(component)``: a constructor's argument checks, without Amaranth's "created but never used" warning
when they fail.

Amaranth warns (``UnusedElaboratable``) about every Elaboratable that is garbage-collected without having been
elaborated, including one whose constructor raised, and the sub-blocks that constructor had already built.
Wrapping the constructor's work in ``with rejecting(self):`` marks the object and every Elaboratable it holds so
far (its attributes, and the values of dicts, lists and tuples among them; in turn, everything those hold) as
deliberately unused when an exception leaves the block, then lets the exception go on. This is the project's one
way of doing so, and the only place that touches Amaranth's private ``_MustUse__silence`` flag;
``tests/test_rejecting.py`` checks every rejecting constructor.
"""

from contextlib import contextmanager

from amaranth import Elaboratable

__all__ = ["rejecting"]


def _held(obj):
    """The Elaboratables ``obj`` holds directly: its attributes and the values of its dicts, lists and tuples."""
    for value in vars(obj).values():
        values = value.values() if isinstance(value, dict) else value if isinstance(value, (list, tuple)) \
            else (value,)
        yield from (v for v in values if isinstance(v, Elaboratable))


@contextmanager
def rejecting(component):
    try:
        yield
    except BaseException:
        todo, seen = [component], set()
        while todo:
            obj = todo.pop()
            if id(obj) not in seen:
                seen.add(id(obj))
                obj._MustUse__silence = True
                todo.extend(_held(obj))
        raise
