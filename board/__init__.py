"""The Digilent Genesys board and its build flow: everything that turns the board-independent gateware (``hdl/``)
into a Virtex-5 build for Xilinx ISE, and what checks that build here.

=========================  ===================================================================================
module                     what
=========================  ===================================================================================
``board.genesys``          the platform: the board's resources and its VHDC connector (pin sources, placeholders)
``board.vmodcam``          the VmodCAM add-on: its resources on a VHDC connector, its timing figures
``board.ise``              the ISE flow of the platform: UCF rendering, timing constraints, tool options
``board.ise_templates``    the ISE build's file templates (UCF, XST script, build scripts, project TCL)
``board.pin_file``         the ``--pins`` file: FPGA pins for the VHDC placeholders
``board.top``              ``GenesysTop``: the system on the board's pins; ``board_plan`` (the build)
``board.clocking``         the clock plan (DCM_ADV + PLL_ADV), ``GenesysClocking`` and its reset tree; MIG's clocks
                           (PLL_BASE, ``MIGClocking``)
``board.mig``              the DDR2: the user's MIG core as a black box (``MIGCore``), ``GenesysDDR2``, ``mem``
``board.mig_core``         the ``--mig DIR`` core folder, read and checked
``board.mig_ucf``          the core's UCF merged into ``top.ucf``
``board.export``           Verilog export: flat port names, Amaranth's Verilog and its post-processing
``board.memory_init``      memory initial values in the Verilog text
``board.resources``        the Yosys ``synth_xilinx -family xc5v`` resource estimate
``board.memory_report``    each memory of the design, its XST coding form and its block RAM cost
``board.timing``           the static timing estimate on that netlist (``board.virtex5_delays``: its delays)
=========================  ===================================================================================

May import: ``spec``, ``hdl``. The board's ``top.v`` simulated as built is ``sim.board``.
"""
