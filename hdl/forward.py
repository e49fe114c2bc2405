"""``forward(component, path, obj)``: a wrapper's member *is* its child's interface, not a copy of it.

A component that passes a child's interface (or a single port) straight through would normally declare its own
member and connect it to the child's (``wiring.connect(m, wiring.flipped(self.x), child.x)``). That makes a second
set of signals with the same names in the wrapper's module, which the Verilog export and the VCD writer tell apart
with ``$N`` suffixes (``cam_a__data$43``). Forwarding instead makes the member the child's own object: the same
signals, one name, nothing to connect, and an exported top whose ports are the child's signals.

The object must comply with the member's description (same signature and flow for an interface member, same
shape and initial value for a port member); this is checked. Forward in ``__init__``, after
``super().__init__()`` has created the member.

The forwarded signals are renamed after the member they now are (``board.export.flat_name`` of its path in
``component``): forwarded again by the parent, they take the parent's name, so each signal ends up named as the
outermost component presents it -- in the exported top and, as the same signal, in every module below it. Two
children whose signals had the same names (three I2C buses' ``drive_high``) then no longer collide.
"""

from amaranth.hdl import Signal, Value

__all__ = ["forward"]


def forward(component, path, obj):
    """Make ``obj`` the member at ``path`` (a name, or a tuple of names into nested interfaces) of
    ``component``. Raises ``TypeError`` when ``obj`` does not match the member's description."""
    path = (path,) if isinstance(path, str) else tuple(path)
    description, parent = component.signature, component
    for name in path[:-1]:
        description = description.members[name].signature
        parent = getattr(parent, name)
    member = description.members[path[-1]]
    reasons = []
    if member.is_signature:
        ok = member.signature.is_compliant(obj, reasons=reasons, path=path)
    else:
        value, model = Value.cast(obj), Signal(member.shape, init=member.init)
        ok = isinstance(value, Signal) and value.shape() == model.shape() and value.init == model.init
        reasons.append(f"{'.'.join(path)} is {value!r}, the member is {member!r}")
    if not ok:
        raise TypeError(f"cannot forward {obj!r} as {type(component).__name__}.{'.'.join(path)}: "
                        + "; ".join(reasons))
    setattr(parent, path[-1], obj)
    _rename(member, obj, path)


def _rename(member, obj, path):
    if member.is_port:
        Value.cast(obj).name = "__".join(path)
        return
    for sub_path, _, value in member.signature.flatten(obj):
        Value.cast(value).name = "__".join(map(str, path + sub_path))
