"""Block RAM and clocks of the depth engine at 800 x 600 with the third aggregation path (right to left), for
D = 128, 96 and 64: the lever table of docs/depth.md ("The third path in the RTL: budget").

Measured, not modelled, where the RTL exists: the two-path engine (``hdl.depth.engine.DepthEngine`` at
``SENSOR_800``, 8-bit grey) and the third path's row store (``hdl.depth.reverse_path.ReversePath``) are elaborated
and their memories read from the RTLIL with ``board.memory_report`` (the rule ``stereodepth resources`` prints,
equal to Yosys's mapping for every engine memory of the board build); the passes' clocks come from
``hdl.depth.engine.schedule`` and the blocks' loop constants. Memories of schemes that are not built (the census
row, the cost row, the segment buffers) are costed with the same rule (``block_cost``) from their shapes.

Schemes for the right-to-left path, whose recursion runs against the pixel order (docs/depth.md):

* a'  (built: ReversePath, DepthEngine with THREE_PATHS) forward pass as today, storing per pixel and
  disparity the sum S2 = L_lr + L_tb of the row (9 bits); then a reverse pass over the same row, its census
  recomputed from the input ring (the ring still holds the row's 7 census rows: the next row's fetch waits),
  the costs again, L_rl, S = S2 + L_rl, the winner in reverse order, the codes turned round through a row of
  codes and replayed into the median (two clocks a code). Serial: forward, reverse, replay.
* a   the same with the reverse pass of row y beside the forward pass of row y + 1 (one pass time per row): the
  census row (2 x W x 48 bits, the ring no longer holds the rows) and the sums of two rows in flight; a1: one
  row of sums whose addresses are mirrored every row (row y + 1's pixel x goes where row y's pixel W - 1 - x was,
  read by the reverse pass just before).
* b   the costs buffered instead of recomputed: C (6 bits) and S2 (9 bits) per cell, serial.
* c   the reverse pass first (L_rl stored, 8 bits; no code reversal) beside the previous row's forward pass: it
  needs its own read of the ring (the ring's copy, as the ring has one read port per copy).
* d   no row store: checkpoints of L_lr every K pixels, each K-pixel segment's costs and L_lr recomputed
  forward into a double buffer (C and S2, 15 bits), then replayed backwards; serial. Its census shift register
  must be refilled with D - 1 signatures per segment.

Run: ``python -m bench depth_budget`` (about a minute: three engines elaborated); ``--quality`` adds the golden
model's figures of the candidate builds, ``--synth`` the engines' LUTs, flip-flops and block RAM through Yosys;
``--blocks`` (alone) the 800 x 600 build's engine's LUTs per block and the registers taking the most
(``--blocks --base``: ``DEPTH_800_BASE``'s two-path engine);
``--left-right`` (alone) the left-right check's blocks through Yosys and the 800 x 600 pass and map with it
(``--left-right --engine``: also the engine without and with the check).
"""

import dataclasses

from amaranth.back import rtlil

from board.memory_report import block_cost, memories
from hdl.depth.engine import DepthEngine, schedule
from hdl.depth.reverse_path import ReversePath
from spec.board import CLOCKS
from spec.depth import DEPTH_800, DEPTH_800_BASE, THREE_PATHS, TWO_PATHS
from spec.sensor import SENSOR_800, disparity_of_distance

#: The cameras' frame rate at 1600 x 1200 (Digilent VmodCAM reference manual: 15 fps max; docs/capture.md).
CAMERA_FPS = 15
#: Block RAM for the whole design, MIG's own included (issue's budget; docs/depth.md).
BUDGET_RAMB36 = 58
#: RAMB36 outside the engine in the 800 x 600 DDR2 build: today's DDR2 build (``stereodepth resources --memory
#: ddr2``, Yosys's mapping: 21 in all with MIG's 3, the engine's 14 of them) has the frame store's four read rings
#: (a RAMB18 each) 2, MIG 3, the colour map 1, the vertical-offset profiles 1; the averaging capture adds its two
#: line buffers (a RAMB18 each) 1.
OUTSIDE_ENGINE_RAMB36 = 8
SEGMENT = 64            # scheme d's segment length K
DISPARITIES = (128, 96, 64)


def _memories(component):
    return memories(rtlil.convert(component, name="top"))


def engine_blocks(config):
    """{memory name: RAMB36} of today's two-path engine at 800 x 600 with ``config``."""
    engine = DepthEngine(SENSOR_800, dataclasses.replace(config, paths=TWO_PATHS))
    return {info.name: info.blocks36 for info in _memories(engine)}


def row_store_blocks(config, width):
    """RAMB36 of ReversePath's row store (W x G words of lanes x 9 bits), read from its RTLIL."""
    return sum(info.blocks36 for info in _memories(ReversePath(config, width=width)))


def pass_clocks(config):
    """(forward, reverse) clocks of one row at 800 x 600: the two-path engine's pass (+ 3 to start) and what the
    three-path engine (scheme a', ``hdl.depth.schedule``) adds to it: W + 2 rx backward steps of the same length
    (the census windows' lead only: left and right signatures move together backwards), the row's last code, and
    the replay of the row's codes into the median (2 (W + 1) clocks), less the shorter final drain."""
    two = schedule(SENSOR_800, dataclasses.replace(config, paths=TWO_PATHS))
    three = schedule(SENSOR_800, dataclasses.replace(config, paths=THREE_PATHS))
    return two.pass_clocks + 3, three.pass_clocks - two.pass_clocks


def scheme_rows(config, engine_total):
    """[(scheme, extra RAMB36, clocks per map, note)] for one D."""
    w, h, D, lanes = SENSOR_800.buf_width, SENSOR_800.buf_height, config.disparities, config.lanes
    groups = D // lanes
    forward, reverse = pass_clocks(config)
    census = 2 * block_cost(w, config.census_bits)                  # a row of left and right signatures
    codes = block_cost(w, config.code_bits)                         # the codes of a row, turned round
    sums = row_store_blocks(config, w)                              # S2 of a row (ReversePath's row store)
    costs_and_sums = block_cost(w * groups, lanes * (config.cost_bits + 9))
    l_rl = block_cost(w * groups, lanes * config.path_bits)
    ring_copy = 2 * block_cost(w, 8 * SENSOR_800.grey_bits)       # one more copy of each image's 8-row ring
    checkpoints = block_cost(-(-w // SEGMENT) * groups, lanes * config.path_bits)
    segments = block_cost(2 * SEGMENT * groups, lanes * (config.cost_bits + 9))     # both halves
    refill = -(-w // SEGMENT) * (D - 1)                             # the census shift register, per segment
    serial, overlapped = h * (forward + reverse), h * forward
    return [
        ("a' (built): S2 row, census from the ring, serial", sums + codes, serial,
         f"S2 row {sums:g} + codes {codes:g}"),
        ("a: S2 rows overlapped", 2 * sums + census + codes, overlapped,
         f"2 S2 rows {2 * sums:g} + census row {census:g} + codes {codes:g}"),
        ("a1: as a, one S2 row, its addresses mirrored every row", sums + census + codes, overlapped,
         f"S2 row {sums:g} + census row {census:g} + codes {codes:g}"),
        ("b: cost + S2 row, serial", costs_and_sums + codes, serial,
         f"C + S2 row {costs_and_sums:g} + codes {codes:g}"),
        ("c: L_rl row first, overlapped", 2 * l_rl + ring_copy, overlapped,
         f"2 L_rl rows {2 * l_rl:g} + ring copies {ring_copy:g}"),
        (f"d: checkpoints every {SEGMENT} px + segment replay, serial", checkpoints + segments + codes,
         serial + h * refill, f"checkpoints {checkpoints:g} + segments {segments:g} + codes {codes:g}; "
         f"a second L_lr path and cost unit"),
    ]


def segment_with_lanes_lines(engine_totals):
    """Scheme d with the vertical line buffer as one W x G-word memory, at 16 and 32 lanes (the time needs more
    lanes): the engine's other memories as measured (they do not depend on the lanes), the rest from shapes."""
    w, h = SENSOR_800.buf_width, SENSOR_800.buf_height
    lines = []
    for D, (engine_total, line_buffer) in engine_totals.items():
        for lanes in (16, 32):
            config = dataclasses.replace(DEPTH_800_BASE, disparities=D, lanes=lanes)
            groups, segments = D // lanes, -(-w // SEGMENT)
            blocks = (engine_total - line_buffer + block_cost(w * groups, lanes * config.path_bits)
                      + block_cost(segments * groups, lanes * config.path_bits)
                      + block_cost(2 * SEGMENT * groups, lanes * (config.cost_bits + 9))
                      + block_cost(w, config.code_bits))
            forward, reverse = pass_clocks(config)
            ms = 1e3 * h * (forward + reverse + segments * (D - 1)) / CLOCKS.PIXEL_HZ
            lines.append(f"D = {D}, {lanes} lanes, scheme d with the line buffer as one memory: {blocks:g} RAMB36, "
                         f"{ms:.1f} ms per map")
    return lines


def table_lines():
    frame_clocks = CLOCKS.PIXEL_HZ / CAMERA_FPS
    lines = ["## The third path at 800 x 600: block RAM and clocks", "",
             f"Budget: {BUDGET_RAMB36} RAMB36 with MIG's; outside the engine {OUTSIDE_ENGINE_RAMB36} (DDR2 build), "
             f"so the engine may use {BUDGET_RAMB36 - OUTSIDE_ENGINE_RAMB36}. A map per camera frame: "
             f"{frame_clocks:,.0f} pix clocks ({1e3 / CAMERA_FPS:.1f} ms at {CLOCKS.PIXEL_HZ / 1e6:g} MHz). "
             f"Lanes {DEPTH_800_BASE.lanes}.", "",
             "| D | nearest valid distance | two-path engine RAMB36 | scheme | + RAMB36 | engine total | "
             "ms per map | fits |", "|---|---|---|---|---|---|---|---|"]
    notes, engine_totals = [], {}
    for D in DISPARITIES:
        config = dataclasses.replace(DEPTH_800_BASE, disparities=D)
        blocks = engine_blocks(config)
        engine_total = sum(blocks.values())
        nearest = disparity_of_distance(1.0, SENSOR_800) / (D - 2)
        line_buffer = sum(v for k, v in blocks.items() if k.startswith("vertical_rows"))
        engine_totals[D] = (engine_total, line_buffer)
        groups = D // config.lanes
        one_memory = block_cost(SENSOR_800.buf_width * groups, config.lanes * config.path_bits)
        ddr2 = 2 * SENSOR_800.buf_width * D * 9 * SENSOR_800.buf_height * CAMERA_FPS / 8e9
        notes.append(f"D = {D}: two-path engine {engine_total:g} RAMB36 (vertical line buffer {line_buffer:g}, "
                     f"{one_memory:g} as one W x G-word memory read a group at a time; rings "
                     f"{sum(v for k, v in blocks.items() if 'ring' in k):g}); forward / reverse pass "
                     + " / ".join(f"{c:,}" for c in pass_clocks(config))
                     + f" clocks; S2 rows through the DDR2 instead: {ddr2:.2f} GB/s written and read at "
                     f"{CAMERA_FPS} maps/s")
        for name, extra, clocks, note in scheme_rows(config, engine_total):
            total = engine_total + extra
            ms = 1e3 * clocks / CLOCKS.PIXEL_HZ
            fits = total <= BUDGET_RAMB36 - OUTSIDE_ENGINE_RAMB36 and clocks <= frame_clocks
            lines.append(f"| {D} | {nearest:.2f} m | {engine_total:g} | {name} ({note}) | {extra:g} | {total:g} | "
                         f"{ms:.1f} | {'yes' if fits else 'no'} |")
    del engine_totals[64]
    return lines + [""] + notes + segment_with_lanes_lines(engine_totals) + [""]


def quality_lines():
    """What the schemes that fit buy: the golden model at 800 x 600 (bench depth's pairs, 400-pixel units, invalid
    counted bad), D = 128 with two and three paths, D = 96 and 64 with three (max_cost 60 per path)."""
    from bench.depth_builds import BUILDS, engine, pairs
    from sim.analysis.truth import error_figures
    build = BUILDS[1]
    per_path = DEPTH_800_BASE.max_cost // len(DEPTH_800_BASE.paths)
    variants = [(f"D {D}, {len(paths)} paths", dataclasses.replace(DEPTH_800_BASE, disparities=D, paths=paths,
                                                                  max_cost=per_path * len(paths)))
                for D, paths in ((128, THREE_PATHS), (128, TWO_PATHS), (96, THREE_PATHS), (64, THREE_PATHS))]
    rows = {name: [] for name, _ in variants}
    names = []
    for pair_name, left, right, truth in pairs(build):
        names.append(pair_name)
        for name, config in variants:
            f = error_figures(*engine(build, left, right, config), truth)
            rows[name].append(f"{100 * f[0]:.1f} / {100 * f[1]:.1f} / {100 * f[2]:.1f}, {100 * f[4]:.1f}")
    lines = ["### What they buy (golden model, 800 x 600 build; bad > 0.5 / 1 / 2 %, density %)", "",
             "| engine | " + " | ".join(names) + " |", "|---|" + "---|" * len(names)]
    return lines + [f"| {name} | " + " | ".join(cells) + " |" for name, cells in rows.items()] + [""]


def synth_lines():
    """The engine alone through Yosys (``board.resources.run_yosys``: synth_xilinx -family xc5v): the board's
    (400 x 300, D = 64, two paths) and, at 800 x 600, D = 64 with two paths and three (scheme a', built) and
    D = 128 with two."""
    import tempfile
    from board.resources import LUT_CELLS, run_yosys
    from spec.depth import DEPTH
    from spec.sensor import SENSOR
    builds = [("400 x 300, D 64, 2 paths (the board's)", SENSOR, DEPTH)]
    builds += [(f"800 x 600, D {D}, {len(paths)} paths", SENSOR_800,
                dataclasses.replace(DEPTH_800_BASE, disparities=D, paths=paths, max_cost=60 * len(paths)))
               for D, paths in ((64, TWO_PATHS), (64, THREE_PATHS), (128, TWO_PATHS))]
    lines = ["### The engine alone through Yosys", "",
             "| engine | LUTs (logic) | shift registers (SRL16E, a LUT each) | flip-flops | RAMB36 (+ RAMB18 / 2) |",
             "|---|---|---|---|---|"]
    for name, geometry, config in builds:
        with tempfile.TemporaryDirectory() as work:
            cells, _, _ = run_yosys(rtlil.convert(DepthEngine(geometry, config), name="top"), work)
        count = lambda prefix: sum(n for t, n in cells.items() if t.startswith(prefix))     # noqa: E731
        luts = sum(n for t, n in cells.items() if t in LUT_CELLS)
        lines.append(f"| {name} | {luts:,} | {count('SRL'):,} | {count('FD'):,} | "
                     f"{count('RAMB36') + count('RAMB18') / 2:g} |")
    return lines + [""]


def blocks_lines(base=False):
    """The 800 x 600 build's engine (``DEPTH_800``) through Yosys (as ``--synth``), its LUTs per block
    (``board.blocks``: each LUT charged to the register it computes, the register to the file declaring it) and
    the source lines whose registers take the most logic; with ``base``, the two-path engine without the quality
    options (``DEPTH_800_BASE``)."""
    import tempfile
    from board.blocks import attribute, block_lines, blocks, line_lines
    from board.resources import run_yosys
    config = (dataclasses.replace(DEPTH_800_BASE, disparities=128, paths=TWO_PATHS, max_cost=60 * len(TWO_PATHS))
              if base else DEPTH_800)
    name = "two-path base" if base else "build's (`DEPTH_800`)"
    with tempfile.TemporaryDirectory() as work:
        _, netlist, _ = run_yosys(rtlil.convert(DepthEngine(SENSOR_800, config), name="top"), work)
        attributed = attribute(netlist)
    return ([f"### The 800 x 600, D 128, {name} engine per block (Yosys; LUTs = logic + SRL + LUT RAM)", ""]
            + block_lines(blocks(attributed)) + ["", "Registers taking the most logic:", ""]
            + line_lines(attributed) + [""])


#: The median choices ``--median`` puts through Yosys: (median, median_valid).
MEDIANS = ((3, False), (5, False), (5, True), (7, False), (7, True))


def median_lines():
    """The median blocks (``MEDIANS``) alone through Yosys (as ``--synth``) at W = 800 with DEPTH_800_BASE's 12-bit
    codes, and the 800 x 600 map's clocks in the store with each (``hdl.stereo_display.map_clocks``)."""
    import tempfile
    from board.resources import LUT_CELLS, run_yosys
    from hdl.depth.engine import median_block
    from hdl.stereo_display import map_clocks
    lines = ["### The median blocks alone through Yosys (W = 800, 12-bit codes)", "",
             "| block | median, median_valid | LUTs (logic) | SRL16E | flip-flops | RAMB36 (+ RAMB18 / 2) | "
             "pass clocks | map clocks |",
             "|---|---|---|---|---|---|---|---|"]
    for median, valid_only in MEDIANS:
        config = dataclasses.replace(DEPTH_800_BASE, median=median, median_valid=valid_only)
        block = median_block(config)
        with tempfile.TemporaryDirectory() as work:
            cells, _, _ = run_yosys(rtlil.convert(block(config, SENSOR_800), name="top"), work)
        count = lambda prefix: sum(n for t, n in cells.items() if t.startswith(prefix))     # noqa: E731
        luts = sum(n for t, n in cells.items() if t in LUT_CELLS)
        lines.append(f"| `{block.__name__}` | {median}, {valid_only} | {luts:,} | {count('SRL'):,} | {count('FD'):,} | "
                     f"{count('RAMB36') + count('RAMB18') / 2:g} | {schedule(SENSOR_800, config).pass_clocks:,} | "
                     f"{map_clocks(SENSOR_800, config):,} |")
    return lines + [""]


def left_right_lines():
    """The left-right check's two blocks alone through Yosys (as ``--synth``) at W = 800 with ``DEPTH_800_BASE``'s D =
    128, 16 lanes (``LeftWinner``, ``LeftRightFill``), and the 800 x 600 pass and map with and without the check
    (``hdl.stereo_display.map_clocks``, ``check_map_rate`` at 1080p60: display frames a map)."""
    import tempfile
    from board.blocks import LUT_RAM_LUTS
    from board.resources import LUT_CELLS, run_yosys
    from hdl.depth.left_right_fill import LeftRightFill
    from hdl.depth.left_winner import LeftWinner
    from hdl.stereo_display import check_map_rate, map_clocks
    from spec.video import CEA_1080P60
    config = dataclasses.replace(DEPTH_800_BASE, left_right=True)
    lines = ["### The left-right check's blocks alone through Yosys (W = 800, D = 128, 16 lanes)", "",
             "| block | LUTs (logic) | LUT RAM (LUTs) | flip-flops | RAMB36 (+ RAMB18 / 2) |", "|---|---|---|---|---|"]
    for block in (LeftWinner, LeftRightFill):
        with tempfile.TemporaryDirectory() as work:
            cells, _, _ = run_yosys(rtlil.convert(block(config, SENSOR_800.buf_width), name="top"), work)
        count = lambda prefix: sum(n for t, n in cells.items() if t.startswith(prefix))     # noqa: E731
        luts = sum(n for t, n in cells.items() if t in LUT_CELLS)
        lut_ram = sum(LUT_RAM_LUTS[t] * n for t, n in cells.items() if t in LUT_RAM_LUTS)
        lines.append(f"| `{block.__name__}` | {luts:,} | {lut_ram:,} | {count('FD'):,} | "
                     f"{count('RAMB36') + count('RAMB18') / 2:g} |")
    lines += ["", "| 800 x 600, D 128 | pass clocks | map clocks | display frames a map (1080p60) |",
              "|---|---|---|---|"]
    for name, build in (("`DEPTH_800_BASE`", DEPTH_800_BASE), ("+ `left_right`", config)):
        lines.append(f"| {name} | {schedule(SENSOR_800, build).pass_clocks:,} | {map_clocks(SENSOR_800, build):,} | "
                     f"{check_map_rate(CEA_1080P60, SENSOR_800, build)} |")
    return lines + [""]


def left_right_engine_lines():
    """The 800 x 600, D 128 two-path engine (``DEPTH_800_BASE``) through Yosys (as ``--synth``) without and with
    ``left_right``: what the check adds in place."""
    import tempfile
    from board.blocks import LUT_RAM_LUTS
    from board.resources import LUT_CELLS, run_yosys
    lines = ["### The 800 x 600 engine without and with the left-right check (Yosys)", "",
             "| engine | LUTs (logic) | SRL16E | LUT RAM (LUTs) | flip-flops | RAMB36 (+ RAMB18 / 2) |",
             "|---|---|---|---|---|---|"]
    builds = (("`DEPTH_800_BASE`", DEPTH_800_BASE),
              ("+ `left_right`", dataclasses.replace(DEPTH_800_BASE, left_right=True)))
    for name, config in builds:
        with tempfile.TemporaryDirectory() as work:
            cells, _, _ = run_yosys(rtlil.convert(DepthEngine(SENSOR_800, config), name="top"), work)
        count = lambda prefix: sum(n for t, n in cells.items() if t.startswith(prefix))     # noqa: E731
        luts = sum(n for t, n in cells.items() if t in LUT_CELLS)
        lut_ram = sum(LUT_RAM_LUTS[t] * n for t, n in cells.items() if t in LUT_RAM_LUTS)
        lines.append(f"| {name} | {luts:,} | {count('SRL'):,} | {lut_ram:,} | {count('FD'):,} | "
                     f"{count('RAMB36') + count('RAMB18') / 2:g} |")
    return lines + [""]


def main(options=()):
    """``--quality``: the golden model's figures of the candidate builds as well (several minutes); ``--synth``:
    the engines through Yosys (about 15 minutes); ``--blocks``: the 800 x 600 build's engine's LUTs per
    block (about 5 minutes), alone (with ``--base``: ``DEPTH_800_BASE``'s two-path engine); ``--median``: the median blocks through Yosys (about a minute), alone;
    ``--left-right``: the left-right check's blocks through Yosys and the pass with the check, alone (with
    ``--engine``: also the 800 x 600 engine without and with it, about 4 minutes)."""
    if "--left-right" in options:
        print("\n".join(left_right_lines() + (left_right_engine_lines() if "--engine" in options else [])))
        return
    if "--blocks" in options:
        print("\n".join(blocks_lines(base="--base" in options)))
        return
    if "--median" in options:
        print("\n".join(median_lines()))
        return
    lines = table_lines()
    if "--quality" in options:
        lines += quality_lines()
    if "--synth" in options:
        lines += synth_lines()
    print("\n".join(lines))


if __name__ == "__main__":
    main()
