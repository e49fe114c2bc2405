"""``MIGUserSignature``: Xilinx MIG 3.x's DDR2 user interface (Virtex-5), seen from the design that uses it."""

from amaranth.lib.wiring import In, Out, Signature

from spec.memory import MIG

from .signature import ParametricSignature

__all__ = ["MIGUserSignature"]


class MIGUserSignature(ParametricSignature):
    """MIG's user interface from the user's side (the controller's ports are the flipped signature).

    Every member is synchronous to MIG's ``clk0`` (the ``mem`` domain). The exported board top names them as MIG's
    generated module does (``app_af_cmd``, ``app_wdf_data``, ``rd_data_fifo_out``, ...).

    Parameters
    ----------
    addr_width : int
        ``app_af_addr``'s width (64-bit memory words).
    data_width : int
        One user word (``app_wdf_data``, ``rd_data_fifo_out``): {falling-edge half, rising-edge half}.

    Members
    -------
    command : Out(Signature)
        The address FIFO: ``cmd`` (``MIG.CMD_WRITE`` / ``MIG.CMD_READ``), ``addr`` (burst-aligned: its low two bits
        are 0), ``wren`` (writes one command), ``afull`` (In: 15 or fewer entries free).
    write : Out(Signature)
        The write-data FIFO: ``data``, ``mask`` (a 1 masks its byte), ``wren`` (writes one word), ``afull`` (In). A
        burst's words go in before (or with) its command.
    read : In(Signature)
        Read data: ``data``, ``valid``. Two words per read command, in command order; no backpressure.
    phy_init_done : In(1)
        High once MIG has initialised and calibrated the memory; no command before it.
    """

    def __init__(self, *, addr_width=MIG.ADDR_WIDTH, data_width=MIG.DATA_WIDTH):
        mask_width = data_width // 8
        super().__init__({
            "command": Out(Signature({
                "cmd": Out(MIG.CMD_WIDTH), "addr": Out(addr_width), "wren": Out(1), "afull": In(1)})),
            "write": Out(Signature({
                "data": Out(data_width), "mask": Out(mask_width), "wren": Out(1), "afull": In(1)})),
            "read": In(Signature({"data": Out(data_width), "valid": Out(1)})),
            "phy_init_done": In(1),
        }, addr_width=addr_width, data_width=data_width)
