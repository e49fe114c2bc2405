"""Formal safety properties of the blocks: the runner (``runner.py``: named Assert/Assume/Cover harnesses proven
with Yosys/ABC, covers searched, traces replayed into VCDs), its proof engines (``engines.py``), one harness per
block (``harnesses/``) and the registry of what ``python -m sim.formal`` (``make formal``) proves.

May import: ``spec``, ``hdl``, ``sim.runners``.
"""
