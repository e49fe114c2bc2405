"""The MT9D112's I2C register file as a bus target: :class:`MT9D112Model` (chip ID, MCU variables through
0x338C/0x3390, the sequencer command that reads back 0 when done, PLL lock time, boot time after reset)."""

from spec.board import CLOCKS, I2C_ADDR
from sim.models.i2c.target import RegisterTarget
from sim.models.mt9d112.config import SensorConfig

__all__ = ["MT9D112Model"]


class MT9D112Model(RegisterTarget):
    """The MT9D112's I2C register file (16-bit registers, 16-bit data) at 7-bit address 0x3C.

    The registers, MCU variables and sequencer are :class:`sim.models.mt9d112.registers.MT9D112Registers` (``self.chip``):
    every write is decoded there and one the model does not understand raises
    :class:`~sim.models.mt9d112.registers.RegisterError`. :meth:`state` is the resulting sensor state (compared field by
    field with ``golden.part_config.mt9d112_expected``), :meth:`sensor_config` the output the video model
    (``sim/models/mt9d112/sensor.py``) obeys. The device NACKs its address for ``boot_s`` after the start of the simulation
    (reset released at t = 0). ``still_frames``: frames a still capture sends before returning to preview.
    """

    CHIP_VERSION = 0x1580

    def __init__(self, address=I2C_ADDR.MT9D112, *, extclk_hz=CLOCKS.CAM_MCLK_HZ, boot_s=7000 / CLOCKS.CAM_MCLK_HZ,
                 pll_lock_s=1e-3, cmd_busy_reads=2, still_frames=1, **faults):
        super().__init__(address, reg_bytes=2, data_bytes=2, name="mt9d112", **faults)
        from sim.models.mt9d112.registers import MT9D112Registers
        self.boot_s = boot_s
        self.cmd_busy_reads = cmd_busy_reads
        self.chip = MT9D112Registers(extclk_hz=extclk_hz, pll_lock_s=pll_lock_s, cmd_busy_reads=cmd_busy_reads,
                                     still_frames=still_frames)

    # ---- bus side ----------------------------------------------------------------------------------------
    def ready(self):
        return self.now >= self.boot_s

    def write_register(self, reg, value):
        self.chip.write(reg, value, self.now)

    def read_register(self, reg):
        return self.chip.read(reg, self.now)

    # ---- configuration seen by the sensor model ---------------------------------------------------------
    @property
    def commands_done(self):
        return self.chip.commands_done

    @property
    def streaming(self):
        """Parallel output on (0x301A bits 0x00CC)."""
        return self.chip.parallel_output

    @property
    def pixel_clock_hz(self):
        return self.chip.pclk_hz

    def state(self):
        """The sensor state (``MT9D112Registers.state``)."""
        return self.chip.state()

    def sensor_config(self):
        """The output in force: ``rgb565`` once the active context outputs RGB 5:6:5 without R/B swap, a
        sequencer command has completed and the parallel output is on."""
        st = self.chip.state()
        rgb = st["output_format"] == "rgb565" and not st["rb_swapped"]
        return SensorConfig(width=st["output_width"], height=st["output_height"],
                            rgb565=rgb and st["parallel_output"] and bool(self.chip.commands_done),
                            r_byte_first=st["r_byte_first"])

    def start_frame(self):
        """Called by the video model at each frame boundary; returns the configuration of that frame."""
        self.chip.start_frame()
        return self.sensor_config()

    def problems(self):
        """Writes not understood and inconsistencies found in what was written (empty list = none)."""
        return list(self.chip.errors) + self.chip.consistency()
