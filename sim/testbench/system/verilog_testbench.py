"""VerilogReplayTestbench: the system testbench with its clocks, camera pins and display pins handled inside the simulator.

The design of the fast cocotb route (Verilator, Icarus). With the sensor models driven per PCLK from Python and the
HDMI sink sampling per pixel clock in Python, a full-resolution run spends nearly all its time in Python (about 9
million sensor samples and 2.5 million pixel clocks). This bench puts small behavioural Verilog modules next to
:class:`sim.testbench.system.testbench.SystemTestbench` so those loops run inside the simulator:

* clocks: ``clock_gen`` per domain (``mem`` too in the DDR2 build) and ``pix_rec_gen`` for the pixel clock and
  the recorder's sample clock (behavioural ``#`` delays, so Verilator builds with ``--timing``), each started by
  its ``clock_en`` input, whose rising time sets the clock's phase; ``clocks`` mirrors them for the test to wait on;
* each camera's pins from a ``sensor_replay`` module (:mod:`sim.replay.sensor`), controlled through ``replay.<cam>``;
  ``replay.<cam>.seen`` is what the capture sees, ``{fv, lv, d}``, for the replay's equivalence check;
* the CH7301C pins recorded by ``ch7301c_recorder`` (:mod:`sim.replay.pins`), controlled through ``recorder``.

The files are ``cam_a.hex``, ``cam_b.hex`` and ``bus.txt`` in the simulator's working directory. Clock domains:
those of the system testbench, defined here. Latency: as the replay and the recorder say.
"""

from pathlib import Path

from amaranth import Cat, Instance, Module, Signal
from amaranth.lib import wiring
from amaranth.lib.wiring import In, Out

from hdl.system import CAMERAS, SystemParameters
from sim.replay.pins import RECORDER_VERILOG
from sim.replay.sensor import REPLAY_VERILOG
from sim.testbench.system.testbench import SystemTestbench, bench_members, pass_through

__all__ = ["VerilogReplayTestbench", "ReplayControlSignature", "RecorderSignature", "write_sources"]

CLOCK_VERILOG = r"""
// sim/testbench/system/verilog_testbench.py: clocks generated in the simulator (simulation only).
`timescale 1ps/1ps

// A free-running clock started by `en` (its phase is the time `en` rises: first rising edge HALF_PS later).
module clock_gen #(parameter HALF_PS = 5000) (input en, output reg clk);
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
module pix_rec_gen #(parameter QUARTER_PS = 1684) (input en, input rec_en, output reg pix, output reg rec);
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
"""

#: How a test controls one camera's replay: ``load`` (rising edge: read the file), ``run``, ``length`` (words), and
#: what it reports: ``index`` (the next word) and ``seen`` (``{fv, lv, d}`` on the capture's pins).
ReplayControlSignature = wiring.Signature({
    "load": In(1), "run": In(1), "length": In(32), "index": Out(32), "seen": Out(10),
})
#: How a test controls the pin recorder: ``enable``, ``limit`` (lines) in; ``done``, ``count`` (lines written) out.
RecorderSignature = wiring.Signature({"enable": In(1), "limit": In(32), "done": Out(1), "count": Out(32)})

_CLOCKS = ("sync", "pix", "rec", *(f"cam_{c}" for c in CAMERAS))


def write_sources(directory):
    """Write the Verilog of the clocks, the replay and the recorder to ``directory``; returns the path (an extra
    source for ``sim.runners.cocotb.run_cocotb``)."""
    path = Path(directory) / "system_replay_helpers.v"
    text = CLOCK_VERILOG + REPLAY_VERILOG + RECORDER_VERILOG
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists() or path.read_text() != text:
        path.write_text(text)
    return path


class VerilogReplayTestbench(wiring.Component):
    """See the module docstring.

    Parameters
    ----------
    replay_depth : int
        ROM depth (words) of each replay module.
    periods_ps : dict
        Clock periods in picoseconds: ``"sync"``, ``"pix"`` (a multiple of 4), ``"cam"`` (even); with the DDR2
        build ``"mem"`` (even) too.
    **system_kwargs
        For :class:`sim.testbench.system.testbench.SystemTestbench`.

    Attributes
    ----------
    params : :class:`hdl.system.SystemParameters`
        The system's parameters (``video_timing``: its ``timing``).
    (every member of the system testbench but the camera pins)
    clock_en : ``In``, per clock ``sync``, ``pix``, ``rec``, ``cam_a``, ``cam_b`` (and ``mem`` with the DDR2)
    clocks : ``Out``, the same clocks
    replay : ``Out``, per camera ``cam_a``, ``cam_b`` a :data:`ReplayControlSignature`
    recorder : ``Out(RecorderSignature)``

    Raises
    ------
    ValueError
        Odd clock periods (or a pixel period that is not a multiple of 4 ps).
    """

    def __init__(self, *, replay_depth, periods_ps, **system_kwargs):
        if periods_ps["pix"] % 4 or any(periods_ps[name] % 2 for name in periods_ps):
            raise ValueError("clock periods must be even (the pixel period a multiple of 4) in picoseconds")
        self.replay_depth = int(replay_depth)
        self.periods_ps = dict(periods_ps)
        self.system_kwargs = system_kwargs
        self.params = SystemParameters(ddr="behavioural", **{k: v for k, v in system_kwargs.items()
                                                             if k != "lock_cycles"})
        self.video_timing = self.params.timing
        cam_pins = {f"cam_{c}" for c in CAMERAS}
        members = {name: member for name, member in bench_members(self.params).items() if name not in cam_pins}
        self.ddr2 = self.params.memory == "ddr2"
        if self.ddr2 and "mem" not in periods_ps:
            raise ValueError("the DDR2 build needs the mem clock's period")
        clocks = wiring.Signature({name: Out(1) for name in _CLOCKS + (("mem",) if self.ddr2 else ())})
        members.update({
            "clock_en": In(clocks), "clocks": Out(clocks),
            "replay": Out(wiring.Signature({f"cam_{c}": Out(ReplayControlSignature) for c in CAMERAS})),
            "recorder": Out(RecorderSignature),
        })
        super().__init__(members)

    def elaborate(self, platform):
        m = Module()
        m.submodules.bench = bench = SystemTestbench(define_domains=False, mig_storage="verilog",
                                                     **self.system_kwargs)
        m.domains += bench.domains
        pass_through(m, self, bench)
        domains = {cd.name: cd for cd in bench.domains}
        p = self.periods_ps
        en, clocks = self.clock_en, self.clocks
        m.submodules.sync_gen = Instance("clock_gen", p_HALF_PS=p["sync"] // 2, i_en=en.sync,
                                         o_clk=domains["sync"].clk)
        m.submodules.pix_gen = Instance("pix_rec_gen", p_QUARTER_PS=p["pix"] // 4, i_en=en.pix, i_rec_en=en.rec,
                                        o_pix=domains["pix"].clk, o_rec=clocks.rec)
        if self.ddr2:
            m.submodules.mem_gen = Instance("clock_gen", p_HALF_PS=p["mem"] // 2, i_en=en.mem,
                                            o_clk=domains["mem"].clk)
        for c in CAMERAS:
            name = f"cam_{c}"
            m.submodules[f"{name}_gen"] = Instance("clock_gen", p_HALF_PS=p["cam"] // 2,
                                                   i_en=getattr(en, name), o_clk=domains[name].clk)
            self._replay(m, c, domains[name].clk, bench)
        m.d.comb += [getattr(clocks, name).eq(cd.clk) for name, cd in domains.items()]
        pins, rec = bench.ch7301c, self.recorder
        m.submodules.recorder = Instance(
            "ch7301c_recorder", p_FILE="bus.txt",
            i_clk=clocks.rec, i_pix=domains["pix"].clk, i_enable=rec.enable, i_limit=rec.limit,
            i_data=pins.data, i_hsync=pins.hsync, i_vsync=pins.vsync, i_de=pins.de,
            i_xclk_p=pins.xclk_p, i_xclk_n=pins.xclk_n, o_done=rec.done, o_count=rec.count)
        return m

    def _replay(self, m, c, pclk, bench):
        """Camera ``c``'s replay module onto the camera pins of ``bench`` (the system testbench)."""
        control, pins = getattr(self.replay, f"cam_{c}"), getattr(bench, f"cam_{c}")
        m.submodules[f"replay_{c}"] = Instance(
            "sensor_replay", p_DEPTH=self.replay_depth, p_FILE=f"cam_{c}.hex", p_LOOP=1,
            i_pclk=pclk, i_load=control.load, i_run=control.run, i_length=control.length,
            o_d=pins.data, o_lv=pins.lv, o_fv=pins.fv, o_index=control.index,
            o_done=Signal(name=f"replay_{c}_done"))          # never set: the replay loops
        m.d.comb += control.seen.eq(Cat(pins.data, pins.lv, pins.fv))
