"""The board's clocks and I2C bus addresses (thesis table 4.1, spec "Clocks"; docs/hardware-facts.md gives the
parts' sources)."""

__all__ = ["CLOCKS", "I2C_ADDR", "RESET_MAX_LOADS"]


class CLOCKS:
    """Clock frequencies in Hz. The thesis writes 148.25 MHz; CEA-861 1080p60 is 148.5 MHz (spec)."""
    SYS_HZ = 100_000_000        # Genesys oscillator, "sync" domain (I2C masters, switch synchronisers' source)
    CAM_MCLK_HZ = 24_000_000    # MCLK to both MT9D112 sensors (PLL_ADV: 100 MHz x 6 / 25; board/clocking.py)
    CAM_PCLK_HZ = 80_000_000    # each sensor's PCLK as the MT9D112 init table programs it (24 MHz x 80 / 3 / 8;
                                # Digilent's CamCtl: "1600x1200 @ 80 MHz pixel clock"): the cam_a/cam_b domains
    PIXEL_HZ = 148_500_000      # "pix" domain: sync generator, frame-buffer read ports, disparity, compositor
    I2C_HZ = 100_000            # I2C standard mode


class I2C_ADDR:
    """7-bit I2C addresses (docs/hardware-facts.md gives the sources)."""
    MT9D112 = 0x3C   # 0x78 as an 8-bit write address; each camera has its own bus on the VmodCAM
    CH7301C = 0x76   # AS strap dependent (0x75 or 0x76): see docs/hardware-facts.md


#: The most loads any reset net of the board design may drive (the registered reset tree, hdl/reset_tree.py; a
#: design target for a 6.7 ns period, not a device figure).
RESET_MAX_LOADS = 500
