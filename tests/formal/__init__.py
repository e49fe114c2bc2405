"""Tests of the formal harnesses (``sim.formal.harnesses``): every proof passes (``test_proofs.py``) and every
harness catches its mutant (``test_bites.py``)."""
