"""The init tables checked against the parts, not against themselves.

Each table is played into its register-file model (``sim.models.i2c.table.play_table``: the writes, waits and reads a
sequencer makes, without the bus), which decodes every register and variable into the part's state; that state
is compared field by field with the golden state (``golden.part_config``, written from the references, never
from the tables). Then the tables are mutated -- one value at a time, each a change that alters what the part
does -- and every mutant must either land in a state that differs from the golden one in the named field, or be
refused by the model as a write it does not understand. The sequencer playing the same tables on a simulated bus
reaches the same state (tests/test_i2c_init.py).
"""

from contextlib import nullcontext
from dataclasses import replace

import pytest

from golden.part_config import ch7301c_expected, mt9d112_expected
from hdl.init_tables import CH7301C_TABLE, MT9D112_TABLE, InitTable, Write, ch7301c_table
from spec.sensor import SMALL_SENSOR
from spec.video import VideoTiming
from sim.models.ch7301c.registers import CH7301CRegisters
from sim.models.ch7301c.target import CH7301CModel
from sim.models.mt9d112.target import MT9D112Model
from sim.models.i2c.table import play_table
from sim.models.mt9d112.registers import KNOWN_REGISTERS, KNOWN_VARIABLES, RegisterError
from sim.testbench.system.tables import mt9d112_table


def differences(state, expected):
    return {k: (state.get(k), e.value) for k, e in expected.items() if state.get(k) != e.value}


def configured_sensor(table=MT9D112_TABLE):
    cam = MT9D112Model()
    result = play_table(table, cam)
    return cam, result


# --- the tables reach the golden state ------------------------------------------------------------------------

def test_mt9d112_table_reaches_the_golden_state():
    cam, result = configured_sensor()
    assert result.done and result.mismatches == []
    assert differences(cam.state(), mt9d112_expected()) == {}
    assert cam.problems() == []


def test_simulation_size_table_reaches_the_golden_state_at_that_size():
    """The simulations' table (board table, output size of the small sensor, waits scaled) -- not the quick one."""
    cam, result = configured_sensor(mt9d112_table(SMALL_SENSOR, time_scale=0.02))
    assert result.done
    assert differences(cam.state(), mt9d112_expected(SMALL_SENSOR)) == {}


def test_quick_simulation_table_keeps_the_sensor_streaming():
    """The default-run simulations' short table sets the capture mode too: a sensor left in still capture sends
    one frame and returns to preview (which a one-frame simulation would not notice)."""
    cam, result = configured_sensor(mt9d112_table(SMALL_SENSOR, time_scale=0.02, quick=True))
    assert result.done and cam.state()["capture_video"]
    assert all(cam.start_frame().rgb565 for _ in range(4))


def test_ch7301c_table_reaches_the_golden_mode():
    dvi = CH7301CModel()
    result = play_table(CH7301C_TABLE, dvi)
    assert result.done and result.mismatches == []
    assert differences(dvi.state(), ch7301c_expected()) == {}


def test_golden_states_cover_every_field_the_models_decode():
    cam, _ = configured_sensor()
    dvi = CH7301CModel()
    play_table(CH7301C_TABLE, dvi)
    assert set(cam.state()) == set(mt9d112_expected())
    assert set(dvi.state()) == set(ch7301c_expected())
    for expected in (mt9d112_expected(), ch7301c_expected()):
        assert all(e.source for e in expected.values())


def test_every_register_and_variable_the_tables_write_is_decoded():
    """Coverage: each register the MT9D112 table writes is one the model decodes, each variable address names
    a variable it decodes; the CH7301C model refuses registers it does not know (so every one written is known)."""
    var_addr = None
    for e in MT9D112_TABLE.entries:
        if isinstance(e, Write):
            assert e.reg in KNOWN_REGISTERS, f"register 0x{e.reg:04x}"
            if e.reg == 0x338C:
                var_addr = e.value
                assert ((e.value >> 8) & 0x1F, e.value & 0xFF) in KNOWN_VARIABLES, f"variable 0x{e.value:04x}"
            elif e.reg == 0x3390:
                assert var_addr is not None
    regs = CH7301CRegisters()
    for e in CH7301C_TABLE.entries:
        if isinstance(e, Write):
            regs.write(e.reg, e.value)                  # raises for anything not understood
    with pytest.raises(RegisterError):
        regs.write(0x21, 0x09)                         # DAC control: not written by the table, not modelled


# --- mutated tables -------------------------------------------------------------------------------------------

def _var_entry(table, driver, offset):
    """Index of the data write of variable (driver, offset) in ``table``."""
    for i, e in enumerate(table.entries):
        if isinstance(e, Write) and e.reg == 0x338C and ((e.value >> 8) & 0x1F, e.value & 0xFF) == (driver, offset):
            return i + 1
    raise LookupError(f"variable {driver}:0x{offset:02x} not in the table")


def _reg_entry(table, reg, value=None, last=False):
    hits = [i for i, e in enumerate(table.entries)
            if isinstance(e, Write) and e.reg == reg and (value is None or e.value == value)]
    return hits[-1] if last else hits[0]


def mutate(table, index, value):
    entries = list(table.entries)
    entries[index] = replace(entries[index], value=value)
    return InitTable(table.device, tuple(entries))


T = MT9D112_TABLE
#: (what changes, entry index, new value, the golden field that must differ -- or RegisterError / "poll").
MT9D112_MUTANTS = [
    ("capture mode still (0x00F0)", _var_entry(T, 1, 0x20), 0x00F0, "capture_video"),
    ("capture mode unknown bits", _var_entry(T, 1, 0x20), 0x0072, RegisterError),
    ("byte swap", _var_entry(T, 7, 0x97), 0x0032, "r_byte_first"),
    ("R/B swap", _var_entry(T, 7, 0x97), 0x0031, "rb_swapped"),
    ("RGB555", _var_entry(T, 7, 0x97), 0x0070, "output_format"),
    ("YUV", _var_entry(T, 7, 0x97), 0x0010, "output_format"),
    ("no BT.656 codes", _var_entry(T, 7, 0x97), 0x0020, "bt656_codes"),
    ("output format unknown bit", _var_entry(T, 7, 0x97), 0x0130, RegisterError),
    ("output width", _var_entry(T, 7, 0x07), 1280, "output_width"),
    ("output height", _var_entry(T, 7, 0x09), 1199, "output_height"),
    ("crop X1", _var_entry(T, 7, 0x61), 1599, "crop"),
    ("row end", _var_entry(T, 7, 0x33), 1199, "sensor_rows"),
    ("column start", _var_entry(T, 7, 0x31), 8, "sensor_cols"),
    ("fine_IT_min", _var_entry(T, 7, 0x41), 360, "fine_it_min"),
    ("PLL M 81", _reg_entry(T, 0x341C), 0x0251, "pclk_hz"),
    ("PLL N 3", _reg_entry(T, 0x341C), 0x0350, "pclk_hz"),
    ("PLL left bypassed", _reg_entry(T, 0x341E, last=True), 0x8F09, "pll_enabled"),
    ("PLL reserved bits", _reg_entry(T, 0x341E, last=True), 0x8E08, RegisterError),
    ("sequencer command preview", _var_entry(T, 1, 0x03), 0x0001, "context"),
    ("sequencer command unknown", _var_entry(T, 1, 0x03), 0x0003, RegisterError),
    ("8-bit variable read 16-bit", _var_entry(T, 1, 0x03) - 1, 0x2103, RegisterError),
    ("parallel output off", _reg_entry(T, 0x301A), 0x0200, "parallel_output"),
    ("parallel output half on", _reg_entry(T, 0x301A), 0x02C8, RegisterError),
    ("standby control", _reg_entry(T, 0x3202), 0x0000, RegisterError),
    ("slew rate", _reg_entry(T, 0x3214), 0x0D84, "slew_data"),
    ("MCU left in reset", _reg_entry(T, 0x3386, 0x0500), 0x0501, "poll"),
    ("unknown variable", _var_entry(T, 7, 0x41) - 1, 0x2743, RegisterError),
]


@pytest.mark.parametrize("what, index, value, field", MT9D112_MUTANTS, ids=[m[0] for m in MT9D112_MUTANTS])
def test_mt9d112_table_mutant_is_caught(what, index, value, field):
    table = mutate(MT9D112_TABLE, index, value)
    cam = MT9D112Model()
    if field is RegisterError:
        with pytest.raises(RegisterError):
            play_table(table, cam)
        return
    result = play_table(table, cam)
    if field == "poll":
        assert not result.done and result.failed_entry is not None
        return
    assert result.done
    diff = differences(cam.state(), mt9d112_expected())
    assert field in diff, f"{what}: state differs only in {sorted(diff)}"


def test_still_capture_returns_to_preview_after_its_frame():
    """captureParams.mode[1] = 0 (the 0x00F0 mutant): one frame of context B, then preview (800 x 600 YUV)."""
    cam, result = configured_sensor(mutate(MT9D112_TABLE, _var_entry(MT9D112_TABLE, 1, 0x20), 0x00F0))
    assert result.done and cam.sensor_config().rgb565 and cam.state()["context"] == "B"
    first = cam.start_frame()
    second = cam.start_frame()
    assert first.rgb565 and (first.width, first.height) == (1600, 1200)
    assert not second.rgb565 and (second.width, second.height) == (800, 600)
    assert cam.state()["sequencer_state"] == "preview"
    video, _ = configured_sensor()
    assert all(video.start_frame().rgb565 for _ in range(5))


_DVI = CH7301C_TABLE
CH7301C_MUTANTS = [
    ("negative syncs", _reg_entry(_DVI, 0x1F), 0x80, "hsync_positive"),
    ("negative vsync", _reg_entry(_DVI, 0x1F), 0x88, "vsync_positive"),
    ("IDF bit 7 clear", _reg_entry(_DVI, 0x1F), 0x18, "idf_bit7"),
    ("IDF 1", _reg_entry(_DVI, 0x1F), 0x99, RegisterError),
    ("IDF unknown bit", _reg_entry(_DVI, 0x1F), 0xB8, RegisterError),
    ("PLL charge pump of the low range", _reg_entry(_DVI, 0x33), 0x08, RegisterError),
    ("PLL filter", _reg_entry(_DVI, 0x36), 0xA1, RegisterError),
    ("full power-down", _reg_entry(_DVI, 0x49), 0xC1, "dvi_output"),
    ("DVI link off", _reg_entry(_DVI, 0x49), 0x80, "dvi_output"),
    ("DACs powered down", _reg_entry(_DVI, 0x49), 0xCE, "dac_powered_down"),
]


@pytest.mark.parametrize("what, index, value, field", CH7301C_MUTANTS, ids=[m[0] for m in CH7301C_MUTANTS])
def test_ch7301c_table_mutant_is_caught(what, index, value, field):
    dvi = CH7301CModel()
    table = mutate(CH7301C_TABLE, index, value)
    with pytest.raises(RegisterError) if field is RegisterError else nullcontext():
        play_table(table, dvi)
        diff = differences(dvi.state(), ch7301c_expected())
        assert field in diff, f"{what}: mode differs only in {sorted(diff)}"


def test_ch7301c_table_for_a_slow_mode_is_not_the_1080p_mode():
    slow = VideoTiming(640, 16, 96, 48, 480, 10, 2, 33, False, False, pixel_hz=25_175_000)
    dvi = CH7301CModel()
    play_table(ch7301c_table(slow), dvi)
    assert differences(dvi.state(), ch7301c_expected(slow)) == {}
    assert set(differences(dvi.state(), ch7301c_expected())) == {"dvi_pll", "hsync_positive", "vsync_positive"}


def test_unconfirmed_ch7301c_ids_are_read_and_reported_not_fatal():
    dvi = CH7301CModel(version_id=0x4A)
    result = play_table(CH7301C_TABLE, dvi)
    assert result.done and [(reg, v) for _, reg, v in result.mismatches] == [(0x4A, 0x4A)]
    assert differences(dvi.state(), ch7301c_expected()) == {}

