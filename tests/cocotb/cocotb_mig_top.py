"""cocotb test of the MIG model behind MIG's generated top-module port names (sim/models/mig/mig_top.py; driven by
tests/test_mig_model.py): reset through ``sys_rst_n`` and ``locked``, one BL4 write (the command with its first
word, some bytes masked) and its read back through the ``app_*`` ports, the first word's latency after the read
command (the run's ``+mig_read_latency`` plusarg; the row open, a write before it: plus the write-to-read
turnaround) into the result file; then an unaligned read, on which the module stops the simulation itself.
"""

import json

try:
    import cocotb
    from cocotb.clock import Clock
    from cocotb.triggers import FallingEdge, ReadOnly
except ImportError:          # imported outside a cocotb run
    cocotb = None


if cocotb is not None:
    from sim.runners.cocotb import test_params

    async def clock(dut, n=1):
        for _ in range(n):
            await FallingEdge(dut.clk0)

    @cocotb.test()
    async def write_read_then_violation(dut):
        p = test_params()
        Clock(dut.clk0, 8000, unit="ps").start()
        dut.sys_rst_n.value, dut.locked.value = 0, 0
        for port in ("app_af_cmd", "app_af_addr", "app_af_wren", "app_wdf_data", "app_wdf_mask_data",
                     "app_wdf_wren"):
            getattr(dut, port).value = 0
        await clock(dut, 3)
        dut.sys_rst_n.value, dut.locked.value = 1, 1
        for _ in range(200):
            await clock(dut)
            if dut.phy_init_done.value:
                break
        words, masks = p["words"], p["masks"]
        for i in range(2):
            dut.app_wdf_data.value, dut.app_wdf_mask_data.value, dut.app_wdf_wren.value = words[i], masks[i], 1
            dut.app_af_wren.value, dut.app_af_cmd.value, dut.app_af_addr.value = int(i == 0), 0, p["addr"]
            await clock(dut)
        dut.app_wdf_wren.value, dut.app_af_wren.value = 0, 0
        await clock(dut, 30)
        dut.app_af_wren.value, dut.app_af_cmd.value, dut.app_af_addr.value = 1, 1, p["addr"]
        await clock(dut)
        dut.app_af_wren.value = 0
        got, latency = [], None
        for n in range(1, 100):
            await ReadOnly()
            if dut.rd_data_valid.value:
                latency = n if latency is None else latency
                got.append(int(dut.rd_data_fifo_out.value))
            await clock(dut)
        with open(p["result"], "w") as f:
            json.dump(dict(words=got, latency=latency), f)
        dut.app_af_wren.value, dut.app_af_cmd.value, dut.app_af_addr.value = 1, 1, p["addr"] + 1
        await clock(dut)
        dut.app_af_wren.value = 0
        await clock(dut, 20)
