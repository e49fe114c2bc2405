"""Clocking: the board's M/D/O plan against the required frequencies, the primitives' parameters in the exported
Verilog, and the reset tree of the simulation model (per-domain, held until lock, released synchronously)."""

import re
from fractions import Fraction

import pytest
from amaranth import Elaboratable, Module, Signal
from amaranth.back import verilog

from board.clocking import PLAN, ClockPlan, GenesysClocking
from sim.models.clocking import SimClocking
from spec.board import CLOCKS
from spec.video import CEA_1080P60
from sim.runners.amaranth import simulate

FREQS = {"sync": 100e6, "pix": 148.5e6, "cam_a": 48e6, "cam_b": 37e6}


def test_plan_gives_the_exact_frequencies():
    # Targets from the spec: 24 MHz MCLK (100 / 25 * 6), CEA-861 1080p60 pixel clock 148.5 MHz.
    assert PLAN.mclk_hz == Fraction(24_000_000)
    assert PLAN.pix_hz == Fraction(CEA_1080P60.pixel_hz) == Fraction(148_500_000)
    assert PLAN.osc_hz == CLOCKS.SYS_HZ == 100_000_000
    for _, _, f, target, ppm in PLAN.table():
        assert f == target and ppm == 0.0


def test_one_dcm_cannot_make_the_pixel_clock():
    """The reason for the DCM -> PLL cascade: no CLKFX M/D (M 2..32, D 1..32) gives 148.5 MHz from 100 MHz."""
    target = Fraction(148_500_000, 100_000_000)
    assert all(Fraction(mm, dd) != target for mm in range(2, 33) for dd in range(1, 33))
    best = min((abs(Fraction(mm, dd) - target), mm, dd) for mm in range(2, 33) for dd in range(1, 33))
    assert best[0] > 0


@pytest.mark.parametrize("change, message", [
    (dict(dcm_m=33), "CLKFX_MULTIPLY"),
    (dict(dcm_d=0), "CLKFX_DIVIDE"),
    (dict(pix_pll_m=10), "VCO"),            # 22 MHz * 10 = 220 MHz VCO: too low
    (dict(cam_pll_m=12), "VCO"),            # 1200 MHz: above the conservative maximum
    (dict(pix_pll_d=6), "PFD"),             # 110 / 6 = 18.3 MHz
    (dict(cam_pll_o=129), "CLKOUT_DIVIDE"),
])
def test_plan_check_rejects_out_of_range_values(change, message):
    with pytest.raises(ValueError, match=message):
        ClockPlan(**change).check()


def _instances(text, cell):
    """``{instance_name: {param: value}}`` for every ``cell #(...) name (`` in Verilog text."""
    out = {}
    for match in re.finditer(rf"{cell} #\((.*?)\)\s*(\S+)\s*\(", text, re.S):
        params = dict(re.findall(r"\.(\w+)\(([^()]*)\)", match.group(1)))
        out[match.group(2)] = {k: v.strip('"') for k, v in params.items()}
    return out


def _num(value):
    return float(value.split("'d")[-1])


class _Wrap(Elaboratable):
    def __init__(self, clocking):
        self.clocking = clocking

    def elaborate(self, platform):
        m = Module()
        m.domains += self.clocking.domains
        m.submodules.clocking = self.clocking
        for d in self.clocking.domain_names:
            s = Signal(name=f"t_{d}")
            m.d[d] += s.eq(~s)
        return m


def test_board_primitives_carry_the_plan():
    """Recompute every output frequency from the parameters in the exported Verilog (Xilinx formulas:
    CLKFX = CLKIN * M / D; PLL output = CLKIN * CLKFBOUT_MULT / DIVCLK_DIVIDE / CLKOUTn_DIVIDE)."""
    g = GenesysClocking()
    pclks = [getattr(g.cam_pclk, d) for d in g.cam_domains]
    text = verilog.convert(_Wrap(g), ports=[g.clk100, g.button, g.locked, *pclks])
    dcms = _instances(text, "DCM_ADV")
    plls = _instances(text, "PLL_ADV")
    assert list(dcms) == ["dcm_pix"] and sorted(plls) == ["pll_cam", "pll_pix"]
    osc = 1e3 / _num(dcms["dcm_pix"]["CLKIN_PERIOD"])                  # MHz
    fx = osc * _num(dcms["dcm_pix"]["CLKFX_MULTIPLY"]) / _num(dcms["dcm_pix"]["CLKFX_DIVIDE"])
    pix = plls["pll_pix"]
    assert 1e3 / _num(pix["CLKIN1_PERIOD"]) == pytest.approx(fx)
    vco = fx * _num(pix["CLKFBOUT_MULT"]) / _num(pix["DIVCLK_DIVIDE"])
    assert vco / _num(pix["CLKOUT0_DIVIDE"]) == pytest.approx(148.5, abs=1e-9)
    assert vco / _num(pix["CLKOUT1_DIVIDE"]) == pytest.approx(148.5, abs=1e-9)
    assert _num(pix["CLKOUT1_PHASE"]) == 90.0 and _num(pix["CLKOUT0_PHASE"]) == 0.0
    assert pix["COMPENSATION"] == "DCM2PLL"
    cam = plls["pll_cam"]
    cam_vco = 1e3 / _num(cam["CLKIN1_PERIOD"]) * _num(cam["CLKFBOUT_MULT"]) / _num(cam["DIVCLK_DIVIDE"])
    assert cam_vco / _num(cam["CLKOUT0_DIVIDE"]) == pytest.approx(24.0, abs=1e-9)
    assert all(p["RESET_ON_LOSS_OF_LOCK"] == "FALSE" for p in plls.values())
    # Every domain clock is a global buffer output.
    assert text.count("BUFG ") == len(g.domain_names)


def _reset_bench(lock_cycles, press_at_ns):
    clocking = SimClocking(lock_cycles=lock_cycles)
    dut = _Wrap(clocking)
    log = []   # (time_ns, domain, reset) at every change of any domain's reset or of locked

    async def watch(ctx):
        resets = {cd.name: cd.rst for cd in clocking.domains}
        clocks = {cd.name: cd.clk for cd in clocking.domains}
        last = None
        edges = {d: [] for d in clocking.domain_names}
        prev_clk = {d: 0 for d in clocking.domain_names}
        t = 0
        while t < 2000:
            await ctx.delay(0.25e-9)
            t += 0.25
            state = {d: ctx.get(r) for d, r in resets.items()}
            state["locked"] = ctx.get(clocking.locked)
            for d, c in clocks.items():
                v = ctx.get(c)
                if v and not prev_clk[d]:
                    edges[d].append(t)
                prev_clk[d] = v
            if state != last:
                log.append((t, state))
                last = state
            if abs(t - press_at_ns) < 0.125:
                ctx.set(clocking.button, 1)
            if abs(t - press_at_ns - 50) < 0.125:
                ctx.set(clocking.button, 0)
        log.append(("edges", edges))

    simulate(dut, clocks=FREQS, testbenches=[watch])
    return clocking, log


def test_sim_resets_held_until_lock_then_released_per_domain():
    clocking, log = _reset_bench(lock_cycles=20, press_at_ns=1000)
    edges = log.pop()[1]
    states = log
    domains = clocking.domain_names
    # 1. Every domain is in reset from time 0 until locked rises.
    lock_t = next(t for t, s in states if s["locked"])
    for t, s in states:
        if t < lock_t:
            assert all(s[d] for d in domains), (t, s)
    # locked rises after lock_cycles sync clocks (10 ns each), counted from the first sync edge.
    assert lock_t == pytest.approx(edges["sync"][20 - 1], abs=0.5)
    # 2. Each domain leaves reset on one of its own clock edges, 2 or 3 of its edges after locked.
    for d in domains:
        release = next(t for t, s in states if t > lock_t and not s[d])
        later_edges = [e for e in edges[d] if e > lock_t]
        assert release in [pytest.approx(e, abs=0.3) for e in later_edges[1:3]], (d, release, later_edges[:4])
    # 3. The button asserts every reset at once (asynchronously) and they are released again after re-lock.
    press = next(t for t, s in states if t >= 1000 and all(s[d] for d in domains))
    assert press == pytest.approx(1000.25, abs=0.3)
    after = [s for t, s in states if t > 1100]
    assert after and not any(after[-1][d] for d in domains)


def test_sim_clocking_rejects_zero_lock_time():
    with pytest.raises(ValueError, match="lock_cycles"):
        SimClocking(lock_cycles=0)
