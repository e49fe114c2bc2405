"""Verilog export: flat port names, and Amaranth's Verilog with compact memory initialisation.

Flat names. Interfaces are nested ``amaranth.lib.wiring`` signatures; flat names exist only where a tool needs them
(the exported top's ports, which cocotb reaches by name, and the board's IO buffers). There is one rule, Amaranth's
own for Verilog export: the member at path ``(a, b, c)`` is the port ``a__b__c`` (:func:`flat_name`;
``StereoDepthSystem``'s ``cam_a.data`` is ``cam_a__data``, ``i2c.dvi.scl.oe`` is ``i2c__dvi__scl__oe``).
:func:`flat_ports` lists a component's ports by that rule.

Export. :func:`export_verilog` is :func:`amaranth_verilog` with every uniform, complete memory ``initial`` block
written as a loop (:func:`board.memory_init.compact_memory_init`, where the rewrite and its limits are described): a
400 x 300 frame buffer's 120,000 per-word lines per bit memory make Verilator and Icarus slow. Equivalence is
tested in ``tests/test_capture.py`` and by the cocotb capture tests, which read a whole buffer back as zeros after
reset and as the golden image after a capture, on the compact export. The board's ``top.v`` leaves zero
initialisation out instead (:func:`board.memory_init.strip_zero_memory_init`, ``board/genesys.py``).
"""

from board.memory_init import compact_memory_init

__all__ = ["flat_name", "flat_ports", "amaranth_verilog", "export_verilog", "compact_memory_init"]


def flat_name(path):
    """The flat name of the member at ``path`` (a tuple of names and indices): ``"__".join(path)``."""
    return "__".join(str(part) for part in path)


def flat_ports(component):
    """``{flat name: signal}`` for every port of ``component``'s signature, as the exported top names them."""
    return {flat_name(path): value for path, _, value in component.signature.flatten(component)}


def amaranth_verilog(component, name, ports=None):
    """Amaranth's own Verilog for ``component`` (top-level module ``name``; a ``wiring.Component`` needs no
    ``ports``), without source locations."""
    # imported here: the cocotb test processes import this module for flat_name alone, and importing Amaranth
    # inside a simulator costs them about 0.3 s each
    from amaranth.back import verilog as _verilog
    if ports is None:
        return _verilog.convert(component, name=name, emit_src=False)
    return _verilog.convert(component, name=name, ports=ports, emit_src=False)


def export_verilog(component, name, ports=None):
    """:func:`amaranth_verilog` with compact memory initialisation. Pass the text to
    ``sim.runners.cocotb.run_cocotb`` as its ``design``."""
    text, _ = compact_memory_init(amaranth_verilog(component, name, ports))
    return text
