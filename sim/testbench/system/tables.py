"""I2C init tables for whole-system simulations at a reduced sensor size and/or time scale.

The board uses ``hdl.init_tables.MT9D112_TABLE`` (1600 x 1200) as is. A simulation with a small sensor
(``spec.sensor.SMALL_SENSOR``) needs the same table with the output size and crop window of that sensor, and a
short simulation wants the table's waits (1 ms each: sensor boot, PLL lock, MCU command) shortened. This module
derives such tables from the board's table, entry for entry: the same registers in the same order, only

* the values of the context-B output width/height variables (driver 7, offsets 0x07/0x09) and of the crop
  window's X1/Y1 (offsets 0x61/0x65) replaced by the sensor geometry's width and height, and
* every ``Wait`` and every ``Poll`` interval multiplied by ``time_scale`` (at least 1 us),
* with ``quick=True``, only the entries the sensor needs to come up in RGB565 at that size kept (:data:`QUICK`):
  the boot wait, the chip-version check, the output format, width, height and crop-window variables, the
  sequencer's capture mode (video: without it the sensor sends one still frame and returns to preview) and
  "capture" command with its wait and completion poll, and the output enable -- 19 of the table's
  42 entries. The default-run simulations use it (the Amaranth simulator spends about 1 s of
  wall time per 20 us of I2C traffic on this design); the full table runs in the full-size run.

The sensor models must then be given matching timing (``MT9D112Model(boot_s=..., pll_lock_s=...)``):
:func:`model_timing` returns the scaled figures.
"""

from dataclasses import replace

from hdl.init_tables import MT9D112_TABLE, Barrier, InitTable, Poll, Wait, Write
from spec.board import CLOCKS

__all__ = ["mt9d112_table", "model_timing", "SIZE_VARIABLES", "QUICK_VARIABLES"]

_VAR_ADDRESS = 0x338C
_VAR_DATA = 0x3390

#: (driver, offset) of the variables that carry the output size -> "width" or "height".
SIZE_VARIABLES = {(7, 0x07): "width", (7, 0x09): "height", (7, 0x61): "width", (7, 0x65): "height"}


#: Variables kept by ``quick=True``: output format, size, crop X1/Y1 (context B), the capture mode and the
#: sequencer command.
QUICK_VARIABLES = {(7, 0x97), (7, 0x07), (7, 0x09), (7, 0x61), (7, 0x65), (1, 0x20), (1, 0x03)}
_QUICK_REGISTERS = {0x3000, 0x301A}       # chip version poll, output enable


def _scaled(us, time_scale):
    return max(1, round(us * time_scale))


def mt9d112_table(geometry, *, time_scale=1.0, quick=False, base=MT9D112_TABLE):
    """``base`` with the output size of ``geometry`` (``width`` x ``height``), waits scaled by ``time_scale``
    and, with ``quick``, only the essential entries (see the module docstring). Raises ``ValueError`` if
    ``base`` does not set all four size variables."""
    entries = []
    var = None
    found = set()
    waits_seen = 0
    for e in base.entries:
        keep = True
        if isinstance(e, Write) and e.reg == _VAR_ADDRESS:
            var = ((e.value >> 8) & 0x1F, e.value & 0xFF)
            keep = var in QUICK_VARIABLES
        elif isinstance(e, Write) and e.reg == _VAR_DATA:
            keep = var in QUICK_VARIABLES
            if var in SIZE_VARIABLES:
                value = getattr(geometry, SIZE_VARIABLES[var])
                e = replace(e, value=value, comment=f"{e.comment} -> {value} (simulation size)")
                found.add(var)
        elif isinstance(e, Wait):
            waits_seen += 1
            keep = waits_seen == 1 or entries_after_command(entries)
            e = replace(e, us=_scaled(e.us, time_scale))
        elif isinstance(e, Barrier):
            keep = True
        elif isinstance(e, Poll):
            keep = e.reg in _QUICK_REGISTERS or e.reg == _VAR_DATA
            if e.interval_us:
                e = replace(e, interval_us=_scaled(e.interval_us, time_scale))
        else:
            keep = e.reg in _QUICK_REGISTERS
        if keep or not quick:
            entries.append(e)
    missing = set(SIZE_VARIABLES) - found
    if missing:
        raise ValueError(f"the base table does not set the size variables {sorted(missing)}")
    return InitTable(base.device, tuple(entries))


def entries_after_command(entries):
    """True once the sequencer command (variable 1:0x03) has been written: the wait that follows it is kept."""
    return any(isinstance(e, Write) and e.reg == _VAR_ADDRESS and ((e.value >> 8) & 0x1F, e.value & 0xFF)
               == (1, 0x03) for e in entries)


def model_timing(time_scale=1.0):
    """Keyword arguments for ``sim.models.mt9d112.target.MT9D112Model`` matching a table scaled by ``time_scale``:
    the sensor's boot time (7000 MCLK) and PLL lock time (1 ms), scaled the same way."""
    return dict(boot_s=7000 / CLOCKS.CAM_MCLK_HZ * time_scale, pll_lock_s=1e-3 * time_scale)
