"""Pipelined minimum trees shared by the path and winner stages: at most two compare-and-select levels per clock."""

from amaranth import Mux, Signal

__all__ = ["tree_stages", "min_tree"]

FAN_IN = 4      # inputs reduced per clock: two levels of 2-input compare-and-select


def tree_stages(n):
    """Clocks :func:`min_tree` takes for ``n`` inputs."""
    stages = 0
    while n > 1:
        n = (n + FAN_IN - 1) // FAN_IN
        stages += 1
    return stages


def _min2(a, b):
    """The smaller of two (value, index) pairs; ``a`` (the lower index) wins a tie."""
    take_b = b[0] < a[0]
    return (Mux(take_b, b[0], a[0]), None if a[1] is None else Mux(take_b, b[1], a[1]))


def min_tree(m, items, name):
    """Reduce ``items`` [(value, index or None), ...] to the smallest value (the first one on ties), through
    registers in the ``sync`` domain, :data:`FAN_IN` items per clock. Returns the final (value, index)
    signals, :func:`tree_stages` clocks after the items (with no stage at all for a single item)."""
    level = 0
    while len(items) > 1:
        nxt = []
        for i in range(0, len(items), FAN_IN):
            group = items[i:i + FAN_IN]
            while len(group) > 1:
                group = [_min2(group[j], group[j + 1]) if j + 1 < len(group) else group[j]
                         for j in range(0, len(group), 2)]
            value = Signal.like(items[0][0], name=f"{name}_v{level}_{i // FAN_IN}", reset_less=True)
            m.d.sync += value.eq(group[0][0])
            index = None
            if group[0][1] is not None:
                index = Signal.like(items[0][1], name=f"{name}_i{level}_{i // FAN_IN}", reset_less=True)
                m.d.sync += index.eq(group[0][1])
            nxt.append((value, index))
        items = nxt
        level += 1
    return items[0]
