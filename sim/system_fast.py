"""The fast cocotb route: behavioural Verilog sensors replaying the Python model's bytes, a Verilog bus recorder.

With the sensor models driven per PCLK from Python and the HDMI sink sampling per pixel clock in Python, a
full-resolution end-to-end run spends nearly all its time in Python (about 9 million sensor samples and 2.5
million pixel clocks). :class:`FastSystemBench` puts two small behavioural Verilog modules next to the design
so those loops run inside the simulator:

* ``system_sensor_replay`` (one per camera): a ROM of ``{fv, lv, d[7:0]}`` samples, loaded with ``$readmemh``
  from a file the cocotb test writes from the *Python sensor model's* stream (``sim.mt9d112.MT9D112.frame``,
  once the model's I2C register file says the sensor is configured), replayed one sample per PCLK: the next
  sample is put on the pins at every falling edge, so the capture samples it at the rising edge -- the timing of
  ``sim.mt9d112.drive_cocotb``. After ``length`` samples it starts again at sample 0 (the same frame period
  repeated, as the Python route repeats the image).
* ``system_bus_recorder``: clocked by a clock at twice the pixel rate, a quarter pixel period after each pixel
  clock edge (the sample points of ``sim.hdmi_sink.CocotbSink``), it writes one line per pixel clock to a text
  file: XCLK levels in both phases, hsync/vsync/de and the word of each phase. The cocotb test reads the file and
  feeds ``sim.hdmi_sink.HdmiSink`` with exactly what ``CocotbSink`` would have fed it (:func:`replay_recording`,
  same XCLK-level checks).

Equivalence is tested (tests/test_system.py, small preset): in one run the Python sink and the recorder sample
the same pins and their per-clock samples must be identical; and the replayed camera pins, sampled at every PCLK
rising edge, must equal the model's stream.

The clocks are generated inside the simulator too (``system_clock_gen``, ``system_pix_rec_gen``: behavioural
``#`` delays, so Verilator builds with ``--timing``), started by enable ports whose rising time sets each clock's
phase; cocotb no longer services every clock edge. The cameras' pins are multiplexed: ``use_replay`` = 0 takes
them from the ports (Python drivers on the generated PCLK), 1 from the replay modules.
"""

from pathlib import Path

import numpy as np

from amaranth import Cat, Instance, Module, Mux, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.system import CAMERAS
from sim.system_bench import SystemBench

__all__ = ["FastSystemBench", "VERILOG", "write_sources", "stream_to_hex", "read_recording",
           "replay_recording"]

VERILOG = r"""
// Behavioural simulation helpers of sim/system_fast.py (not synthesisable, not part of the design).
`timescale 1ps/1ps

// A free-running clock started by `en` (its phase is the time `en` rises: first rising edge HALF_PS later).
module system_clock_gen #(parameter HALF_PS = 5000) (input en, output reg clk);
    initial begin
        clk = 0;
        wait (en);
        forever begin
            #HALF_PS clk = 1;
            #HALF_PS clk = 0;
        end
    end
endmodule

// The pixel clock (rises when `en` rises, period 4 * QUARTER_PS) and, once `rec_en` is set, the recorder's
// sample clock: rising a quarter period after each pixel-clock edge (t0 + T/4, t0 + 3T/4, ...), so it adds no
// simulator time slots before it is needed.
module system_pix_rec_gen #(parameter QUARTER_PS = 1684) (input en, input rec_en, output reg pix, output reg rec);
    initial begin
        pix = 0;
        wait (en);
        forever begin
            pix = 1;
            #(2 * QUARTER_PS) pix = 0;
            #(2 * QUARTER_PS);
        end
    end
    initial begin
        rec = 0;
        wait (rec_en);
        @(posedge pix);
        forever begin
            #QUARTER_PS rec = 1;
            #QUARTER_PS rec = 0;
        end
    end
endmodule

module system_sensor_replay #(parameter DEPTH = 1, parameter FILE = "cam.hex") (
    input pclk, input load, input run, input [31:0] length,
    output reg [7:0] d, output reg lv, output reg fv, output reg [31:0] index
);
    reg [9:0] rom [0:DEPTH-1];
    initial begin d = 0; lv = 0; fv = 0; index = 0; end
    always @(posedge load) $readmemh(FILE, rom);
    always @(negedge pclk) begin
        if (run) begin
            {fv, lv, d} <= rom[index];
            index <= (index + 1 >= length) ? 0 : index + 1;
        end else begin
            {fv, lv, d} <= 10'd0;
            index <= 0;
        end
    end
endmodule

module system_bus_recorder #(parameter FILE = "bus.txt") (
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


def write_sources(directory):
    """Write the helper modules to ``directory``; returns the file path (an extra source for the runner)."""
    path = Path(directory) / "system_fast_helpers.v"
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text() != VERILOG:
        path.write_text(VERILOG)
    return path


#: ``$readmemh`` line of every 10-bit word: three hex digits and a newline.
_HEX_LINES = np.array([f"{w:03x}\n".encode() for w in range(1024)], dtype="S4")


def stream_to_hex(stream, path):
    """Write a :class:`sim.mt9d112.SensorStream` as ``$readmemh`` lines of ``{fv, lv, d}`` (10 bits)."""
    from sim.sensor_replay import pack_stream
    words = pack_stream(stream)
    Path(path).write_bytes(_HEX_LINES[words].tobytes())
    return len(words)


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
    """Feed ``sink`` (an :class:`sim.hdmi_sink.HdmiSink`) from recorder lines, with ``CocotbSink``'s checks of
    the XCLK levels (high phase: XCLK_P 1, XCLK_N 0; low phase: 0, 1). Returns ``sink``."""
    for high, low, first, second in records:
        xp, xn = (high >> 4) & 1, (high >> 3) & 1
        if (xp, xn) != (1, 0) or low != 0b01:
            sink.report_violation(
                "xclk", f"xclk_p/xclk_n are {xp}/{xn} a quarter period after the rising edge and "
                        f"{(low >> 1) & 1}/{low & 1} a quarter period after the falling edge (expected 1/0 then 0/1)")
        sink.sample(bool(high & 4), bool(high & 2), bool(high & 1), first, second)
    return sink


class FastSystemBench(wiring.Component):
    """:class:`sim.system_bench.SystemBench` (clock ports) + a sensor replay module per camera + the bus
    recorder. Extra ports: ``use_replay``; per camera ``cam_<c>_load``, ``cam_<c>_run``, ``cam_<c>_length[32]``,
    ``cam_<c>_index[32]``, ``cam_<c>_seen[10]`` (``{fv, lv, d}`` as the capture sees them), ``cam_<c>_en``
    (starts that PCLK), ``cam_<c>_clk`` (out); ``sync_en``, ``pix_en``, ``rec_clk_en`` (start the clocks),
    ``clk``/``pix_clk``/``rec_clk`` (out); ``rec_clk``, ``rec_enable``, ``rec_limit[32]``, ``rec_done``, ``rec_count[32]``.
    ``replay_depth`` is the ROM depth (samples) of each replay module; the files are ``cam_a.hex``,
    ``cam_b.hex`` and ``bus.txt`` in the simulator's working directory."""

    def __init__(self, *, replay_depth, sys_period_ps=10_000, pix_period_ps=6736, pclk_period_ps=12_500,
                 **system_kwargs):
        if pix_period_ps % 4 or sys_period_ps % 2 or pclk_period_ps % 2:
            raise ValueError("clock periods must be even (the pixel period a multiple of 4) in picoseconds")
        self.replay_depth = int(replay_depth)
        self.periods = {"sync": sys_period_ps, "pix": pix_period_ps, "cam": pclk_period_ps}
        self.bench = SystemBench(clock_ports=True, **system_kwargs)
        clock_ports = {"clk", "pix_clk"} | {f"cam_{c}_clk" for c in CAMERAS}
        members = {n: m for n, m in self.bench.signature.members.items() if n not in clock_ports}
        members.update({"use_replay": In(1), "rec_enable": In(1), "rec_limit": In(32),
                        "rec_done": Out(1), "rec_count": Out(32),
                        "sync_en": In(1), "pix_en": In(1), "rec_clk_en": In(1),
                        "clk": Out(1), "pix_clk": Out(1), "rec_clk": Out(1)})
        for c in CAMERAS:
            members.update({f"cam_{c}_load": In(1), f"cam_{c}_run": In(1), f"cam_{c}_length": In(32),
                            f"cam_{c}_index": Out(32), f"cam_{c}_seen": Out(10),
                            f"cam_{c}_en": In(1), f"cam_{c}_clk": Out(1)})
        super().__init__(members)

    def elaborate(self, platform):
        m = Module()
        m.submodules.bench = bench = self.bench
        p = self.periods
        # Clocks generated in the simulator (no per-edge call into Python): outputs mirror them for the test.
        m.submodules.sync_gen = Instance("system_clock_gen", p_HALF_PS=p["sync"] // 2,
                                         i_en=self.sync_en, o_clk=bench.clk)
        m.submodules.pix_gen = Instance("system_pix_rec_gen", p_QUARTER_PS=p["pix"] // 4,
                                        i_en=self.pix_en, i_rec_en=self.rec_clk_en,
                                        o_pix=bench.pix_clk, o_rec=self.rec_clk)
        m.d.comb += [self.clk.eq(bench.clk), self.pix_clk.eq(bench.pix_clk)]
        for c in CAMERAS:
            clk = getattr(bench, f"cam_{c}_clk")
            m.submodules[f"cam_{c}_gen"] = Instance("system_clock_gen", p_HALF_PS=p["cam"] // 2,
                                                    i_en=getattr(self, f"cam_{c}_en"), o_clk=clk)
            m.d.comb += getattr(self, f"cam_{c}_clk").eq(clk)
        cam_pins = {f"cam_{c}_{p}" for c in CAMERAS for p in ("data", "lv", "fv")}
        clocks = {"clk", "pix_clk"} | {f"cam_{c}_clk" for c in CAMERAS}
        for name, member in bench.signature.members.items():
            if name in cam_pins or name in clocks or name not in self.signature.members:
                continue
            ours, theirs = getattr(self, name), getattr(bench, name)
            m.d.comb += (theirs.eq(ours) if member.flow == In else ours.eq(theirs))
        for c in CAMERAS:
            data, lv, fv = Signal(8, name=f"replay_{c}_d"), Signal(name=f"replay_{c}_lv"), Signal(name=f"replay_{c}_fv")
            m.submodules[f"replay_{c}"] = Instance(
                "system_sensor_replay", p_DEPTH=self.replay_depth, p_FILE=f"cam_{c}.hex",
                i_pclk=getattr(bench, f"cam_{c}_clk"), i_load=getattr(self, f"cam_{c}_load"),
                i_run=getattr(self, f"cam_{c}_run"), i_length=getattr(self, f"cam_{c}_length"),
                o_d=data, o_lv=lv, o_fv=fv, o_index=getattr(self, f"cam_{c}_index"))
            for pin, replay in (("data", data), ("lv", lv), ("fv", fv)):
                m.d.comb += getattr(bench, f"cam_{c}_{pin}").eq(
                    Mux(self.use_replay, replay, getattr(self, f"cam_{c}_{pin}")))
            # What the capture sees, {fv, lv, d}, for the equivalence check.
            m.d.comb += getattr(self, f"cam_{c}_seen").eq(Cat(getattr(bench, f"cam_{c}_data"),
                                                               getattr(bench, f"cam_{c}_lv"),
                                                               getattr(bench, f"cam_{c}_fv")))
        m.submodules.recorder = Instance(
            "system_bus_recorder", p_FILE="bus.txt",
            i_clk=self.rec_clk, i_pix=bench.pix_clk, i_enable=self.rec_enable, i_limit=self.rec_limit,
            i_data=bench.data, i_hsync=bench.hsync, i_vsync=bench.vsync, i_de=bench.de,
            i_xclk_p=bench.xclk_p, i_xclk_n=bench.xclk_n, o_done=self.rec_done, o_count=self.rec_count)
        return m
