"""The board's Verilog simulated as built: ``top.py`` (the ``top.v`` of the build under cocotb on Icarus and
Verilator), ``top_cocotb.py`` (its cocotb test module), ``xilinx/`` (behavioural models of the Virtex-5 primitives the
board top instantiates).

May import: ``spec``, ``hdl``, ``golden``, ``board``, ``sim.models``, ``sim.runners``, ``sim.testbench`` (the board
build is below it; nothing in ``board`` imports it).
"""
