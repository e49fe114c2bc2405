"""The MT9D112 output configuration that the sensor model obeys.

The I2C register-file model of the MT9D112 (``sim/models/{i2c,mt9d112,ch7301c}/``) derives one of these from the registers
the RTL wrote; the sensor model (``sim/models/mt9d112/sensor.py``) produces pixels only when ``rgb565`` is set. Tests of
the capture path that do not exercise I2C build one directly, or take the spec's with
:func:`expected_sensor_config`.
"""

from dataclasses import dataclass

__all__ = ["SensorConfig", "expected_sensor_config"]


@dataclass(frozen=True)
class SensorConfig:
    width: int = 1600            # output columns
    height: int = 1200           # output rows
    rgb565: bool = True          # output format RGB565 (False: the sensor's power-on YUV / not configured)
    r_byte_first: bool = True    # first byte of a pixel is R[4:0]G[5:3] (False: G[2:0]B[4:0] first)


def expected_sensor_config(geometry=None):
    """The output the golden sensor state (``golden.part_config.mt9d112_expected``) describes."""
    from golden.part_config import mt9d112_expected
    from spec.sensor import SENSOR
    g = mt9d112_expected(geometry or SENSOR)
    return SensorConfig(width=g["output_width"].value, height=g["output_height"].value,
                        rgb565=g["output_format"].value == "rgb565" and not g["rb_swapped"].value,
                        r_byte_first=g["r_byte_first"].value)
