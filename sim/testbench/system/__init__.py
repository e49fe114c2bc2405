"""The whole system in simulation: the testbenches, and one driver per simulator that runs the phases.

========================  ==========================================================================================
``setup.py``              :class:`~sim.testbench.system.setup.SystemSetup`: sizes, clocks, tables, models, golden frame
                          (the presets ``small``, ``full``, ``full_800``, ``small_800``); ``tables.py`` derives the
                          small and fast MT9D112 tables
``testbench.py``          :class:`~sim.testbench.system.testbench.SystemTestbench`: the design + its clocking model +
                          its I2C buses (``sim/models/i2c/bus.py``) + a cycle counter; what every driver simulates
``rom_testbench.py``      the Amaranth replay route's design: the system testbench + ROM sensor replays + gated clocks
``verilog_testbench.py``  the cocotb in-simulator route's design: the system testbench + clock generators + Verilog
                          sensor replays + the CH7301C pin recorder (``sim/replay/sensor.py``, ``sim/replay/pins.py``)
``run_verilator.py``      :class:`~sim.testbench.system.run_verilator.VerilatorRun`: the driver of Verilator with the
                          C++ testbench (``sim/runners/verilator/``)
``run_amaranth.py``       :class:`~sim.testbench.system.run_amaranth.AmaranthRun` and the Amaranth routes
``run_cocotb.py``         :func:`~sim.testbench.system.run_cocotb.run_cocotb_system`: the pytest side of a cocotb run
``cocotb_routes.py``      the cocotb routes (design + how each drives clocks, cameras, display)
``cocotb_scenario.py``    the phases inside a cocotb simulation (``system_cocotb.py`` runs it)
``result.py``             :class:`~sim.testbench.system.result.DisplayFrame`, the display frames' bookkeeping every
                          driver shares, the parts' check, the golden frame of a tear
``waves.py``              what the whole system's GTKWave save file shows (groups, markers, view; ``sim/waves/gtkw.py``)
========================  ==========================================================================================

Each driver runs a still pair (a one-frame run) or a sequence of camera frames through the same phases (reset, I2C
init, capture, display frames, the parts' check) and hands each display frame on as the HDMI sink completes it. Its
caller is the run, :func:`sim.system.simulate` (``sim/system/``), which puts each simulator behind one backend
interface and judges the display frames against the golden model.
"""
