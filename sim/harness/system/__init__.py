"""The whole system in simulation: one harness, two simulators, pluggable routes.

========================  ==========================================================================================
``setup.py``              :class:`~sim.harness.system.setup.SystemSetup`: sizes, clocks, tables, models, golden frame (the
                          ``small`` and ``full`` presets); ``tables.py`` derives the small and fast MT9D112 tables
``bench.py``              :class:`~sim.harness.system.bench.SystemBench`: the design + its clocking model + its I2C buses
                          (``sim/models/i2c/bus.py``) + a cycle counter; what every route simulates
``rom_bench.py``          the Amaranth replay route's design: the bench + ROM sensor replays + gated clocks
``verilog_bench.py``      the cocotb in-simulator route's design: the bench + clock generators + Verilog sensor
                          replays + the CH7301C pin recorder (``sim/replay/sensor.py``, ``sim/replay/pins.py``)
``run_amaranth.py``       :func:`~sim.harness.system.run_amaranth.run_amaranth` and the Amaranth routes
``cocotb_routes.py``      the cocotb routes (design + how each drives clocks, cameras, display)
``run_cocotb.py``         :func:`~sim.harness.system.run_cocotb.run_cocotb_system` (the pytest side of a cocotb run)
``cocotb_scenario.py``    the scenario inside the simulator (``sim/harness/system/system_cocotb.py`` runs it)
``result.py``             :class:`~sim.harness.system.result.SystemResult` and the check phase every run ends with
``waves.py``              what the whole system's GTKWave save file shows (groups, markers, view; ``sim/waves/gtkw.py``)
========================  ==========================================================================================

Every run goes through the same phases (reset, init, capture, display, check) against the same golden frame.
"""
