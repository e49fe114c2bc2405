"""The Verilator route's C++ testbench: ``testbench.h`` (clocks, camera replays, pin recorder, watched outputs),
``ctestbench.cpp`` + ``ctestbench.py`` (the same as a library driven from Python), ``build.py`` (cached builds),
``recording.py`` (the recorded pins into the HDMI sink)."""
