"""The frame store in the DDR2 behind MIG (docs/frame_store.md): camera writers, buffer ownership, readers and
the arbiter, in the ``mem`` domain (MIG's clk0) and the cameras' and the display's domains."""
