"""Command-line front end of the stereo-FPGA project (``python -m stereodepth --help``)."""
