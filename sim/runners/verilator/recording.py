"""The C++ recorder's CH7301C pin samples (one uint32 word per pixel clock, ``sim.runners.verilator.ctestbench.RECORD_BITS``)
decoded with NumPy and fed to the HDMI sink model.

:func:`feed_sink` gives :class:`sim.models.ch7301c.hdmi_sink.HdmiSink` exactly what ``sim.models.ch7301c.hdmi_sink.CocotbSink`` would have
given it from the same pins -- hsync, vsync, de and the word a quarter period after the XCLK rising edge, the word a
quarter period after the falling edge -- with the same check of the XCLK levels at both sample points (XCLK_P 1,
XCLK_N 0 after the rising edge; 0, 1 after the falling edge) reported as ``xclk`` violations at the clock where
they happen.
"""

import numpy as np

from sim.runners.verilator.ctestbench import RECORD_BITS

__all__ = ["decode", "feed_sink"]


def decode(words):
    """``{field: uint32 array}`` of the recorder's words (fields of :data:`RECORD_BITS`)."""
    words = np.asarray(words, dtype=np.uint32)
    return {name: (words >> low) & ((1 << width) - 1) for name, (low, width) in RECORD_BITS.items()}


def feed_sink(words, sink):
    """Feed ``sink`` one pixel clock per recorder word (see the module docstring). Returns ``sink``."""
    f = decode(words)
    bad_xclk = ((f["xclk_p_high"] != 1) | (f["xclk_n_high"] != 0) | (f["xclk_p_low"] != 0)
                | (f["xclk_n_low"] != 1))
    columns = [f[k] for k in ("hsync", "vsync", "de", "first", "second")]
    start = 0
    for i in np.flatnonzero(bad_xclk).tolist():
        sink.feed_columns(*(c[start:i] for c in columns))
        sink.report_violation(
            "xclk", f"xclk_p/xclk_n are {f['xclk_p_high'][i]}/{f['xclk_n_high'][i]} a quarter period after the "
                    f"rising edge and {f['xclk_p_low'][i]}/{f['xclk_n_low'][i]} a quarter period after the "
                    f"falling edge (expected 1/0 then 0/1)")
        start = i
    sink.feed_columns(*(c[start:] for c in columns))
    return sink
