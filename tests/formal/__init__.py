"""Formal harnesses of the blocks (``sim.formal``): ``python -m tests.formal`` (``make formal``) proves them all."""
