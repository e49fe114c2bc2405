"""Per-domain resets and their fanout.

``add_reset_tree(m, domains, arst)``: per-domain resets, asserted asynchronously, released synchronously. The board
clocking (:class:`board.clocking.GenesysClocking`) and its simulation model
(:class:`sim.models.clocking.SimClocking`) build the same tree with it.

``add_reset_subtree(m, name, block)``: a branch of a domain's registered reset tree. The block's registers are also
reset by a registered copy of the domain's reset (``ResetInserter``); synthesis folds the domain reset and the
copy into one reset net per branch (a two-input OR in front of the branch's reset pins), so the domain's reset
itself drives only the branches' ORs and copies, and each branch's net only that branch's registers. Every
branch's registers are released one clock after the domain's reset, whatever its depth (each copy is one
register behind the domain's reset itself, not behind its parent's copy).
"""

from amaranth import ResetInserter, ResetSignal, Signal
from amaranth.lib.cdc import ResetSynchronizer

__all__ = ["add_reset_tree", "add_reset_subtree", "RESET_COPY_ATTRS"]

#: Attributes of every reset copy: the XST User Guide's EQUIVALENT_REGISTER_REMOVAL (the copies are equivalent
#: registers by design; XST would merge them back into one), and ``keep`` for Yosys (``opt_merge``), which
#: board/export.py removes from the board's ``top.v``.
RESET_COPY_ATTRS = {"EQUIVALENT_REGISTER_REMOVAL": "no", "keep": "true"}


def add_reset_tree(m, domains, arst):
    """Give each domain in ``domains`` a reset asserted asynchronously by ``arst`` and released synchronously."""
    for domain in domains:
        m.submodules[f"rst_sync_{domain}"] = ResetSynchronizer(arst, domain=domain)


def add_reset_subtree(m, name, block, domain="sync"):
    """Add ``block`` to ``m`` as submodule ``name``, its registers also reset by a registered copy of ``domain``'s
    reset (the copy ``<name>_rst``, ``domain``, reset-less, starts at 1).

    Latency: the block leaves reset one ``domain`` clock after the domain's reset falls; it enters reset with it.
    Returns ``block``.
    """
    copy = Signal(init=1, reset_less=True, name=f"{name}_rst", attrs=RESET_COPY_ATTRS)
    m.d[domain] += copy.eq(ResetSignal(domain))
    m.submodules[name] = ResetInserter({domain: copy})(block)
    return block
