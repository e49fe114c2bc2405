"""The MT9D112 output configuration that the sensor model obeys.

The I2C register-file model of the MT9D112 (``sim/i2c_devices.py``) derives one of these from the registers
the RTL wrote; the sensor model (``sim/mt9d112.py``) produces pixels only when ``rgb565`` is set. Tests of
the capture path that do not exercise I2C build one directly.
"""

from dataclasses import dataclass

__all__ = ["SensorConfig"]


@dataclass(frozen=True)
class SensorConfig:
    width: int = 1600            # output columns
    height: int = 1200           # output rows
    rgb565: bool = True          # output format RGB565 (False: the sensor's power-on YUV / not configured)
    r_byte_first: bool = True    # first byte of a pixel is R[4:0]G[5:3] (False: G[2:0]B[4:0] first)
