"""``ParametricSignature``: the base of the project's parametric ``wiring.Signature`` s (built in ``__init__``).

Amaranth compares signature subclasses by identity unless they say otherwise; a parametric signature here is
equal to another of its class with the same members (so two blocks built with the same widths connect), and shows
its parameters in its ``repr``.
"""

from amaranth.lib import wiring

__all__ = ["ParametricSignature"]


class ParametricSignature(wiring.Signature):
    """``members`` as a signature; ``params`` (keyword arguments) are kept as attributes and shown by ``repr``."""

    def __init__(self, members, **params):
        self._params = params
        for name, value in params.items():
            setattr(self, name, value)
        super().__init__(members)

    def __eq__(self, other):
        return type(other) is type(self) and self.members == other.members

    def __repr__(self):
        args = ", ".join(f"{name}={value!r}" for name, value in self._params.items())
        return f"{type(self).__name__}({args})"
