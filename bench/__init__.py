"""Benchmarks. Each ``bench/bench_<topic>.py`` has a ``main()`` that runs it and prints its figures.

``python -m bench`` runs them all; ``python -m bench display`` (or ``bench_display``) runs the named ones.
Figures are wall-clock rates on whatever machine runs them: on a shared or loaded machine they are low.
"""
