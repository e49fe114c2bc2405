"""Pipelined minimum trees shared by the path and winner stages: up to four items reduced per clock, every
comparison made from the clock's registers (the second level's choice picked by the first's, not compared after its
selects)."""

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


def _pick(items, choice):
    """``items[choice]`` of one or two (value, index) pairs (``choice`` None for one)."""
    if choice is None:
        return items[0]
    a, b = items
    return (Mux(choice, b[0], a[0]), None if a[1] is None else Mux(choice, b[1], a[1]))


def _min_group(group):
    """The smallest of up to :data:`FAN_IN` (value, index) pairs, the first on ties, as two compare-and-select
    levels would give it: each half's smaller (``_min2``'s tie rule), then the right half's if it is strictly
    smaller -- that last comparison chosen among the comparisons of every right item with every left one, all made
    from the inputs, by the halves' own comparisons."""
    if len(group) <= 2:
        return group[0] if len(group) == 1 else _min2(*group)
    left, right = group[:2], group[2:]
    left_b = left[1][0] < left[0][0]                     # the left half's second item is its smaller
    right_b = right[1][0] < right[0][0] if len(right) == 2 else None
    cross = {(i, j): r[0] < l[0] for i, r in enumerate(right) for j, l in enumerate(left)}
    by_left = [Mux(left_b, cross[i, 1], cross[i, 0]) for i in range(len(right))]
    take_right = by_left[0] if right_b is None else Mux(right_b, by_left[1], by_left[0])
    return _pick([_pick(left, left_b), _pick(right, right_b)], take_right)


def min_tree(m, items, name):
    """Reduce ``items`` [(value, index or None), ...] to the smallest value (the first one on ties), through
    registers in the ``sync`` domain, :data:`FAN_IN` items per clock. Returns the final (value, index)
    signals, :func:`tree_stages` clocks after the items (with no stage at all for a single item)."""
    level = 0
    while len(items) > 1:
        nxt = []
        for i in range(0, len(items), FAN_IN):
            least = _min_group(items[i:i + FAN_IN])
            value = Signal.like(items[0][0], name=f"{name}_v{level}_{i // FAN_IN}", reset_less=True)
            m.d.sync += value.eq(least[0])
            index = None
            if least[1] is not None:
                index = Signal.like(items[0][1], name=f"{name}_i{level}_{i // FAN_IN}", reset_less=True)
                m.d.sync += index.eq(least[1])
            nxt.append((value, index))
        items = nxt
        level += 1
    return items[0]
