"""The board's Verilog simulated as built: ``top.py`` (the ``top.v`` of the build, the setup it is built for and
the testbench around it for cocotb on Icarus and Verilator; tests/test_board_top.py runs it), ``xilinx/``
(behavioural models of the Virtex-5 primitives the board top instantiates).

May import: ``spec``, ``hdl``, ``board``, ``sim.testbench`` (the board build is below it; nothing in ``board``
imports it).
"""
