"""The MT9D112 init table at a sensor geometry's output size: a design fact.

The sensors must send the frame the capture path downscales into its buffers: a design whose
:class:`spec.sensor.SensorGeometry` is not the board's 1600 x 1200 (the small design the default test run
simulates, ``spec.sensor.SMALL_SENSOR``) programs the sensors to that output size. :func:`sized_mt9d112_table`
derives that table from the board's ``hdl.init_tables.MT9D112_TABLE`` entry for entry: the same registers in
the same order, only the values of the context-B output width/height variables (driver 7, offsets 0x07/0x09) and
of the crop window's X1/Y1 (offsets 0x61/0x65) replaced by the geometry's width and height. At the board's
size it is ``MT9D112_TABLE`` itself.

Shortening the table's waits and dropping entries a sensor model does not need are simulation speed-ups, not
design facts: ``sim/testbench/system/tables.py``.
"""

from dataclasses import replace

from hdl.init_tables import MT9D112_TABLE, InitTable, Write

__all__ = ["VAR_ADDRESS", "VAR_DATA", "SIZE_VARIABLES", "variable", "sized_mt9d112_table"]

#: The MT9D112's variable-address register: written with the variable a following ``VAR_DATA`` access means.
VAR_ADDRESS = 0x338C
#: The MT9D112's variable-data register.
VAR_DATA = 0x3390

#: (driver, offset) of the variables that carry the output size -> "width" or "height".
SIZE_VARIABLES = {(7, 0x07): "width", (7, 0x09): "height", (7, 0x61): "width", (7, 0x65): "height"}


def variable(value):
    """The ``(driver, offset)`` a ``VAR_ADDRESS`` write of ``value`` selects (bits 12:8 and 7:0)."""
    return (value >> 8) & 0x1F, value & 0xFF


def sized_mt9d112_table(geometry, *, base=MT9D112_TABLE):
    """``base`` programming the output size ``geometry.width`` x ``geometry.height`` (see the module docstring).

    Parameters
    ----------
    geometry : :class:`spec.sensor.SensorGeometry`
    base : :class:`hdl.init_tables.InitTable`
        An MT9D112 table that sets the four size variables.

    Raises
    ------
    ValueError
        ``base`` does not set all four size variables.
    """
    entries = []
    var = None
    found = set()
    for e in base.entries:
        if isinstance(e, Write) and e.reg == VAR_ADDRESS:
            var = variable(e.value)
        elif isinstance(e, Write) and e.reg == VAR_DATA and var in SIZE_VARIABLES:
            value = getattr(geometry, SIZE_VARIABLES[var])
            if value != e.value:
                e = replace(e, value=value, comment=f"{e.comment} -> {value} (output size)")
            found.add(var)
        entries.append(e)
    missing = set(SIZE_VARIABLES) - found
    if missing:
        raise ValueError(f"the base table does not set the size variables {sorted(missing)}")
    if tuple(entries) == base.entries:
        return base
    return InitTable(base.device, tuple(entries))
