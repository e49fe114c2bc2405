"""The thesis's test bed (section 4.6): ``experiment.py`` (table 4.2 and figure 4.35 as a repeatable experiment) and
``scene.py`` (synthetic scenes seen by the VmodCAM's two pinhole cameras, with exact truth at any offset).

May import: ``spec``, ``hdl``, ``golden``, ``sim.runners``, ``sim.testbench``.
"""
