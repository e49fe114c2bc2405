"""``StoreWindows.display_missed`` (hdl/store_windows.py): a compositor read the frame store refuses and the picture
uses fires it; the subtractor's no-data reads (address 0 below the left window) and the engine's waits do not. The
streams are driven by hand: a row lands when the test says so."""

from amaranth.sim import Simulator

from dataclasses import replace

from hdl.config import DesignConfig
from hdl.store_windows import StoreWindows

CONFIG = DesignConfig.small()
G = CONFIG.geometry
W = G.buf_width


def run(steps, layout=CONFIG.layout, asked=None):
    """Apply ``steps`` -- per clock a dict of the windows' inputs to set (``"left"``/``"right"``/``"engine"``: an
    address to request, ``"landed"``: streams whose row lands, ``"taken"``, ``"maps"``: the maps' restart line,
    ``"rectification"``, ``"engine_start"``) -- and return ``display_missed`` in each clock; ``asked`` (a list per
    stream), if given, gets the rows each stream is asked for."""
    dut = StoreWindows(G, layout, slots=2)
    out = []

    async def bench(ctx):
        for step in steps:
            ctx.set(dut.rectification, step.get("rectification", 0))
            ctx.set(dut.taken, step.get("taken", 0))
            ctx.set(dut.engine_start, step.get("engine_start", 0))
            ctx.set(dut.timing.y, dut.panels_end if step.get("maps") else 0)
            ctx.set(dut.timing.x, 0 if step.get("maps") else 1)
            for name, consumer in (("left", dut.display_left), ("right", dut.display_right),
                                   ("engine", dut.engine_left)):
                ctx.set(consumer.request, name in step)
                ctx.set(consumer.port.addr, step.get(name, 0))
            for i, stream in enumerate(dut.streams):
                ctx.set(stream.fetch.rdy, 1)
                ctx.set(stream.landed, i in step.get("landed", ()))
                if asked is not None and ctx.get(stream.fetch.en):
                    asked[i].append(ctx.get(stream.fetch.row))
            out.append(ctx.get(dut.display_missed))
            await ctx.tick()

    sim = Simulator(dut)
    sim.add_clock(1e-8)
    sim.add_testbench(bench)
    sim.run()
    return out


def test_a_refused_panel_read_fires_and_a_granted_one_does_not():
    steps = [{"taken": 1}, {},
             {"landed": (0, 1)},                  # the row asked for in the take's clock (the window before it)
             {"landed": (0, 1)}, {},              # row 0
             {"left": 5, "right": 7},             # row 0 of both landed: granted
             {"left": W + 5},                     # row 1 of the left image not landed: refused
             {"right": W}]                        # nor of the right
    assert run(steps) == [0, 0, 0, 0, 0, 0, 1, 1]


def test_the_subtractor_s_no_data_reads_and_the_engine_s_waits_do_not_fire():
    """The maps restart the left window at row r = 3: a read of address 0 (a shifted pixel outside the image) is below
    the window and not a miss; row 3 not landed yet is; row 1 (below the window, not address 0) is too."""
    r = 3
    steps = [{"taken": 1}, {}, {"maps": 1, "rectification": r}, {}, {},
             {"left": 0},                         # no-data: not a miss
             {"engine": 0, "engine_start": 0},    # the engine waits: not the display's
             {"left": r * W + 2},                 # row 3 not landed: a miss
             {"left": W + 2},                     # row 1, below the window: a miss
             {"landed": (0,)},                    # the row asked for in the take's clock (the window before it)
             {"landed": (0,)}, {"landed": (0,)},  # rows 0 and 1, asked for after the take
             {"landed": (0,)}, {},                # row 3
             {"left": r * W + 2},                 # row 3 landed: granted
             {"left": 0}]                         # no-data again
    assert run(steps) == [0, 0, 0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 0, 0, 0]


def test_half_size_panels_windows_ask_every_second_row_then_every_row():
    """Panels at half size: after ``taken`` the compositor's windows ask for rows 0 and 2 (their two slots), the
    engine's for rows 0 and 1; after the maps' restart (rectification 3) the left window asks for rows 3 and 4, the
    right for 0 and 1; in between a read of row 2 (landed) moves the panels' windows on: they ask for row 4."""
    layout = replace(CONFIG.layout, regions=tuple(replace(r, shrink=2) if r.source in ("left", "right") else r
                                                  for r in CONFIG.layout.regions))
    asked = [[] for _ in range(4)]
    steps = [{"taken": 1, "engine_start": 1}] + [{}] * 4 + [{"left": 0, "right": 0, "landed": (0, 1)}] * 3 \
        + [{"left": 2 * W, "right": 2 * W}] + [{}] * 3 \
        + [{"maps": 1, "rectification": 3}] + [{}] * 5
    run(steps, layout, asked)
    # the take's clock: the windows before it ask for row 0 (from reset); then the panels 0, 2, ...
    assert asked[0] == [0, 0, 2, 4, 3, 4] and asked[1] == [0, 0, 2, 4, 0, 1]
    assert asked[2] == [0, 0, 1] and asked[3] == [0, 0, 1]
