"""The CH7301C's I2C register file as a bus target: :class:`CH7301CModel` and the decoded :class:`DviConfig`."""

from dataclasses import dataclass

from spec.board import I2C_ADDR
from sim.models.i2c.target import RegisterTarget

__all__ = ["CH7301CModel", "DviConfig"]


@dataclass(frozen=True)
class DviConfig:
    dvi_on: bool            # PM 0x49: DVIP and DVIL set, FPD clear
    idf: int                # input data format (0 = 12-bit multiplexed RGB 8:8:8 on both clock edges)
    hsync_positive: bool    # IDF bit 3 (HSP)
    vsync_positive: bool    # IDF bit 4 (VSP)
    pll_range: str          # "high" (> 65 MHz), "low" (<= 65 MHz) or "unset"


class CH7301CModel(RegisterTarget):
    """The CH7301C's register file (8-bit registers) at 7-bit address 0x76 (AS strap; 0x75 is the other
    choice): :class:`sim.models.ch7301c.registers.CH7301CRegisters` (``self.chip``) decodes every write (one it does not
    understand raises ``RegisterError``). Version ID 0x4A / device ID 0x4B read ``version_id`` / ``device_id``
    (0x95 / 0x17 by default; another value models a part the table does not expect). :meth:`state` is the
    transmitter's mode, :meth:`dvi_config` the summary the older tests use."""

    def __init__(self, address=I2C_ADDR.CH7301C, *, version_id=0x95, device_id=0x17, **faults):
        super().__init__(address, reg_bytes=1, data_bytes=1, name="ch7301c", **faults)
        from sim.models.ch7301c.registers import CH7301CRegisters
        self.chip = CH7301CRegisters(version_id=version_id, device_id=device_id)

    def write_register(self, reg, value):
        self.chip.write(reg & 0xFF, value)

    def read_register(self, reg):
        return self.chip.read(reg & 0xFF)

    def state(self):
        return self.chip.state()

    def problems(self):
        return list(self.chip.errors)

    def dvi_config(self):
        st = self.chip.state()
        rng = {"> 65 MHz": "high", "<= 65 MHz": "low"}.get(st["dvi_pll"], "unset")
        return DviConfig(dvi_on=st["dvi_output"], idf=self.chip.regs[0x1F] & 0x7,
                         hsync_positive=st["hsync_positive"], vsync_positive=st["vsync_positive"], pll_range=rng)
