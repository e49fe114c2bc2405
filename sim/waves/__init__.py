"""Waveform tooling: ``gtkw.py`` (GTKWave save files: first view, markers, decoded buses), ``fsm_filters.py``
(translate filters for the state machines), ``i2c_filter.py`` (an I2C transaction filter), ``gtkwave_check.py``
(GTKWave itself, headless, lists what a save file shows), ``cocotb.py`` (the save file of a cocotb run).

May import: ``spec``, ``hdl``.
"""
