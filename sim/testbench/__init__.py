"""Testbenches: a block or the whole system with its environment, run on a simulator and read back.

``capture.py`` (the capture path from the sensor models), ``display.py`` (the display path through the HDMI sink),
``subtractor.py`` (the disparity subtractor with preloaded buffers), ``depth.py`` (the depth engine with two
buffers and a result reader), ``system/`` (the whole system, every route); ``*_cocotb.py`` are their cocotb test
modules (run by name through ``sim.runners.cocotb.run_cocotb``).

May import: ``spec``, ``hdl``, ``golden``, ``board``, ``sim.models``, ``sim.replay``, ``sim.runners``, ``sim.waves``.
"""
