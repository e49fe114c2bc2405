"""The MT9D112 init table of a whole-system simulation: the design's table with the simulation's speed-ups.

The output size the table programs is a design fact: ``hdl.sensor_table.sized_mt9d112_table`` gives the board's
``hdl.init_tables.MT9D112_TABLE`` at a sensor geometry's size, and ``hdl.config.DesignConfig`` holds it. Two
changes on top of it are simulation speed-ups, valid only against the sensor models, never on a board:

* every ``Wait`` and every ``Poll`` interval multiplied by ``time_scale`` (at least 1 us); the sensor models then
  boot and lock their PLL as much faster (:func:`model_timing`), a real MT9D112 does not;
* with ``quick=True``, only the entries the sensor needs to come up in RGB565 at that size kept (:data:`QUICK_VARIABLES`):
  the boot wait, the chip-version check, the output format, width, height and crop-window variables, the
  sequencer's capture mode (video: without it the sensor sends one still frame and returns to preview) and
  "capture" command with its wait and completion poll, and the output enable -- 19 of the table's
  42 entries (the model needs no PLL, slew-rate or standby settings; a real sensor does). The default-run
  simulations use it (the Amaranth simulator spends about 1 s of wall time per 20 us of I2C traffic on this
  design); the full table runs in the full-size run and the board top's small run.

``sim.testbench.system.setup.SystemSetup`` applies them (its ``time_scale`` and ``quick_table``) to its design's
table.
"""

from dataclasses import replace

from hdl.init_tables import MT9D112_TABLE, Barrier, InitTable, Poll, Wait, Write
from hdl.sensor_table import SIZE_VARIABLES, VAR_ADDRESS, VAR_DATA, sized_mt9d112_table, variable
from spec.board import CLOCKS

__all__ = ["mt9d112_table", "model_timing", "SIZE_VARIABLES", "QUICK_VARIABLES"]

#: Variables kept by ``quick=True``: output format, size, crop X1/Y1 (context B), the capture mode and the
#: sequencer command.
QUICK_VARIABLES = {(7, 0x97), (7, 0x07), (7, 0x09), (7, 0x61), (7, 0x65), (1, 0x20), (1, 0x03)}
_QUICK_REGISTERS = {0x3000, 0x301A}       # chip version poll, output enable


def _scaled(us, time_scale):
    return max(1, round(us * time_scale))


def mt9d112_table(geometry, *, time_scale=1.0, quick=False, base=MT9D112_TABLE):
    """``base`` with the output size of ``geometry`` (``hdl.sensor_table.sized_mt9d112_table``), waits scaled by
    ``time_scale`` and, with ``quick``, only the essential entries (see the module docstring). Raises
    ``ValueError`` if ``base`` does not set all four size variables."""
    sized = sized_mt9d112_table(geometry, base=base)
    if time_scale == 1.0 and not quick:
        return sized
    entries = []
    var = None
    waits_seen = 0
    for e in sized.entries:
        keep = True
        if isinstance(e, Write) and e.reg == VAR_ADDRESS:
            var = variable(e.value)
            keep = var in QUICK_VARIABLES
        elif isinstance(e, Write) and e.reg == VAR_DATA:
            keep = var in QUICK_VARIABLES
        elif isinstance(e, Wait):
            waits_seen += 1
            keep = waits_seen == 1 or entries_after_command(entries)
            e = replace(e, us=_scaled(e.us, time_scale))
        elif isinstance(e, Barrier):
            keep = True
        elif isinstance(e, Poll):
            keep = e.reg in _QUICK_REGISTERS or e.reg == VAR_DATA
            if e.interval_us:
                e = replace(e, interval_us=_scaled(e.interval_us, time_scale))
        else:
            keep = e.reg in _QUICK_REGISTERS
        if keep or not quick:
            entries.append(e)
    return InitTable(sized.device, tuple(entries))


def entries_after_command(entries):
    """True once the sequencer command (variable 1:0x03) has been written: the wait that follows it is kept."""
    return any(isinstance(e, Write) and e.reg == VAR_ADDRESS and variable(e.value) == (1, 0x03) for e in entries)


def model_timing(time_scale=1.0):
    """Keyword arguments for ``sim.models.mt9d112.target.MT9D112Model`` matching a table scaled by ``time_scale``:
    the sensor's boot time (7000 MCLK) and PLL lock time (1 ms), scaled the same way."""
    return dict(boot_s=7000 / CLOCKS.CAM_MCLK_HZ * time_scale, pll_lock_s=1e-3 * time_scale)
