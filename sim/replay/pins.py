"""The CH7301C pins recorded inside the simulator, for the HDMI sink model to read afterwards: no Python per clock.

:data:`RECORDER_VERILOG`, module ``ch7301c_recorder`` (cocotb on Verilator / Icarus; simulation only): clocked by
a clock at twice the pixel rate, a quarter pixel period after each pixel-clock edge (the sample points of
:class:`sim.models.ch7301c.hdmi_sink.CocotbSink`), it writes one line per pixel clock to a text file while ``enable`` is high,
``limit`` lines in all (then ``done``): the XCLK levels and hsync/vsync/de in the high phase, the XCLK levels in the
low phase, and the word of each phase. :func:`read_recording` reads the file back with NumPy and
:func:`replay_recording` feeds a :class:`sim.models.ch7301c.hdmi_sink.HdmiSink` with exactly what ``CocotbSink`` would have fed it,
with the same XCLK-level checks.
"""

import numpy as np

__all__ = ["RECORDER_VERILOG", "read_recording", "replay_recording"]

RECORDER_VERILOG = r"""
// sim/replay/pins.py: the CH7301C pins, one line per pixel clock, to a file (simulation only).
module ch7301c_recorder #(parameter FILE = "bus.txt") (
    input clk, input pix, input enable, input [31:0] limit,
    input [11:0] data, input hsync, input vsync, input de, input xclk_p, input xclk_n,
    output reg done, output reg [31:0] count
);
    integer f;
    reg [11:0] first;
    reg [4:0] high;              // xclk_p, xclk_n, hsync, vsync, de in the high phase
    reg have_high;
    initial begin done = 0; count = 0; have_high = 0; f = 0; end
    always @(posedge clk) begin
        if (enable && !done) begin
            if (f == 0) f = $fopen(FILE, "w");
            if (pix) begin
                high <= {xclk_p, xclk_n, hsync, vsync, de};
                first <= data;
                have_high <= 1;
            end else if (have_high) begin
                $fwrite(f, "%h %h %h %h\n", high, {xclk_p, xclk_n}, first, data);
                count <= count + 1;
                if (count + 1 >= limit) begin
                    done <= 1;
                    $fclose(f);
                end
            end
        end
    end
endmodule
"""

#: The recorder's line, ``$fwrite("%h %h %h %h\\n")`` of 5, 2, 12 and 12 bits: fixed width, 13 bytes.
_LINE = np.frombuffer(b"hh h hhh hhh\n", dtype=np.uint8)
_HEX = np.full(256, -1, dtype=np.int16)
_HEX[np.frombuffer(b"0123456789abcdef", dtype=np.uint8)] = np.arange(16)


def read_recording(path):
    """The recorder's file as a list of ``[high_bits, low_bits, first, second]`` ints per pixel clock. Raises
    ``ValueError`` naming the first line with X/Z (or anything but hex digits) on the recorded pins."""
    raw = np.fromfile(path, dtype=np.uint8)
    if raw.size % _LINE.size:
        raise ValueError(f"{path}: {raw.size} bytes, not whole {_LINE.size}-byte recorder lines")
    lines = raw.reshape(-1, _LINE.size)
    digit = _LINE == ord("h")
    values = _HEX[lines[:, digit]]
    bad = np.flatnonzero((values < 0).any(axis=1) | (lines[:, ~digit] != _LINE[~digit]).any(axis=1))
    if bad.size:
        text = bytes(lines[bad[0]]).decode(errors="replace").strip()
        raise ValueError(f"X/Z on the recorded pins (line {bad[0] + 1}): {text!r}")
    weights = np.array([16, 1, 1, 256, 16, 1, 256, 16, 1], dtype=np.int64)
    fields = np.add.reduceat(values * weights, [0, 2, 3, 6], axis=1)
    return fields.tolist()


def replay_recording(records, sink):
    """Feed ``sink`` (an :class:`sim.models.ch7301c.hdmi_sink.HdmiSink`) from recorder lines, with ``CocotbSink``'s checks of
    the XCLK levels (high phase: XCLK_P 1, XCLK_N 0; low phase: 0, 1). Returns ``sink``."""
    for high, low, first, second in records:
        xp, xn = (high >> 4) & 1, (high >> 3) & 1
        if (xp, xn) != (1, 0) or low != 0b01:
            sink.report_violation(
                "xclk", f"xclk_p/xclk_n are {xp}/{xn} a quarter period after the rising edge and "
                        f"{(low >> 1) & 1}/{low & 1} a quarter period after the falling edge (expected 1/0 then 0/1)")
        sink.sample(bool(high & 4), bool(high & 2), bool(high & 1), first, second)
    return sink
