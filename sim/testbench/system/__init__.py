"""The whole system in simulation: one testbench, two simulators, pluggable routes.

========================  ==========================================================================================
``setup.py``              :class:`~sim.testbench.system.setup.SystemSetup`: sizes, clocks, tables, models, golden frame (the
                          ``small`` and ``full`` presets); ``tables.py`` derives the small and fast MT9D112 tables
``testbench.py``          :class:`~sim.testbench.system.testbench.SystemTestbench`: the design + its clocking model + its I2C buses
                          (``sim/models/i2c/bus.py``) + a cycle counter; what every route simulates
``rom_testbench.py``      the Amaranth replay route's design: the system testbench + ROM sensor replays + gated clocks
``verilog_testbench.py``  the cocotb in-simulator route's design: the system testbench + clock generators + Verilog sensor
                          replays + the CH7301C pin recorder (``sim/replay/sensor.py``, ``sim/replay/pins.py``)
``run_amaranth.py``       :func:`~sim.testbench.system.run_amaranth.run_amaranth` and the Amaranth routes
``cocotb_routes.py``      the cocotb routes (design + how each drives clocks, cameras, display)
``run_cocotb.py``         :func:`~sim.testbench.system.run_cocotb.run_cocotb_system` (the pytest side of a cocotb run)
``cocotb_scenario.py``    the scenario inside the simulator (``sim/testbench/system/system_cocotb.py`` runs it)
``result.py``             :class:`~sim.testbench.system.result.SystemResult` and the check phase every run ends with
``waves.py``              what the whole system's GTKWave save file shows (groups, markers, view; ``sim/waves/gtkw.py``)
========================  ==========================================================================================

Every run goes through the same phases (reset, init, capture, display, check) against the same golden frame.
"""
