"""The design configuration (hdl/config.py): the board build and the simulation read one design.

The board's preset is the system's own defaults (so ``stereodepth verilog`` builds the design the blocks default
to); a simulation setup's design is a design preset plus only the simulation's table speed-ups; the MT9D112
table at a sensor size changes only the four size variables.
"""

from dataclasses import FrozenInstanceError, fields

import pytest

from hdl.config import DesignConfig
from hdl.init_tables import MT9D112_TABLE, Write
from hdl.sensor_table import SIZE_VARIABLES, sized_mt9d112_table
from hdl.system import SystemParameters
from spec.layout import DisplayLayout
from spec.sensor import SENSOR, SMALL_SENSOR
from sim.testbench.system.setup import SystemSetup


def test_the_board_design_is_the_systems_defaults():
    defaults = {f.name: f.default for f in fields(SystemParameters)}     # StereoDepthSystem's parameters
    design = DesignConfig.full()
    for name, value in design.top_kwargs().items():
        if name == "layout":
            assert value == DisplayLayout.centred(design.timing, design.geometry, design.depth)
        else:
            assert value == defaults[name], name
    assert design.cam_table is MT9D112_TABLE


@pytest.mark.parametrize("preset", ["small", "full"])
def test_a_setups_design_is_the_preset_with_the_table_speed_ups(preset):
    setup = getattr(SystemSetup, preset)()
    design = getattr(DesignConfig, preset)()
    assert setup.design == DesignConfig(**{**vars(design), "cam_table": setup.cam_table})
    assert setup.board_kwargs() == setup.design.top_kwargs()
    assert setup.system_kwargs() == {**setup.board_kwargs(), "lock_cycles": setup.lock_cycles, "memory": "bram"}
    as_built = getattr(SystemSetup, preset)(time_scale=1.0, quick_table=False)
    assert as_built.design == design and as_built.cam_table == design.cam_table


def test_where_the_frames_are_is_the_designs():
    """``memory`` is a field of the design: a setup's is its design's, and the board build and the simulated system
    both get it from there."""
    setup = SystemSetup.small(memory="ddr2")
    assert setup.design == DesignConfig.small(memory="ddr2", cam_table=setup.cam_table)
    assert setup.board_kwargs()["memory"] == setup.system_kwargs()["memory"] == "ddr2"
    assert DesignConfig.full().memory == "bram"


def test_the_small_design_programs_its_output_size():
    table = DesignConfig.small().cam_table
    assert len(table) == len(MT9D112_TABLE)
    changed = [(a.value, b.value) for a, b in zip(MT9D112_TABLE.entries, table.entries) if a != b]
    assert sorted(changed) == sorted([(1600, 64), (1200, 48), (1600, 64), (1200, 48)])
    assert all(isinstance(e, Write) for e in table.entries if e not in MT9D112_TABLE.entries)
    assert sized_mt9d112_table(SENSOR) is MT9D112_TABLE
    assert sized_mt9d112_table(SMALL_SENSOR) == table


def test_a_table_without_the_size_variables_is_refused():
    from hdl.init_tables import InitTable
    table = InitTable(MT9D112_TABLE.device, MT9D112_TABLE.entries[:3])
    with pytest.raises(ValueError, match="size variables"):
        sized_mt9d112_table(SMALL_SENSOR, base=table)
    assert len(SIZE_VARIABLES) == 4


def test_the_configuration_is_frozen_and_resolved():
    design = DesignConfig.small()
    with pytest.raises(FrozenInstanceError):
        design.i2c_hz = 400_000
    assert design.layout == DisplayLayout.centred(design.timing, design.geometry, design.depth)
    assert DesignConfig.small(layout=design.layout, cam_table=design.cam_table) == design
    assert DesignConfig.small(i2c_hz=400_000).top_kwargs()["i2c_hz"] == 400_000
