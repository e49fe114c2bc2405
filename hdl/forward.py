"""``forward(owner, path, child, child_path)``: a child's member *is* its owner's member, not a copy of it.

A component that passes a child's interface (or a single port) straight through would normally connect its own
member to the child's (``wiring.connect(m, wiring.flipped(self.x), child.x)``). That makes a second set of
signals with the same names, which the Verilog export and the VCD writer tell apart with ``$N`` suffixes
(``cam_a__data$43``). Forwarding instead hands the owner's member down: the child's member at ``child_path``
becomes the owner's member object at ``path``, whose signals the owner's ``super().__init__()`` created and named
after the owner's signature (``cam_a__data``). One set of signals, nothing to connect, and no signal renamed.

The owner's member may itself be forwarded from further up (the owner is a grandparent's child): the
grandparent's object then replaces it in the owner and in every component the owner forwarded it to, at any
depth (``forward`` keeps, per owner, the links it made). So each component forwards in its own ``__init__``, after
``super().__init__()``, in any order, and the outermost component's signals reach the innermost child: in the
exported top and in every module below it, a forwarded signal carries the top's name.

When the two members' flows differ (the owner's is ``In``, the child's ``Out``: two siblings, one driving the
other), the child gets the owner's object flipped (``wiring.flipped``). A child reads its members through
``self.<name>`` when it elaborates; an object taken from a member before it was forwarded is not updated.
"""

import weakref

from amaranth.hdl import Signal, Value
from amaranth.lib import wiring

__all__ = ["forward"]

# owner -> [(path in owner, child, path in child, flipped)], one entry per forward() call
_links = weakref.WeakKeyDictionary()


def forward(owner, path, child, child_path=None):
    """Make ``child``'s member at ``child_path`` the object of ``owner``'s member at ``path``.

    Parameters
    ----------
    owner : wiring.Component
        Whose member object is handed down (its signals keep the names ``owner``'s signature gave them).
    path : str or tuple of str
        The member of ``owner``: a name, or names into nested interfaces (``("capture", "cam_a")``).
    child : wiring.Component
        Whose member is replaced: by the owner's object, or by it flipped where the two members' flows differ.
    child_path : str or tuple of str, optional
        The member of ``child``; by default the last name of ``path``. ``()`` stands for all of ``child``'s
        members (``owner``'s member then has ``child``'s signature).

    Raises
    ------
    TypeError
        A path names no member, or the owner's object does not match the child's member (same signature, for an
        interface; for a port, a signal of the same shape and initial value).
    """
    path = _as_path(path)
    child_path = path[-1:] if child_path is None else _as_path(child_path)
    flip = _member(owner, path).flow != _member(child, child_path).flow
    obj = _view(_get(owner, path), flip)
    _place(child, child_path, obj, f"{type(owner).__name__}.{_dotted(path)}")
    _links.setdefault(owner, []).append((path, child, child_path, flip))


def _as_path(path):
    return (path,) if isinstance(path, str) else tuple(path)


def _dotted(path):
    return ".".join(path) or "(all members)"


def _member(component, path):
    """The description of ``component``'s member at ``path``, its flow seen from ``component``."""
    member = wiring.Out(component.signature)
    for depth, name in enumerate(path):
        if not member.is_signature or name not in member.signature.members:
            raise TypeError(f"{type(component).__name__} has no member {_dotted(path[:depth + 1])}")
        member = member.signature.members[name]
    return member


def _get(obj, path):
    for name in path:
        obj = getattr(obj, name)
    return obj


def _view(obj, flip):
    return wiring.flipped(obj) if flip and hasattr(obj, "signature") else obj


def _check(component, path, obj, source):
    member = _member(component, path)
    where = f"{type(component).__name__}.{_dotted(path)}"
    reasons = []
    if member.is_signature:
        ok = member.signature.is_compliant(obj, reasons=reasons, path=path or ("obj",))
    else:
        try:
            value = Value.cast(obj)
        except TypeError:
            value = None
        model = Value.cast(Signal(member.shape, init=member.init, name="model"))
        ok = isinstance(value, Signal) and value.shape() == model.shape() and value.init == model.init
        found = f"{value.shape()}, init={value.init}" if isinstance(value, Signal) else type(obj).__name__
        reasons.append(f"{source} is {obj!r} ({found}), the member is {member!r}")
    if not ok:
        raise TypeError(f"cannot forward {source} to {where}: " + "; ".join(reasons))


def _place(component, path, obj, source):
    """Set ``component``'s member at ``path`` to ``obj`` and pass it on along ``component``'s own links."""
    _check(component, path, obj, source)
    if path:
        setattr(_get(component, path[:-1]), path[-1], obj)
    else:
        for name in component.signature.members:
            setattr(component, name, getattr(obj, name))
    for link_path, child, child_path, flip in _links.get(component, ()):
        if link_path[:len(path)] == path:          # the link's member is the replaced one, or inside it
            _place(child, child_path, _view(_get(obj, link_path[len(path):]), flip), source)
        elif path[:len(link_path)] == link_path:   # the replaced member is inside the link's member
            _place(child, child_path + path[len(link_path):], _view(obj, flip), source)
