"""cocotb tests of the Virtex-5 primitive models (sim/board/xilinx) against their documented behaviour.

Run from tests/test_xilinx_models.py on ``tests/cocotb/xilinx_models_tb.v``. Each test drives one group of
primitives and compares what it measures with a reference written here from the documents (UG190 and the
library guide's description of the same primitive), not from the models' code:

* ``io_buffers``: IBUF, IBUFG, BUFG, OBUF follow their input; OBUFT releases its output when T = 1 (the bench's
  pull-up then reads 1); IOBUF drives the pad when T = 0 and always reads it back.
* ``flip_flops``: FDCE / FDPE against a clock-by-clock reference (INIT, CE, asynchronous clear / preset).
* ``oddr``: the four DDR_CLK_EDGE x SRTYPE combinations against an edge-by-edge reference of UG190's
  description; Q is read in the middle of every half period.
* ``dcm``: CLKFX = CLKIN x 11 / 10 (period, duty, CLKFX180, alignment to CLKIN every 10 input periods), the DLL
  outputs with a fixed phase shift, LOCKED after the lock time, no output before lock, reset.
* ``pll``: 100 MHz x 6 / 25 = 24 MHz; the pixel PLL's ratios (x 27 / 5 / 4), a 90 degree output, a 25 % duty
  180 degree output, alignment to CLKIN, LOCKED only with the feedback closed, reset.
* ``pll_base``: PLL_BASE with the MIG clocks (100 MHz x 10 / 1 = 1 GHz VCO): 125 MHz, 125 MHz a quarter period
  later (90 degrees), 62.5 MHz, 200 MHz, all starting on one CLKIN edge, duty 50 %; LOCKED after the lock time;
  reset.
"""

import random

import cocotb
from cocotb.clock import Clock
from cocotb.simtime import get_sim_time
from cocotb.triggers import RisingEdge, Timer

PS = 1          # every time below is in picoseconds
TOL_PS = 1      # the models' edges are within the simulator precision (1 ps) of their ideal times


def now():
    return get_sim_time("ps")


class Edges:
    """Records the rising and falling edge times of a signal (ps) from when it is started."""

    def __init__(self, signal):
        self.signal = signal
        self.rises, self.falls = [], []
        self.task = cocotb.start_soon(self._run())

    async def _run(self):
        while True:
            await self.signal.value_change
            v = str(self.signal.value)
            if v == "1":
                self.rises.append(now())
            elif v == "0":
                self.falls.append(now())

    def stop(self):
        self.task.cancel()


def _close(a, b, tol=TOL_PS):
    return abs(a - b) <= tol


def check_clock(name, edges, period_ps, *, high_ps=None, first_rise_ps=None, count=None, tol=TOL_PS):
    """Every rising edge ``first_rise + k * period`` (when given) and every period and high time as stated."""
    r, f = edges.rises, edges.falls
    assert len(r) >= (count or 3), f"{name}: only {len(r)} rising edges"
    if first_rise_ps is not None:
        assert _close(r[0], first_rise_ps, tol), f"{name}: first rising edge at {r[0]} ps, expected {first_rise_ps}"
    for k in range(1, len(r)):
        expect = r[0] + k * period_ps
        assert abs(r[k] - expect) <= tol, \
            f"{name}: rising edge {k} at {r[k]} ps, expected {expect:.1f} (period {period_ps:.3f} ps)"
    if high_ps is not None:
        for k, t in enumerate(r):
            falls = [x for x in f if x > t]
            if not falls:
                break
            assert abs(falls[0] - t - high_ps) <= tol, \
                f"{name}: high for {falls[0] - t} ps after rising edge {k}, expected {high_ps:.1f}"


# --------------------------------------------------------------------------------------------------------
# IO buffers
# --------------------------------------------------------------------------------------------------------

@cocotb.test(timeout_time=10, timeout_unit="us")
async def io_buffers(dut):
    cases = [(i, t, drive, value) for i in (0, 1) for t in (0, 1) for drive in (0, 1) for value in (0, 1)
             if not (t == 0 and drive == 1)]            # never two drivers on the pad
    random.Random(1).shuffle(cases)
    for i, t, drive, value in cases * 2:
        dut.buf_i.value, dut.buf_t.value, dut.pad_drive.value, dut.pad_value.value = i, t, drive, value
        await Timer(1, "ns")
        for name in ("ibuf_o", "ibufg_o", "bufg_o", "obuf_o"):
            assert str(getattr(dut, name).value) == str(i), f"{name} = {getattr(dut, name).value}, I = {i}"
        assert str(dut.obuft_o.value) == str(i if t == 0 else 1), \
            f"OBUFT: T = {t}, I = {i} reads {dut.obuft_o.value} (pulled up when released)"
        pad = i if t == 0 else (value if drive else 1)
        assert str(dut.pad.value) == str(pad), f"IOBUF pad: T = {t}, I = {i}, other driver {drive}/{value}"
        assert str(dut.iobuf_o.value) == str(pad), f"IOBUF O = {dut.iobuf_o.value}, pad = {pad}"


# --------------------------------------------------------------------------------------------------------
# FDCE / FDPE
# --------------------------------------------------------------------------------------------------------

@cocotb.test(timeout_time=10, timeout_unit="us")
async def flip_flops(dut):
    rng = random.Random(2)
    dut.ff_c.value = 0
    for s in ("ff_ce", "ff_clr", "ff_pre", "ff_d"):
        getattr(dut, s).value = 0
    await Timer(1, "ns")
    fdce, fdpe = 1, 0                     # INIT values of the bench's instances
    assert (int(dut.fdce_q.value), int(dut.fdpe_q.value)) == (fdce, fdpe), "INIT not applied at time 0"
    for cycle in range(200):
        ce, clr, pre, d = (rng.random() < 0.7, rng.random() < 0.1, rng.random() < 0.1, rng.getrandbits(1))
        async_pulse = rng.random() < 0.1
        dut.ff_ce.value, dut.ff_clr.value, dut.ff_pre.value, dut.ff_d.value = int(ce), int(clr), int(pre), d
        await Timer(1, "ns")
        if clr:
            fdce = 0                      # asynchronous: at once, before any clock edge
        if pre:
            fdpe = 1
        assert (int(dut.fdce_q.value), int(dut.fdpe_q.value)) == (fdce, fdpe), f"cycle {cycle}: async clear/preset"
        dut.ff_c.value = 1
        await Timer(1, "ns")
        if not clr and ce:
            fdce = d
        if not pre and ce:
            fdpe = d
        assert (int(dut.fdce_q.value), int(dut.fdpe_q.value)) == (fdce, fdpe), \
            f"cycle {cycle}: after the rising edge (CE {int(ce)}, CLR {int(clr)}, PRE {int(pre)}, D {d})"
        dut.ff_c.value = 0
        await Timer(1, "ns")
        assert (int(dut.fdce_q.value), int(dut.fdpe_q.value)) == (fdce, fdpe), f"cycle {cycle}: falling edge acted"
        if async_pulse:                   # a clear / preset pulse between clock edges
            dut.ff_clr.value, dut.ff_pre.value = 1, 1
            await Timer(1, "ns")
            fdce, fdpe = 0, 1
            assert (int(dut.fdce_q.value), int(dut.fdpe_q.value)) == (0, 1), f"cycle {cycle}: async pulse"
        dut.ff_clr.value, dut.ff_pre.value = 0, 0
        await Timer(1, "ns")


# --------------------------------------------------------------------------------------------------------
# ODDR
# --------------------------------------------------------------------------------------------------------

class OddrReference:
    """UG190's ODDR, event by event: ``rise``/``fall`` of C, ``inputs`` changing between edges."""

    def __init__(self, same_edge, async_sr, init):
        self.same, self.async_sr = same_edge, async_sr
        self.q = self.d2 = init

    def _set_reset(self, r, s):
        if r:
            self.q = self.d2 = 0
            return True
        if s:
            self.q = self.d2 = 1
            return True
        return False

    def inputs(self, ce, d1, d2, r, s):
        if self.async_sr:
            self._set_reset(r, s)

    def rise(self, ce, d1, d2, r, s):
        if not self._set_reset(r, s) and ce:
            self.q, self.d2 = d1, d2

    def fall(self, ce, d1, d2, r, s):
        if r:
            self.q = 0
        elif s:
            self.q = 1
        elif ce:
            self.q = self.d2 if self.same else d2


@cocotb.test(timeout_time=20, timeout_unit="us")
async def oddr(dut):
    period = 8000
    q = 2000
    rng = random.Random(3)
    outs = {"oddr_same_async": OddrReference(True, True, 0), "oddr_same_sync": OddrReference(True, False, 1),
            "oddr_opp_async": OddrReference(False, True, 0), "oddr_opp_sync": OddrReference(False, False, 1)}
    ins = dict(ce=1, d1=0, d2=0, r=0, s=0)

    def apply():
        for k, v in ins.items():
            getattr(dut, f"oddr_{k}").value = v
        for ref in outs.values():
            ref.inputs(**ins)

    def check(when):
        for name, ref in outs.items():
            got = str(getattr(dut, name).value)
            assert got == str(ref.q), f"{name} {when}: Q = {got}, expected {ref.q} (inputs {ins})"

    check("before any input is driven (INIT)")
    ins["ce"] = 0                         # the clock's first edge (Z -> 0) must not load anything
    apply()
    dut.oddr_c.value = 0
    await Timer(q, "ps")
    check("after the clock starts low (INIT kept)")
    ins["ce"] = 1
    apply()
    seen_r = seen_s = 0
    for cycle in range(300):
        # inputs change a quarter period after the rising edge: they are what the falling edge and the next
        # rising edge see, which is where SAME_EDGE and OPPOSITE_EDGE differ
        dut.oddr_c.value = 1
        for ref in outs.values():
            ref.rise(**ins)
        await Timer(q, "ps")
        check(f"cycle {cycle}, high phase")
        ins.update(ce=int(rng.random() < 0.85), d1=rng.getrandbits(1), d2=rng.getrandbits(1), r=0, s=0)
        x = rng.random()
        if cycle > 20 and x < 0.05:
            ins["r"] = 1
        elif cycle > 20 and x < 0.10:
            ins["s"] = 1
        seen_r += ins["r"]
        seen_s += ins["s"]
        apply()
        await Timer(1, "ps")
        check(f"cycle {cycle}, after the inputs changed (asynchronous reset/set)")
        await Timer(2 * q - q - 1, "ps")
        dut.oddr_c.value = 0
        for ref in outs.values():
            ref.fall(**ins)
        await Timer(q, "ps")
        check(f"cycle {cycle}, low phase")
        await Timer(period // 2 - q, "ps")
    assert seen_r and seen_s, "the sequence never exercised R and S"


# --------------------------------------------------------------------------------------------------------
# DCM_ADV
# --------------------------------------------------------------------------------------------------------

async def _release_and_lock(dut, clkin, rst, locked, period_ps, lock_ns, what, feedback_ps=0):
    """Hold ``rst``, release it just after a rising edge of the input, and return (release time, lock time).
    LOCKED must rise within [16 input periods (the period measurement) + lock time, + 2 input periods], plus
    ``feedback_ps`` (one feedback period: the PLL sees its feedback follow twice)."""
    rst.value = 1
    await Timer(50, "ns")
    await RisingEdge(clkin)
    await Timer(1, "ns")
    rst.value = 0
    t_rel = now()
    await Timer(1, "ns")
    assert str(locked.value) == "0", f"{what}: LOCKED high right after reset"
    await RisingEdge(locked)
    t_lock = now()
    lo = 16 * period_ps + lock_ns * 1000 + feedback_ps
    assert lo <= t_lock - t_rel <= lo + 2 * period_ps + 2, \
        f"{what}: LOCKED {t_lock - t_rel} ps after reset release, expected {lo}..{lo + 2 * period_ps} ps"
    return t_rel, t_lock


@cocotb.test(timeout_time=50, timeout_unit="us")
async def dcm(dut):
    tin = 10_000
    dut.dcm_rst.value = 1
    Clock(dut.dcm_clkin, tin, "ps").start()
    clkin = Edges(dut.dcm_clkin)
    fx, fx180 = Edges(dut.dcm_fx), Edges(dut.dcm_fx180)
    dll = {n: Edges(getattr(dut, f"dcm_{n}")) for n in ("clk0", "clk90", "clk180", "clk270", "clk2x", "clkdv")}
    t_rel, t_lock = await _release_and_lock(dut, dut.dcm_clkin, dut.dcm_rst, dut.dcm_fx_locked, tin, 1000,
                                            "CLKFX")
    assert not fx.rises or fx.rises[0] >= t_lock, "CLKFX toggled before LOCKED"
    await Timer(2, "us")
    for e in (fx, fx180, *dll.values()):
        e.stop()

    tfx = tin * 10 / 11
    check_clock("CLKFX", fx, tfx, high_ps=tfx / 2, first_rise_ps=t_lock)
    check_clock("CLKFX180", fx180, tfx, high_ps=tfx / 2, first_rise_ps=t_lock + tfx / 2)
    in_rises = [t for t in clkin.rises if t >= t_lock]
    for k in range(0, len(fx.rises), 11):          # 11 CLKFX periods = 10 CLKIN periods
        assert any(_close(fx.rises[k], t) for t in in_rises), f"CLKFX edge {k} is not on a CLKIN edge"
    assert not any(_close(fx.rises[k], t) for k in (1, 2, 5) for t in in_rises), "CLKFX at CLKIN's frequency?"

    # DLL (feedback 1X, fixed phase shift 32/256 of the input period) -- locked once CLKFB followed CLK0
    assert str(dut.dcm_dll_locked.value) == "1", "the DLL with its feedback connected did not lock"
    shift = tin * 32 / 256
    t0 = dll["clk0"].rises[0]
    assert any(_close(t0 - shift, t) for t in clkin.rises), "CLK0 is not PHASE_SHIFT/256 after a CLKIN edge"
    for name, period, offset in (("clk0", tin, 0), ("clk90", tin, tin / 4), ("clk180", tin, tin / 2),
                                 ("clk270", tin, 3 * tin / 4), ("clk2x", tin / 2, 0), ("clkdv", 4 * tin, 0)):
        check_clock(f"DLL {name}", dll[name], period, high_ps=period / 2, first_rise_ps=t0 + offset)
    assert str(dut.dcm_nofb_locked.value) == "0", "a DLL without feedback locked"

    # Reset while running: outputs and LOCKED low at once, then a new lock.
    await Timer(333, "ns")
    dut.dcm_rst.value = 1
    await Timer(1, "ps")
    for s in ("dcm_fx", "dcm_fx180", "dcm_fx_locked", "dcm_clk0", "dcm_dll_locked"):
        assert str(getattr(dut, s).value) == "0", f"{s} not low during reset"
    fx_during = Edges(dut.dcm_fx)
    await Timer(200, "ns")
    assert not fx_during.rises, "CLKFX toggled in reset"
    fx_during.stop()
    await _release_and_lock(dut, dut.dcm_clkin, dut.dcm_rst, dut.dcm_fx_locked, tin, 1000, "CLKFX after reset")


# --------------------------------------------------------------------------------------------------------
# PLL_ADV
# --------------------------------------------------------------------------------------------------------

@cocotb.test(timeout_time=50, timeout_unit="us")
async def pll(dut):
    tin, tpix = 10_000, 9_090
    dut.pll_rst.value = 1
    dut.pix_rst.value = 1
    Clock(dut.pll_clkin, tin, "ps").start()
    Clock(dut.pix_clkin, tpix, "ps").start()
    pix_in = Edges(dut.pix_clkin)
    cam = Edges(dut.pll_cam_out)
    pix = [Edges(getattr(dut, f"pll_pix_out{n}")) for n in range(3)]
    nofb = Edges(dut.pll_nofb_out0)
    lock_cam = cocotb.start_soon(_release_and_lock(dut, dut.pll_clkin, dut.pll_rst, dut.pll_cam_locked, tin, 2000,
                                                   "camera PLL", feedback_ps=tin))
    _, t_lock = await _release_and_lock(dut, dut.pix_clkin, dut.pix_rst, dut.pll_pix_locked, tpix, 2000,
                                        "pixel PLL", feedback_ps=5 * tpix)
    _, t_lock_cam = await lock_cam
    await Timer(3, "us")
    for e in (cam, *pix, nofb):
        e.stop()

    # 100 MHz x 6 / 1 = 600 MHz VCO, / 25 = 24 MHz
    tcam = tin * 1 / 6 * 25
    check_clock("camera PLL CLKOUT0", cam, tcam, high_ps=tcam / 2)
    assert cam.rises[0] <= t_lock_cam, "LOCKED before the outputs run"
    # pixel PLL: VCO = CLKIN x 27 / 5, CLKOUT0 and 1 / 4, CLKOUT1 90 degrees, CLKOUT2 / 8, 180 degrees, 25 % duty
    t0 = tpix * 5 / 27 * 4
    start = pix[0].rises[0]
    assert any(_close(start, t) for t in pix_in.rises), "CLKOUT0 does not start on a CLKIN edge"
    check_clock("pixel PLL CLKOUT0", pix[0], t0, high_ps=t0 / 2)
    check_clock("pixel PLL CLKOUT1", pix[1], t0, high_ps=t0 / 2, first_rise_ps=start + t0 / 4)
    t2 = 2 * t0
    check_clock("pixel PLL CLKOUT2", pix[2], t2, high_ps=t2 / 4, first_rise_ps=start + t2 / 2)
    in_rises = [t for t in pix_in.rises if t >= start]
    for k in range(0, len(pix[0].rises), 27):      # 27 output periods = 20 input periods
        assert any(_close(pix[0].rises[k], t) for t in in_rises), f"CLKOUT0 edge {k} is not on a CLKIN edge"
    assert str(dut.pll_nofb_locked.value) == "0", "a PLL without feedback locked"

    # Reset while running.
    dut.pix_rst.value = 1
    await Timer(1, "ps")
    for s in ("pll_pix_out0", "pll_pix_out1", "pll_pix_locked"):
        assert str(getattr(dut, s).value) == "0", f"{s} not low during reset"
    during = Edges(dut.pll_pix_out0)
    await Timer(300, "ns")
    assert not during.rises, "CLKOUT0 toggled in reset"
    during.stop()
    await _release_and_lock(dut, dut.pix_clkin, dut.pix_rst, dut.pll_pix_locked, tpix, 2000,
                            "pixel PLL after reset", feedback_ps=5 * tpix)


# --------------------------------------------------------------------------------------------------------
# PLL_BASE
# --------------------------------------------------------------------------------------------------------

@cocotb.test(timeout_time=50, timeout_unit="us")
async def pll_base(dut):
    tin = 10_000
    dut.mem_rst.value = 1
    Clock(dut.mem_clkin, tin, "ps").start()
    clkin = Edges(dut.mem_clkin)
    outs = {n: Edges(getattr(dut, f"mem_{n}")) for n in ("clk0", "clk90", "clkdiv0", "clk200")}
    _, t_lock = await _release_and_lock(dut, dut.mem_clkin, dut.mem_rst, dut.mem_locked, tin, 2000, "MIG PLL",
                                        feedback_ps=tin)
    await Timer(2, "us")
    for e in outs.values():
        e.stop()
    # VCO = 100 MHz x 10 / 1 = 1 GHz (1000 ps): clk0 / 8 = 8000 ps, clk90 / 8 a quarter period later,
    # clkdiv0 / 16 = 16000 ps, clk200 / 5 = 5000 ps
    start = outs["clk0"].rises[0]
    assert start <= t_lock, "LOCKED before the outputs run"
    assert any(_close(start, t) for t in clkin.rises), "clk0 does not start on a CLKIN edge"
    for name, period, offset in (("clk0", 8000, 0), ("clk90", 8000, 2000), ("clkdiv0", 16000, 0),
                                 ("clk200", 5000, 0)):
        check_clock(f"MIG PLL {name}", outs[name], period, high_ps=period / 2, first_rise_ps=start + offset)
    # reset: outputs and LOCKED low at once, then a new lock
    dut.mem_rst.value = 1
    await Timer(1, "ps")
    for s in ("mem_clk0", "mem_clk200", "mem_locked"):
        assert str(getattr(dut, s).value) == "0", f"{s} not low during reset"
    await _release_and_lock(dut, dut.mem_clkin, dut.mem_rst, dut.mem_locked, tin, 2000, "MIG PLL after reset",
                            feedback_ps=tin)
