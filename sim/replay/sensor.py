"""A camera's pins replayed inside the simulator from the Python sensor model's stream: no Python per PCLK sample.

The stream is the *Python sensor model's* (:meth:`sim.models.mt9d112.sensor.MT9D112.frame`), made before the run; a full frame
period at 1600 x 1200 is about 4.4 million samples, which a per-sample Python driver cannot feed fast enough.
Every sample is one 10-bit word ``{fv, lv, d[7:0]}`` (:func:`pack_stream`, the one packer), replayed one word per
PCLK period. Two implementations of the same replay, one per simulator family:

* :data:`REPLAY_VERILOG`, module ``sensor_replay`` (cocotb on Verilator / Icarus): a ROM loaded with
  ``$readmemh`` from a file (:func:`write_hex`) on a rising edge of ``load``. While ``run`` is high it puts word
  ``index`` on the pins at every falling PCLK edge (the capture samples it at the next rising edge: the timing of
  ``sim.models.mt9d112.sensor.drive_cocotb``), ``length`` words in all; then, with ``LOOP`` = 1, it starts again at word 0 (the
  same frame period repeated, as the Python drivers repeat the image), with ``LOOP`` = 0 it holds the pins low and
  raises ``done``. While ``run`` is low the pins are 0 and ``index`` is 0. Simulation only, not synthesisable.
* :class:`SensorReplay` (Amaranth's simulator): the same ROM as an ``amaranth.lib.memory.Memory``, looping,
  registering each word on the rising edge of its domain's clock.

A stream with PCLK pauses cannot be replayed (one word per period): :func:`pack_stream` refuses it.
"""

from pathlib import Path

import numpy as np

from amaranth import Cat, Module
from amaranth.lib import wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from hdl.capture import CameraSignature

__all__ = ["pack_stream", "write_hex", "REPLAY_VERILOG", "SensorReplay"]


def pack_stream(stream):
    """A :class:`sim.models.mt9d112.sensor.SensorStream` as 10-bit words ``{fv, lv, d[7:0]}`` (a uint32 array). Raises
    ``ValueError`` for a stream with PCLK pauses."""
    if stream.pauses:
        raise ValueError("the replay has no PCLK pauses: replay streams without pauses only")
    return (stream.fv.astype(np.uint32) << 9) | (stream.lv.astype(np.uint32) << 8) | stream.data


#: ``$readmemh`` line of every 10-bit word: three hex digits and a newline.
_HEX_LINES = np.array([f"{w:03x}\n".encode() for w in range(1024)], dtype="S4")


def write_hex(words, path):
    """Write packed words as ``$readmemh`` lines (written to a temporary name, then renamed, so a parallel reader
    never sees half a file); returns the number of words."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_bytes(_HEX_LINES[np.asarray(words)].tobytes())
    tmp.replace(path)
    return len(words)


REPLAY_VERILOG = r"""
// sim/replay/sensor.py: a camera's pins replayed from a $readmemh file (simulation only, not synthesisable).
module sensor_replay #(parameter DEPTH = 1, parameter FILE = "cam.hex", parameter LOOP = 1) (
    input pclk, input load, input run, input [31:0] length,
    output reg [7:0] d, output reg lv, output reg fv, output reg [31:0] index, output reg done
);
    reg [9:0] rom [0:DEPTH-1];
    initial begin d = 0; lv = 0; fv = 0; index = 0; done = 0; end
    always @(posedge load) $readmemh(FILE, rom);
    always @(negedge pclk) begin
        if (run && !done) begin
            {fv, lv, d} <= rom[index];
            if (index + 1 >= length) begin
                index <= 0;
                done <= !LOOP;
            end else
                index <= index + 1;
        end else begin
            {fv, lv, d} <= 10'd0;
            if (!run) index <= 0;
        end
    end
endmodule
"""


class SensorReplay(wiring.Component):
    """The replay in Amaranth's simulator (see the module docstring).

    Parameters
    ----------
    words : sequence of int
        The ROM: 10-bit ``{fv, lv, d}`` per sample, at least one (:func:`pack_stream`).
    domain : str
        The PCLK domain, the one the capture samples in.

    Attributes
    ----------
    run : ``In(1)``
    pins : ``Out(CameraSignature)``
        While ``run`` is high, each rising edge registers the next word; after the last one the replay starts
        again at word 0. While ``run`` is low the pins are 0.
    index : ``Out``
        The next word (0 while ``run`` is low).

    Latency: one PCLK from ``run`` rising to word 0 on the pins. Amaranth builds a ROM of a full frame period (4.4 M
    words) slowly: part of a full-size run's set-up time.

    Raises
    ------
    ValueError
        An empty ROM, or a word wider than 10 bits.
    """

    def __init__(self, words, *, domain):
        words = list(words)
        if not words:
            raise ValueError("the replay ROM needs at least one sample")
        if any(not 0 <= w < 1024 for w in words):
            raise ValueError("replay words are 10 bits: {fv, lv, d[7:0]}")
        self._words = words
        self._domain = domain
        super().__init__({"run": In(1), "pins": Out(CameraSignature), "index": Out(range(len(words)))})

    @property
    def length(self):
        return len(self._words)

    def elaborate(self, platform):
        m = Module()
        m.submodules.rom = rom = Memory(shape=10, depth=self.length, init=self._words)
        read = rom.read_port(domain="comb")
        m.d.comb += read.addr.eq(self.index)
        sync = m.d[self._domain]
        pins = Cat(self.pins.data, self.pins.lv, self.pins.fv)
        with m.If(self.run):
            sync += pins.eq(read.data)
            with m.If(self.index == self.length - 1):
                sync += self.index.eq(0)
            with m.Else():
                sync += self.index.eq(self.index + 1)
        with m.Else():
            sync += [pins.eq(0), self.index.eq(0)]
        return m
