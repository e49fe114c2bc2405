"""The I2C bus in simulation: ``bus.py`` (the open-drain bus around a design and the glue that runs targets on it in
Amaranth's simulator and in cocotb), ``target.py`` (the bit-level target and register framing the parts build on),
``monitor.py`` (UM10204 timing and decoding from the two lines), ``table.py`` (an init table as bus traffic)."""
