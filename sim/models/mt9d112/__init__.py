"""The Aptina MT9D112 (one camera of the VmodCAM): ``sensor.py`` (image in, PCLK/FV/LV/D[7:0] out, once configured),
``registers.py`` (what each register and firmware variable the init tables write does), ``target.py`` (the register
file on the I2C bus), ``config.py`` (the output configuration the sensor model obeys)."""
