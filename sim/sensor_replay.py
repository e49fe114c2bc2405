"""SensorReplay: one frame period of a camera's pins, ``{fv, lv, d}`` per PCLK, replayed from a ROM (Amaranth).

The Amaranth-simulator counterpart of the ``system_sensor_replay`` Verilog module of ``sim/system_fast.py``: the
ROM holds the *Python sensor model's* stream (:meth:`sim.mt9d112.MT9D112.frame`, as :func:`stream_words` packs
it), so a full-resolution run does not call into Python for each of the millions of PCLK samples.

Clock domain: ``domain`` (the camera's PCLK domain, the one the capture samples in). While ``run`` is high, each
rising edge registers the next sample onto ``data``/``lv``/``fv`` and the capture, in the same domain, samples it
at the following edge; after the last sample it starts again at sample 0 (the same frame period repeated, as the
Python route repeats the image). While ``run`` is low the pins are 0 and ``index`` is 0.
Latency: one PCLK from ``run`` rising to sample 0 on the pins.

Simulation helper only (not part of the design): building a ROM of a full frame period (about 4.4 million
samples) takes Amaranth about half a minute.
"""

import numpy as np

from amaranth import Cat, Module
from amaranth.lib import wiring
from amaranth.lib.memory import Memory
from amaranth.lib.wiring import In, Out

from hdl.rejecting import rejecting

__all__ = ["SensorReplay", "pack_stream", "stream_words"]


def pack_stream(stream):
    """A :class:`sim.mt9d112.SensorStream` as 10-bit words ``{fv, lv, d[7:0]}`` (a uint32 array), the word of
    this ROM and of the Verilog replay module (``sim/system_fast.py``). Both replay one sample per PCLK: a stream
    with PCLK pauses is refused."""
    if stream.pauses:
        raise ValueError("the replay has no PCLK pauses: replay streams without pauses only")
    return (stream.fv.astype(np.uint32) << 9) | (stream.lv.astype(np.uint32) << 8) | stream.data


def stream_words(stream):
    """:func:`pack_stream` as a list of ints (the ROM's initial contents)."""
    return pack_stream(stream).tolist()


class SensorReplay(wiring.Component):
    """See the module docstring. ``words``: the ROM (10-bit ``{fv, lv, d}`` per sample, at least one);
    ``domain``: the PCLK domain."""

    def __init__(self, words, *, domain):
        words = list(words)
        with rejecting(self):
            if not words:
                raise ValueError("the replay ROM needs at least one sample")
            if any(not 0 <= w < 1024 for w in words):
                raise ValueError("replay words are 10 bits: {fv, lv, d[7:0]}")
        self._words = words
        self._domain = domain
        super().__init__({"run": In(1), "data": Out(8), "lv": Out(1), "fv": Out(1),
                          "index": Out(range(len(words)))})

    @property
    def length(self):
        return len(self._words)

    def elaborate(self, platform):
        m = Module()
        m.submodules.rom = rom = Memory(shape=10, depth=self.length, init=self._words)
        read = rom.read_port(domain="comb")
        m.d.comb += read.addr.eq(self.index)
        sync = m.d[self._domain]
        with m.If(self.run):
            sync += Cat(self.data, self.lv, self.fv).eq(read.data)
            with m.If(self.index == self.length - 1):
                sync += self.index.eq(0)
            with m.Else():
                sync += self.index.eq(self.index + 1)
        with m.Else():
            sync += [Cat(self.data, self.lv, self.fv).eq(0), self.index.eq(0)]
        return m
