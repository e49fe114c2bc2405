"""What the I2C bring-up must put on the buses and what the parts must end up configured to: the expectations the
I2C and whole-system tests check the RTL against.

The write and read lists are derived from the RTL's own tables (``hdl/init_tables.py``), so they check that the
sequencer plays its table faithfully, not that the table is right; that is why they live here in ``sim/`` and not in
``golden/`` (a golden model is written from the spec, never from the RTL). Issue 17 replaces them by a sensor and
transmitter state written from the data sheets in ``golden/``, against which the register-file models' decoded
state is checked.

* :func:`expected_writes`: the ordered ``(device, register, value)`` writes a table must put on the bus (its
  ``Write`` entries, in table order; ``Wait``/``Poll`` entries write nothing).
* :func:`expected_reads`: the registers read, in order, assuming each poll matches on its first read.
* :func:`expected_prefix`: the writes that must have completed when a table stops at a given entry.
* :func:`expected_sensor_config`: the camera configuration the spec asks for (thesis 4.2 / spec "Camera driver":
  1600 x 1200, RGB565, R byte first).
* :func:`expected_dvi_config`: the CH7301C configuration the display path needs for a video mode (spec "HDMI
  driver": DVI, the 12-bit dual-edge multiplexed RGB input, the mode's sync polarities, the DVI PLL range of
  its pixel clock: the references' split at 65 MHz).
"""

from hdl.init_tables import InitTable, Poll, Write
from hdl.params import CEA_1080P60, SENSOR
from sim.i2c_devices import DviConfig
from sim.sensor_config import SensorConfig

__all__ = ["expected_writes", "expected_reads", "expected_prefix", "expected_sensor_config",
           "expected_dvi_config"]


def expected_writes(*tables):
    """``[(device name, register, value), ...]`` for the tables in the order given."""
    out = []
    for table in tables:
        if not isinstance(table, InitTable):
            raise TypeError("expected InitTable arguments")
        out += [(table.device.name, e.reg, e.value) for e in table.entries if isinstance(e, Write)]
    return out


def expected_reads(table):
    """``[(device name, register), ...]`` read by the table's polls (one read each when they match at once)."""
    return [(table.device.name, e.reg) for e in table.entries if isinstance(e, Poll)]


def expected_prefix(table, entry):
    """The writes a table completes before entry number ``entry`` (when it stops there)."""
    return expected_writes(InitTable(table.device, table.entries[:entry])) if entry else []


def expected_sensor_config(geometry=SENSOR):
    """The spec's camera output: the sensor's full size (1600 x 1200), RGB565, the R byte first."""
    return SensorConfig(width=geometry.width, height=geometry.height, rgb565=True, r_byte_first=True)


def expected_dvi_config(timing=CEA_1080P60):
    """DVI on, IDF 0 (12-bit multiplexed RGB on both XCLK edges), the mode's polarities, PLL range by clock."""
    return DviConfig(dvi_on=True, idf=0, hsync_positive=timing.hsync_positive,
                     vsync_positive=timing.vsync_positive,
                     pll_range="high" if timing.pixel_hz > 65_000_000 else "low")
