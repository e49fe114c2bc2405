"""Run an Amaranth design in Amaranth's Python simulator with every clock domain at its real frequency.

A thin, shared wrapper so every testbench sets clocks and writes waves the same way::

    simulate(dut, clocks={"sync": 100e6, "pix": 148.5e6}, testbenches=[testbench], vcd="build/x.vcd",
             traces={"video": [dut.hsync, dut.vsync]})

``testbenches`` are ``async def testbench(ctx)`` functions (``sim.add_testbench``); ``processes`` are
``sim.add_process`` functions (for models that must react within the same delta cycle). ``until`` (seconds)
bounds the run for designs whose benches never return; otherwise the run ends when every testbench returns.
``timeout_s`` (seconds of simulated time) is a watchdog for benches that should return: if they have not by
then, the run fails with ``AssertionError(timeout_message)``.
With ``vcd`` set, a GTKWave save file is written beside it (``.gtkw``) by :func:`sim.waves.gtkw.recording` showing
``traces`` (a :class:`sim.waves.gtkw.Waves`, or a dict of groups).
"""

from pathlib import Path

from amaranth.sim import Simulator

__all__ = ["simulate"]


def simulate(dut, *, clocks, testbenches=(), processes=(), vcd=None, gtkw=None, traces=(), until=None,
             timeout_s=None, timeout_message=None):
    sim = Simulator(dut)
    for domain, hz in clocks.items():
        sim.add_clock(1 / hz, domain=domain)
    for testbench in testbenches:
        sim.add_testbench(testbench)
    for process in processes:
        sim.add_process(process)
    if timeout_s is not None:
        async def watchdog(ctx):
            await ctx.delay(timeout_s)
            raise AssertionError(timeout_message or f"the testbenches did not finish within {timeout_s} s "
                                                    "of simulated time")
        sim.add_testbench(watchdog, background=True)

    def run():
        if until is None:
            sim.run()
        else:
            sim.run_until(until)

    if vcd is None:
        run()
        return sim
    from sim.waves.gtkw import recording
    vcd = Path(vcd)
    gtkw = Path(gtkw) if gtkw is not None else vcd.with_suffix(".gtkw")
    with recording(sim, vcd, gtkw, traces):
        run()
    return sim
