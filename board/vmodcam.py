"""The Digilent VmodCAM (two MT9D112 cameras) as an add-on on a Digilent VHDC connector.

:func:`VmodCAMResources` returns the VmodCAM's resources over the host board's VHDC connector, in the manner of
amaranth-boards' ``extensions/pmod.py``: every pin is a VHDC connector pin (``conn=("vhdc", number)``), so the
board file declares the connector's map (connector pin -> FPGA pin) once and the camera pins follow from it.

Where each camera signal sits on the VHDC connector (:data:`VHDC_PINS`) comes from Digilent's VmodCAM reference
design for the Atlys, whose VHDC connector is the same (the VmodCAM is made for both boards): its UCF gives the
Atlys FPGA pin of every camera signal (``system.ucf``, stored copy in ``tariqmuh/XPS_VmodCam``
``IP1_VideoIn/implementation/system.ucf``), and the Atlys's VHDC connector map turns each FPGA pin back into its
connector pin (``amaranth-lang/amaranth-boards`` ``amaranth_boards/atlys.py``, ``Connector("vhdci", 0, ...)``,
pins 1..68; ``litex-hub/litex-boards`` ``litex_boards/platforms/digilent_atlys.py`` gives the same FPGA pins by
net name, ``EXP-IO1_P`` .. ``EXP-IO20_N``). The pairs: connector pin ``p`` (1..34) is ``EXP-IO<k>_P``, pin
``p + 34`` its ``EXP-IO<k>_N`` (:data:`VHDC_PAIRS`). tests/test_genesys.py re-derives the Atlys pins from this map.

Camera A (resource number 0) is the left camera, camera B (1) the right one; ``vmodcam_vdden`` switches the
supply of both.
"""

from amaranth.build import Clock, Pins, Resource, Subsignal

from spec.board import CLOCKS

__all__ = ["VmodCAMResources", "VHDC_PINS", "VHDC_PAIRS", "VHDC_IO_PINS", "CAM_PCLK_MAX_HZ", "CAM_OFFSET_IN_NS",
           "CAM_VALID_NS"]

#: The VHDC connector pins that carry signals (the others are ground and supply), pair by pair in the order
#: ``EXP-IO1`` .. ``EXP-IO20``: the P pin on the first row (1..34), the N pin 34 further on.
VHDC_PAIRS = tuple(zip((1, 3, 4, 6, 7, 9, 10, 12, 13, 15, 20, 22, 23, 25, 26, 28, 29, 31, 32, 34),
                       (35, 37, 38, 40, 41, 43, 44, 46, 47, 49, 54, 56, 57, 59, 60, 62, 63, 65, 66, 68)))
#: Every signal pin of the VHDC connector, ascending.
VHDC_IO_PINS = tuple(sorted(pin for pair in VHDC_PAIRS for pin in pair))

#: VHDC connector pin(s) of each VmodCAM signal, by ``(camera, signal)``: camera "A", "B", or "X" for the supply
#: enable both share. ``d`` lists D0..D7.
VHDC_PINS = {
    ("A", "d"): "12 13 37 1 3 4 6 7",
    ("A", "pclk"): "15", ("A", "lv"): "10", ("A", "fv"): "9", ("A", "mclk"): "40",
    ("A", "scl"): "43", ("A", "sda"): "44", ("A", "rst_n"): "38", ("A", "pwdn"): "41",
    ("B", "d"): "34 68 22 23 25 26 28 29",
    ("B", "pclk"): "20", ("B", "lv"): "32", ("B", "fv"): "31", ("B", "mclk"): "59",
    ("B", "scl"): "62", ("B", "sda"): "63", ("B", "rst_n"): "57", ("B", "pwdn"): "56",
    ("X", "vdden"): "35",
}

#: PERIOD constraint put on each camera's PCLK input: what the MT9D112 init table programs.
CAM_PCLK_MAX_HZ = CLOCKS.CAM_PCLK_HZ

#: OFFSET IN of each camera's D, LV, FV against its PCLK rising edge: data valid from 1.25 ns before the edge,
#: for 7.5 ns. Source: Digilent's VmodCAM reference design for the Atlys (the same camera board, 80 MHz PCLK):
#: ``OFFSET = IN 1.25 ns VALID 7.5 ns BEFORE "CAMA_PCLK_I" RISING`` (the same ``system.ucf``). The MT9D112 data
#: sheet's output timing figures could not be read here; Digilent's numbers are the constraint its own design
#: meets with this sensor.
CAM_OFFSET_IN_NS = 1.25
CAM_VALID_NS = 7.5


def VmodCAMResources(*args, vhdc):
    """The VmodCAM's resources on VHDC connector number ``vhdc``: ``vmodcam`` 0 (camera A, left) and 1 (camera
    B, right), each with D[7:0], PCLK (with its :class:`~amaranth.build.Clock`), LV, FV inputs, the MCLK output,
    SCL and SDA (``io``), RST_N (the sensor's RESET_BAR, active low) and PWDN (STANDBY, active high) outputs; and
    ``vmodcam_vdden`` 0, the supply enable. ``args`` (e.g. the connector bank's
    :class:`~amaranth.build.Attrs`) go to every resource."""
    conn = ("vhdc", vhdc)

    def pins(cam, signal, direction, **kwargs):
        return Pins(VHDC_PINS[(cam, signal)], dir=direction, conn=conn, **kwargs)

    def camera(number, cam):
        return Resource(
            "vmodcam", number,
            Subsignal("d", pins(cam, "d", "i", assert_width=8)),
            Subsignal("pclk", pins(cam, "pclk", "i"), Clock(CAM_PCLK_MAX_HZ)),
            Subsignal("lv", pins(cam, "lv", "i")),
            Subsignal("fv", pins(cam, "fv", "i")),
            Subsignal("mclk", pins(cam, "mclk", "o")),
            Subsignal("scl", pins(cam, "scl", "io")),
            Subsignal("sda", pins(cam, "sda", "io")),
            Subsignal("rst_n", pins(cam, "rst_n", "o")),
            Subsignal("pwdn", pins(cam, "pwdn", "o")),
            *args,
        )

    return [camera(0, "A"), camera(1, "B"), Resource("vmodcam_vdden", 0, pins("X", "vdden", "o"), *args)]
