"""Golden model of the bring-up: the state the MT9D112 sensors and the CH7301C must end up in, field by field.

Written from the spec and the public references below, never from the RTL or its init tables (this module
imports only ``spec``). Each field is an :class:`Expected` ``(value, source)``. The tests play the tables
into the register-file models (``sim/models/mt9d112/registers.py``, ``sim/models/ch7301c/registers.py``), which decode every
write into the part's state, and compare that state with these fields one by one.

Sources:

* [SPEC] the thesis / spec: two cameras streaming 1600 x 1200 RGB565 continuously (thesis 4.2, spec "Camera
  driver"); the capture takes the R byte (R[4:0] G[5:3]) first (spec, ``hdl/capture.py``); DVI out of the
  CH7301C with the 24-bit pixel as two 12-bit halves, one per XCLK edge (spec "HDMI driver").
* [CAMCTL] Digilent VmodCAM Reference Design 2, ``CamCtl.vhd`` (E. Gyorgy, 2011): Digilent's configuration for
  this camera board, "video capture mode in 1600x1200 @ 80 MHz pixel clock", RGB in context B.
* [MSM] Linux ``drivers/staging/dream/camera/mt9d112.c`` (Qualcomm): MCU reset release, PLL sequence, context-B
  sensor window rows 4..1211 / columns 4..1611, Sensor_Fine_IT_min 361, crop, the snapshot (capture) switch.
* [MT9D111] MT9D111 firmware (same variables), G. Marcelino's driver: captureParams.mode bit 1 = 1 keeps the
  sequencer in capture (video); RGB565 output format 0x20.
* [CEA] CEA-861 1080p60: positive hsync and vsync.
* [POC] VLSI-EDA PoC ``vga_phy_ch7301c`` (Xilinx ML505, a Virtex-5 board with the same CH7301C wiring), [XORG]
  Linux/Xorg ``ch7xxx`` drivers: 0x49 = 0xC0 (DVI on), IDF 0 with bit 7 set, the "> 65 MHz" DVI PLL setting.
"""

from typing import NamedTuple

from spec.sensor import SENSOR
from spec.video import CEA_1080P60

__all__ = ["Expected", "mt9d112_expected", "ch7301c_expected", "PCLK_HZ"]

#: The sensors' pixel clock: [CAMCTL] "1600x1200 @ 80 MHz pixel clock" (from the 24 MHz MCLK).
PCLK_HZ = 80_000_000

_SPEC = "thesis 4.2 / spec 'Camera driver'"
_CAMCTL = "Digilent VmodCAM reference design CamCtl.vhd"
_MSM = "Linux staging/dream/camera/mt9d112.c"
_MT9D111 = "MT9D111 firmware (G. Marcelino's driver: captureParams.mode[1])"


class Expected(NamedTuple):
    value: object
    source: str


def mt9d112_expected(geometry=SENSOR):
    """The state each MT9D112 must be in once configured, for an output of ``geometry.width`` x
    ``geometry.height`` (the board: 1600 x 1200; simulations use the same configuration at a smaller size)."""
    w, h = geometry.width, geometry.height
    return {
        "mcu_running": Expected(True, f"{_MSM} 'Pull MCU from Reset - Start MCU'; {_CAMCTL}"),
        "pll_enabled": Expected(True, f"{_MSM} PLL setup ends with bypass off; {_CAMCTL}"),
        "pclk_hz": Expected(PCLK_HZ, f"{_CAMCTL} '1600x1200 @ 80 MHz pixel clock'"),
        "standby": Expected(False, f"{_CAMCTL} 'wake up'; {_MSM} probe"),
        "slew_pclk": Expected(5, f"{_CAMCTL} 'slew rate PCLK 5'"),
        "slew_data": Expected(5, f"{_CAMCTL} 'slew rate D 5'"),
        "context": Expected("B", f"{_CAMCTL} (context B = capture, full size); {_SPEC}"),
        "sequencer_state": Expected("capture", f"{_MSM} snapshot switch; {_CAMCTL}"),
        "capture_video": Expected(True, f"{_MT9D111}; {_SPEC} (continuous frames, 15 fps)"),
        "capture_options": Expected(0xF, f"{_CAMCTL} comment 'AWB, AE, HG on'"),
        "output_width": Expected(w, _SPEC),
        "output_height": Expected(h, _SPEC),
        "output_format": Expected("rgb565", f"{_SPEC}; {_MT9D111} RGB565 = 0x20; OMAP sensor_mt9d112.c bit 5"),
        "r_byte_first": Expected(True, f"{_SPEC} (the capture path's byte order); {_CAMCTL} first byte -> D[15:8]"),
        "rb_swapped": Expected(False, _SPEC),
        "bt656_codes": Expected(True, f"{_CAMCTL} comment 'RGB with BT656 codes'"),
        "parallel_output": Expected(True, f"{_CAMCTL}; {_MSM} (0x301A output bits)"),
        "sensor_rows": Expected((4, 1211), f"{_MSM} Row Start(S) 4, Row End(S) 1211; {_CAMCTL}"),
        "sensor_cols": Expected((4, 1611), f"{_MSM} Column Start(S) 4, Column End(S) 1611; {_CAMCTL}"),
        "crop": Expected((0, 0, w, h), f"{_MSM} Crop_X0/Y0(S) 0, X1/Y1(S) the output size; {_CAMCTL}"),
        "fine_it_min": Expected(361, f"{_MSM} Sensor_Fine_IT_min 361; {_CAMCTL}"),
    }


def ch7301c_expected(timing=CEA_1080P60):
    """The CH7301C's mode for the display of ``timing``: DVI on, the 12-bit dual-edge RGB input, the mode's
    sync polarities, the DVI PLL setting of its pixel clock (the references split at 65 MHz)."""
    return {
        "full_power_down": Expected(False, "POC / XORG 0x49 = 0xC0"),
        "dvi_output": Expected(True, "POC / XORG 0x49 = 0xC0 (DVIP, DVIL)"),
        "dac_powered_down": Expected(False, "POC 0x49 = 0xC0 (DAC power-down bits clear)"),
        "input_format": Expected("12-bit multiplexed RGB 8:8:8, both XCLK edges",
                                 "spec 'HDMI driver'; POC IDF 0; Xilinx xps_tft"),
        "hsync_positive": Expected(timing.hsync_positive, "CEA-861 1080p60 (the mode's polarity)"),
        "vsync_positive": Expected(timing.vsync_positive, "CEA-861 1080p60 (the mode's polarity)"),
        "idf_bit7": Expected(True, "POC 0x1F = 0x80 / 0x90"),
        "dvi_pll": Expected("> 65 MHz" if timing.pixel_hz > 65_000_000 else "<= 65 MHz",
                            "POC, XORG dvo_ch7xxx, Xilinx iic_init.v: TPCP/TPD/TPF by pixel clock"),
    }
