"""The specification's constants, shared by the gateware (``hdl/``), the golden models (``golden/``), the
simulation models and the board build: one source, split by subject.

======================  ======================================================================
module                  what
======================  ======================================================================
``spec.board``          clock frequencies (``CLOCKS``), I2C addresses (``I2C_ADDR``)
``spec.video``          video timing (``VideoTiming``, ``CEA_1080P60``, ``SMALL_TIMING``)
``spec.sensor``         sensor and buffer geometry (``SensorGeometry``), the rig's optics
``spec.depth``          the depth engine's constants (``DepthConfig``)
``spec.rectification``  the vertical-offset estimator's constants (``RectificationConfig``)
``spec.display``        grey, difference levels, depth colours, labels, readout text
``spec.font``           the screen's font
``spec.layout``         the screen layout (``DisplayLayout`` and its boxes)
======================  ======================================================================

Sources: the thesis (*FPGA based stereo camera depth map generation*, C. Güvendik, 2014) as docs/*.md pin it
down, CEA-861 for the video timing, docs/hardware-facts.md for the parts' clocks and addresses. Every block takes
its sizes as constructor arguments whose defaults come from here, so a test can build the same RTL small.
Imports nothing of the project outside ``spec``.
"""
