"""The parts around the FPGA, in simulation: one sub-package per part, each with a pure-Python core (samples in,
samples out) and thin drivers for Amaranth's simulator and for cocotb, so both simulators run the same model.

==================  ====================================================================================
package             what
==================  ====================================================================================
``mt9d112``         the camera: video output, register file and firmware variables, I2C target, output
                    configuration
``ch7301c``         the DVI transmitter: register file, I2C target, the HDMI sink that reads its pins
``i2c``             the open-drain bus, the target state machine, the UM10204 bus monitor, the table player
``mig``             MIG's DDR2 user interface with the memory behind it (``MIGModel``): gateware for
                    simulation only, not a Python core (docs/memory.md)
``clocking``        the board clocking's simulation model (``SimClocking``)
==================  ====================================================================================

May import: ``spec``, ``hdl`` (signatures, the reset tree), ``golden`` (image helpers, the parts' expected state),
``sim.waves`` (wave markers), the ``sim`` exceptions.
"""
