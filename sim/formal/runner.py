"""Formal safety properties of Amaranth blocks: named assertions, assumptions and covers, proven with Yosys/ABC.

A harness is a :class:`FormalHarness` subclass whose :meth:`~FormalHarness.build` instantiates the block under
test, drives its inputs from :meth:`~FormalHarness.free` signals (unconstrained: any value on any clock) and
states named properties::

    class CounterHarness(FormalHarness):
        name = "counter"
        block = "Counter"

        def build(self, m):
            m.submodules.dut = dut = Counter(limit=9)
            m.d.comb += dut.enable.eq(self.free("enable"))
            self.prove(m, "in_range", dut.count <= 9)
            self.cover(m, "wraps", dut.count == 9)

``check(CounterHarness())`` then

* proves every property without a ``bound`` for all time, with the harness's ``engine`` ("pdr": ABC's IC3, or
  "induction": Yosys's k-induction), and checks each property with ``bound=k`` for the first ``k`` clocks (BMC);
* searches, for each cover, a trace that makes it true: a proof whose covers are not all reached may hold
  vacuously, and the check fails (an unreached cover is proven unreachable; a cover with ``bound=k`` is searched
  by BMC in the first ``k`` clocks only, for one too deep for PDR, and then is reported not reached within k);
* on a failure, writes the counterexample to ``build/formal/<name>/<group>.vcd`` and a one-line summary naming
  the property (the first ``assert_<property>`` wire that is 0 in the trace); each cover trace goes to
  ``cover_<cover>.vcd``.

Every property becomes a wire ``assert_<name>`` / ``assume_<name>`` / ``cover_<name>`` in the harness (so
the traces show each one) and an Amaranth ``Assert`` / ``Assume`` / ``Cover`` on it, in the combinational domain
(checked on every clock). The harness's ``sync`` reset is an input like any other: properties must hold
across resets, and registers start at their ``init`` values. See :mod:`sim.formal.engines` for the engines.

A proof elaborates the harness, and so every block in it, for the platform ``"formal"`` (:data:`PLATFORM`): a
block's own invariants, under ``if platform == "formal":`` as in ``amaranth.lib.fifo``, are asserted with the
harness's properties in every proof group (an ``Assert`` named by its message), so that the proof is inductive
without the harness reaching into the block's state. Simulation and Verilog export never elaborate them. A
counterexample that breaks only a block's invariant is named by replaying it for the formal platform in Amaranth's
simulator (:func:`broken_invariant`).
"""

import keyword
import time
from dataclasses import dataclass, field
from pathlib import Path

from amaranth import ClockDomain, Fragment, Module, Mux, Signal, Value
from amaranth.back import rtlil
from amaranth.hdl import Assert, Assume, Cover
from amaranth.sim import Simulator

from sim.runners import build_dir

from . import engines

__all__ = ["FormalHarness", "Property", "Report", "check", "replay", "broken_invariant", "format_table",
           "DEFAULT_OUTDIR", "PLATFORM"]

DEFAULT_OUTDIR = build_dir("formal")
#: Clock period of the replayed traces (the VCDs): 10 ns, one clock per proof step.
PERIOD = 10e-9
#: The platform a proof elaborates the harness (and so every block in it) for: a block's own invariants live under
#: ``if platform == "formal":`` (as in ``amaranth.lib.fifo``) and are proven with the harness's properties, as
#: assertions named by their message. Simulation and Verilog export never elaborate them.
PLATFORM = "formal"


@dataclass(frozen=True)
class Property:
    kind: str          # "assert", "assume" or "cover"
    name: str
    wire: Signal
    bound: int | None = None
    group: str | None = None


class FormalHarness:
    """Base class of a formal harness; see the module docstring.

    Class attributes: ``name`` (directory and table label), ``block`` (the block under test, for the table),
    ``engine`` ("pdr" or "induction") for the unbounded properties, ``max_steps`` (k-induction limit),
    ``timeout`` (seconds of wall clock for each tool run before the check reports a tool error).
    """
    name = None
    block = None
    engine = "pdr"
    max_steps = 20
    timeout = 600

    def __init__(self):
        self._select = None
        self._platform = None
        self._reset()

    def _reset(self):
        self._properties = []
        self._tests = {}
        self._free = []
        self._past_valid = {}

    # --- what a subclass writes ---------------------------------------------------------------------------

    def build(self, m):
        raise NotImplementedError

    def free(self, name, shape=1):
        """An input driven by the environment: any value on any clock, unless an assumption restricts it."""
        signal = Signal(shape, name=name)
        self._free.append(Value.cast(signal))          # the port is the plain signal under an enum/struct view
        return signal

    def prove(self, m, name, test, *, bound=None, group=None):
        """Assert ``test`` on every clock (for all time, or for the first ``bound`` clocks). Properties with the
        same ``bound`` and ``group`` are proven together, in one run of the engine; a ``group`` (a label) splits
        off properties that are not each other's lemmas: PDR on two unrelated cones at once is slower than on
        each alone."""
        return self._property(m, "assert", name, test, bound, group)

    def assume(self, m, name, test):
        """Restrict the environment to traces where ``test`` holds on every clock (an interface contract)."""
        return self._property(m, "assume", name, test, None)

    def cover(self, m, name, test, *, bound=None):
        """A case the properties must be able to see: the check fails unless some trace makes ``test`` true
        (within the first ``bound`` clocks if given: searched by BMC, not PDR, for a cover hundreds of clocks
        deep)."""
        return self._property(m, "cover", name, test, bound)

    def open(self, m, name, dut):
        """Elaborate ``dut`` now and add its ``Module`` as submodule ``name`` (in place of ``dut``, which is then
        not elaborated again); returns the ``Module``, so that properties can use the ports of its submodules
        (``module.submodules.<name>``), not only its own. ``dut`` itself is then never elaborated by Amaranth: a
        harness file carries Amaranth's ``# amaranth: UnusedElaboratable=no`` linter comment for the blocks it
        creates. ``dut`` is elaborated for the harness's platform (:data:`PLATFORM` in a proof)."""
        module = dut.elaborate(self._platform)
        m.submodules[name] = module
        return module

    def hold(self, m, name, value):
        """Assume ``value`` (a :meth:`free` input) keeps, from the second clock on and across resets, whatever value
        it took at the first: one arbitrary, fixed choice (a watched address or column)."""
        later = Signal(name=f"{name}_later", reset_less=True)
        m.d.sync += later.eq(1)
        self.assume(m, name, ~later | (value == self.past(m, value, name=f"past_{name}", reset_less=True)))

    def assume_pixel_groups(self, m, token, groups):
        """The engine's token contract for a block fed a pixel's ``groups`` groups: in consecutive clocks from group
        0, one x, ``last`` on the last group."""
        expect = Signal(range(groups), name="expected_group")
        x_held = Signal.like(token.x, name="pixel_x")
        with m.If(token.go):
            m.d.sync += [expect.eq(Mux(token.group == groups - 1, 0, token.group + 1)), x_held.eq(token.x)]
        self.assume(m, "groups_in_order", ~token.go | (token.group == expect))
        self.assume(m, "pixel_groups_consecutive", (expect == 0) | (token.go & (token.x == x_held)))
        self.assume(m, "last_on_the_last_group", ~token.go | (token.last == (token.group == groups - 1)))

    def past(self, m, value, clocks=1, *, name=None, reset_less=False):
        """``value`` as it was ``clocks`` clocks ago (registers, reset with the design unless ``reset_less``:
        guard the use with :meth:`past_valid`)."""
        for i in range(clocks):
            reg = Signal.like(value, name=f"{name or 'past'}_{i + 1}", init=0, reset_less=reset_less)
            m.d.sync += reg.eq(value)
            value = reg
        return value

    def past_valid(self, m, clocks=1):
        """1 once ``clocks`` clocks have passed since the last reset (so :meth:`past` values are real)."""
        if clocks not in self._past_valid:
            count = Signal(range(clocks + 1), name=f"past_valid_{clocks}")
            with m.If(count != clocks):
                m.d.sync += count.eq(count + 1)
            self._past_valid[clocks] = count == clocks
        return self._past_valid[clocks]

    # --- what the runner uses -----------------------------------------------------------------------------

    def _property(self, m, kind, name, test, bound, group=None):
        if not name.isidentifier() or keyword.iskeyword(name):
            raise ValueError(f"property name {name!r} must be an identifier")
        if any(p.name == name for p in self._properties):
            raise ValueError(f"property {name!r} is declared twice in {type(self).__name__}")
        if bound is not None and (not isinstance(bound, int) or bound < 1):
            raise ValueError(f"bound of {name!r} must be a positive number of clocks, not {bound!r}")
        wire = Signal(name=f"{kind}_{name}")
        self._tests[name] = test                     # driven in elaborate if the selection needs it
        prop = Property(kind, name, wire, bound, group)
        self._properties.append(prop)
        return wire

    def elaborate(self, platform):
        self._reset()
        self._platform = platform
        m = Module()
        m.domains.sync = self._domain = ClockDomain("sync")
        self.build(m)
        for p in self._properties:
            # A proof group's model holds its own assertions' cones only: the other groups' property wires (kept
            # for the traces) would keep theirs, and PDR is slower with them.
            group = isinstance(self._select, tuple) and p.kind != "assume" and self._select != ("bound", p.bound,
                                                                                                 p.group)
            if not (group or (self._select == "covers" and p.kind == "assert")):
                m.d.comb += p.wire.eq(self._tests[p.name])
            if p.kind == "assume" and self._select != "replay":
                m.d.comb += Assume(p.wire, p.name)
            elif p.kind == "assert" and self._select == ("bound", p.bound, p.group):
                m.d.comb += Assert(p.wire, p.name)
            elif p.kind == "cover" and self._select == "covers":
                # For the search: an assertion that the cover never happens, whose counterexample is the trace.
                uncovered = Signal(name=f"uncovered_{p.name}")
                m.d.comb += [uncovered.eq(~p.wire), Cover(p.wire, p.name), Assert(uncovered, p.name)]
        return m

    def properties(self, kind=None):
        """The declared properties (elaborates the harness)."""
        Fragment.get(self.elaborate(None), None)
        return [p for p in self._properties if kind is None or p.kind == kind]

    def rtlil(self, select):
        """RTLIL of the harness with the assertions of one group (``("bound", None, group)`` for the unbounded
        ones, ``("bound", k, group)``) or, for ``"covers"``, the covers only; the blocks' own invariants in each."""
        self._select = select
        try:
            m = self.elaborate(PLATFORM)
            ports = [self._domain.clk, self._domain.rst, *self._free]
            return rtlil.convert(m, name="top", platform=PLATFORM, ports=ports)
        finally:
            self._select = None


def replay(harness, frames, vcd):
    """Run ``harness`` in Amaranth's simulator on a trace (``frames``: the input ports' values on each clock),
    writing every signal to ``vcd``; the value of each property wire on each clock, ``[{name: 0/1}]``.

    The proof engines work on Yosys's model of the design; this replay is Amaranth's own semantics, so a
    trace that does not make the same property fail here points at a tool problem, not at the design."""
    harness._select = "replay"               # no Assert/Assume cells: the simulator would raise on them
    try:
        m = harness.elaborate(None)
    finally:
        harness._select = None
    ports = {s.name: s for s in (harness._domain.rst, *harness._free)}
    wires = {f"{p.kind}_{p.name}": p.wire for p in harness._properties}
    seen = []

    async def testbench(ctx):
        for frame in frames:
            for name, value in frame.items():
                if name in ports:
                    ctx.set(ports[name], value)
            seen.append({name: ctx.get(wire) for name, wire in wires.items()})
            await ctx.tick()

    sim = Simulator(m)
    sim.add_clock(PERIOD)
    sim.add_testbench(testbench)
    vcd = Path(vcd)
    vcd.parent.mkdir(parents=True, exist_ok=True)
    traces = [harness._domain.rst, *harness._free, *wires.values()]
    with sim.write_vcd(str(vcd), str(vcd.with_suffix(".gtkw")), traces=traces):
        sim.run()
    return seen


def broken_invariant(harness, frames):
    """The first of the blocks' own invariants (``platform == "formal"``) that a trace breaks in Amaranth's
    simulator, as ``(clock, message)``, or None: the simulator raises ``AssertionError("Assertion violated:
    <message>")`` at the edge that ends the clock whose values break a block's ``Assert`` (a block states its
    invariants in its ``sync`` domain, so the simulator checks settled values, not a combinational update in
    progress)."""
    harness._select = "replay"               # the harness's properties as wires only, the blocks' Asserts kept
    try:
        m = harness.elaborate(PLATFORM)
        fragment = Fragment.get(m, PLATFORM)
    finally:
        harness._select = None
    ports = {s.name: s for s in (harness._domain.rst, *harness._free)}
    clock = [0]

    async def testbench(ctx):
        for frame in frames:
            clock[0] += 1
            for name, value in frame.items():
                if name in ports:
                    ctx.set(ports[name], value)
            await ctx.tick()

    sim = Simulator(fragment)
    sim.add_clock(PERIOD)
    sim.add_testbench(testbench)
    try:
        sim.run()
    except AssertionError as exc:
        message = str(exc)
        prefix = "Assertion violated: "
        if message.startswith(prefix):
            return clock[0], message[len(prefix):]
        raise
    return None


def _violations(seen, kind, names, value):
    """The first clock (from 1) at which some ``kind`` wire of ``names`` has ``value``, and those names."""
    for step, wires in enumerate(seen, start=1):
        hit = [n for n in names if wires.get(f"{kind}_{n}") == value]
        if hit:
            return step, hit
    return None, []


@dataclass
class GroupResult:
    bound: int | None
    group: str | None
    engine: str
    names: list
    outcome: engines.Outcome
    seconds: float
    failed: list = field(default_factory=list)
    vcd: Path | None = None

    @property
    def ok(self):
        return self.outcome.status in ("proved", "passed")

    @property
    def proof(self):
        proof = "unbounded" if self.bound is None else f"bounded, {self.bound} clocks"
        return proof if self.group is None else f"{proof} ({self.group})"

    @property
    def label(self):
        """The group's directory and trace name."""
        label = "unbounded" if self.bound is None else f"bounded_{self.bound}"
        return label if self.group is None else f"{label}_{self.group}"


@dataclass
class Report:
    harness: str
    block: str
    groups: list
    covers: dict                   # cover name -> Outcome
    cover_vcds: dict
    seconds: float

    @property
    def ok(self):
        return all(g.ok for g in self.groups) and all(o.status == "reached" for o in self.covers.values())

    @property
    def property_count(self):
        return sum(len(g.names) for g in self.groups)

    def lines(self):
        """One line per failed group or unreached cover; one line saying it all held otherwise."""
        out = []
        for g in self.groups:
            if g.outcome.status == "failed":
                which = ", ".join(g.failed) or "(no assert_ wire is 0 in the trace)"
                verb = "fails" if len(g.failed) == 1 else "fail"
                out.append(f"FAIL {self.harness}: {which} {verb} at clock {g.outcome.steps} "
                           f"({g.engine}, {g.proof}); counterexample: {g.vcd}")
            elif not g.ok:
                out.append(f"UNKNOWN {self.harness}: {g.engine} did not close the proof of "
                           f"{', '.join(g.names)} within {g.outcome.steps} steps")
        for name, o in self.covers.items():
            if o.status != "reached":
                out.append(f"UNREACHED {self.harness}: cover {name} " +
                           (f"not reached within {o.steps} clocks (bmc3)" if o.steps else "is unreachable"))
        if not out:
            out.append(f"PASS {self.harness}: {self.property_count} properties, "
                       f"{len(self.covers)} covers reached, {self.seconds:.1f} s")
        return out


def _run_group(harness, bound, group, names, workdir, outdir):
    start = time.perf_counter()
    text = harness.rtlil(("bound", bound, group))
    if bound is not None:
        engine, outcome = "bmc", engines.bmc(text, workdir, depth=bound, timeout=harness.timeout)
    elif harness.engine == "pdr":
        engine, outcome = "pdr", engines.prove_pdr(text, workdir, timeout=harness.timeout)
    elif harness.engine == "induction":
        engine = "induction"
        outcome = engines.prove_induction(text, workdir, max_steps=harness.max_steps, timeout=harness.timeout)
    else:
        raise ValueError(f"unknown engine {harness.engine!r} in {type(harness).__name__}")
    result = GroupResult(bound, group, engine, names, outcome, 0.0)
    if outcome.status == "failed":
        result.vcd = outdir / f"{result.label}.vcd"
        seen = replay(harness, outcome.frames, result.vcd)
        _check_assumptions(harness, seen, result.vcd)
        step, result.failed = _violations(seen, "assert", names, 0)
        # The first to fail: the harness's properties, and a block's invariant if it fails no later.
        invariant = broken_invariant(harness, outcome.frames)
        if invariant is not None and (step is None or invariant[0] <= step):
            result.failed.append(f"{invariant[1]} (a block's invariant, clock {invariant[0]})")
        if not result.failed:
            raise engines.FormalToolError(f"{harness.name}: the {engine} counterexample does not make any "
                                          f"assertion fail in Amaranth's simulator (see {result.vcd})")
    result.seconds = time.perf_counter() - start
    return result


def _check_assumptions(harness, seen, vcd):
    step, broken = _violations(seen, "assume", [p.name for p in harness._properties if p.kind == "assume"], 0)
    if broken:
        raise engines.FormalToolError(f"{harness.name}: the trace breaks assumption {', '.join(broken)} at "
                                      f"clock {step} in Amaranth's simulator (see {vcd})")


def check(harness, *, outdir=DEFAULT_OUTDIR, covers=True):
    """Prove every property of ``harness`` and search every cover; a :class:`Report`."""
    if not harness.name:
        raise ValueError(f"{type(harness).__name__} needs a name")
    start = time.perf_counter()
    outdir = Path(outdir) / harness.name
    workdir = outdir / "work"
    for old in [*outdir.glob("*.vcd"), *outdir.glob("*.gtkw")]:      # traces of an earlier run
        old.unlink()
    asserts = harness.properties("assert")
    if not asserts:
        raise ValueError(f"{harness.name} declares no assertion")
    keys = sorted({(p.bound, p.group) for p in asserts}, key=lambda k: (-1 if k[0] is None else k[0], k[1] or ""))
    groups = []
    for bound, group in keys:
        label = GroupResult(bound, group, "", [], None, 0.0).label
        names = [p.name for p in asserts if (p.bound, p.group) == (bound, group)]
        groups.append(_run_group(harness, bound, group, names, workdir / label, outdir))
    cover_results, cover_vcds = {}, {}
    # Covers make a passing proof meaningful; a failing one already has its counterexample.
    proved = all(g.ok for g in groups)
    names = [p.name for p in harness.properties("cover")] if covers and proved else []
    if names:
        bounds = {p.name: p.bound for p in harness.properties("cover")}
        cover_results = engines.reach(harness.rtlil("covers"), workdir / "covers", names, bounds=bounds,
                                      timeout=harness.timeout)
        for n, o in cover_results.items():
            if o.status == "reached":
                cover_vcds[n] = vcd = outdir / f"cover_{n}.vcd"
                seen = replay(harness, o.frames, vcd)
                _check_assumptions(harness, seen, vcd)
                if _violations(seen, "cover", [n], 1)[0] is None:
                    raise engines.FormalToolError(f"{harness.name}: the trace of cover {n} does not reach it "
                                                  f"in Amaranth's simulator (see {vcd})")
    return Report(harness.name, harness.block or harness.name, groups, cover_results, cover_vcds,
                  time.perf_counter() - start)


def format_table(reports):
    """The summary table: one row per proof (block, properties, unbounded or bounded to k, engine, result, its
    time, covers reached, the harness's whole time with the cover searches)."""
    rows = [("block", "harness", "properties", "proof", "engine", "result", "proof time", "covers",
             "with covers")]
    for r in reports:
        reached = sum(o.status == "reached" for o in r.covers.values())
        for i, g in enumerate(r.groups):
            first = i == 0
            rows.append((r.block, r.harness, str(len(g.names)), g.proof, g.engine,
                         "ok" if g.ok else g.outcome.status, f"{g.seconds:.1f} s",
                         f"{reached}/{len(r.covers)}" if first else "", f"{r.seconds:.1f} s" if first else ""))
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    lines = ["  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip() for row in rows]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)
