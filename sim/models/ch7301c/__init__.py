"""The Chrontel CH7301C DVI transmitter: ``registers.py`` (what each register the init table writes does),
``target.py`` (the register file on the I2C bus), ``hdmi_sink.py`` (the 12-bit dual-edge bus and syncs sampled as
the part latches them, frames rebuilt, timing checked)."""
