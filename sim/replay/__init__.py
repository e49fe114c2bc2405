"""Inside-the-simulator replays: ``sensor.py`` (a camera's stream packed once and replayed from a Verilog module or
an Amaranth ROM: no Python per PCLK), ``pins.py`` (the CH7301C pins recorded in the simulator and read back).

May import: ``spec``, ``hdl``, ``sim.models``.
"""
