"""``add_reset_tree(m, domains, arst)``: per-domain resets, asserted asynchronously, released synchronously.

The board clocking (:class:`board.clocking.GenesysClocking`) and its simulation model
(:class:`sim.models.clocking.SimClocking`) build the same tree with it.
"""

from amaranth.lib.cdc import ResetSynchronizer

__all__ = ["add_reset_tree"]


def add_reset_tree(m, domains, arst):
    """Give each domain in ``domains`` a reset asserted asynchronously by ``arst`` and released synchronously."""
    for domain in domains:
        m.submodules[f"rst_sync_{domain}"] = ResetSynchronizer(arst, domain=domain)
