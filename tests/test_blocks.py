"""board.blocks on a hand-made flattened netlist: each LUT charged to the register it computes, the register to
the file that declares it (or, without ``src``, to its net's block path); LUT RAM and shift registers counted in
LUTs."""

from board.blocks import BlockCells, attribute, block_lines, blocks

SRC = "/x/hdl/depth/sgm_path.py:111.9-111.60|/share/xilinx/ff_map.v:68.41-68.95"


def cell(kind, inputs, outputs, src=None):
    ports = {**{p: "input" for p in inputs}, **{p: "output" for p in outputs}}
    return {"type": kind, "attributes": {"src": src} if src else {}, "port_directions": ports,
            "connections": {**inputs, **outputs}}


def netlist(ff_src=SRC):
    cells = {
        "lut_a": cell("LUT2", {"I0": [2], "I1": [3]}, {"O": [4]}, "/share/xilinx/lut_map.v:1"),
        "lut_b": cell("LUT3", {"I0": [4], "I1": [2], "I2": [3]}, {"O": [5]}, "/share/xilinx/lut_map.v:1"),
        "ff": cell("FDRE", {"D": [5], "C": [1]}, {"Q": [6]}, ff_src),
        "lut_out": cell("LUT1", {"I0": [6]}, {"O": [7]}),                    # reaches only an output
        "srl": cell("SRL16E", {"D": [6], "CLK": [1]}, {"Q": [8]}),
        "ram": cell("RAM64M", {"DIA": [6], "WCLK": [1]}, {"DOA": [9]}),
    }
    names = {
        "system.display.engine.horizontal$3.low": {"bits": [6], "attributes": {"src": SRC.split("|")[0]}},
        "out": {"bits": [7], "attributes": {}},
        "system.frame_store.reader_0.words.data": {"bits": [9], "attributes": {}},
    }
    return {"modules": {"top": {"attributes": {"top": 1}, "cells": cells, "netnames": names}}}


def test_luts_go_to_the_register_they_compute():
    per_block = blocks(attribute(netlist()))
    assert per_block["depth/sgm_path"] == BlockCells(logic=2, shift=1, ffs=1)
    assert per_block["top"] == BlockCells(logic=1)
    assert per_block["system.frame_store.reader_0.words"] == BlockCells(lut_ram=4)
    assert "| **total** | 8 | 3 | 1 | 4 | 1 | 0 |" in block_lines(per_block)


def test_without_src_the_net_names_the_block():
    per_block = blocks(attribute(netlist(ff_src="/share/xilinx/ff_map.v:68.41-68.95")), 3)
    assert per_block["depth/sgm_path"].logic == 2         # the net's own declaration
    names = netlist()
    del names["modules"]["top"]["netnames"]["system.display.engine.horizontal$3.low"]["attributes"]["src"]
    names["modules"]["top"]["cells"]["ff"]["attributes"] = {}
    per_block = blocks(attribute(names), 3)
    assert per_block["system.display.engine"] == BlockCells(logic=2, shift=1, ffs=1)
