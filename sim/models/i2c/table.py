"""An init table as bus traffic and as an ideal bus playing it into a register-file model.

Two uses, both about the *sequencer* or the *models*, not about what the parts must do (that is
``golden.part_config``):

* :func:`expected_writes`, :func:`expected_reads`, :func:`expected_prefix`: what an
  :class:`hdl.i2c_init.InitSequencer` must put on the bus for a table (its ``Write`` entries in order; the
  registers its ``Poll`` / ``Check`` entries read) -- the sequencer tests compare the bus with these.
* :func:`play_table`: apply a table to a register-file model (``sim.models.mt9d112.target.MT9D112Model`` /
  ``CH7301CModel``) the way a sequencer would, without simulating the bus: writes in order, waits advancing the
  model's clock, polls read until they match or run out, checks recorded. Fast enough to try many mutated
  tables against the golden state (tests/test_part_config.py).
"""

from dataclasses import dataclass, field

from hdl.init_tables import Barrier, Check, InitTable, Poll, Wait, Write

__all__ = ["expected_writes", "expected_reads", "expected_prefix", "PlayResult", "play_table"]

#: Bus time the ideal player charges per transaction (seconds): one I2C write of a few bytes at 100 kHz.
TRANSACTION_S = 0.5e-3


def expected_writes(*tables):
    """``[(device name, register, value), ...]`` for the tables in the order given."""
    out = []
    for table in tables:
        if not isinstance(table, InitTable):
            raise TypeError("expected InitTable arguments")
        out += [(table.device.name, e.reg, e.value) for e in table.entries if isinstance(e, Write)]
    return out


def expected_reads(table):
    """``[(device name, register), ...]`` read by the table's polls and checks (one read each when they match)."""
    return [(table.device.name, e.reg) for e in table.entries if isinstance(e, (Poll, Check))]


def expected_prefix(table, entry):
    """The writes a table completes before entry number ``entry`` (when it stops there)."""
    return expected_writes(InitTable(table.device, table.entries[:entry])) if entry else []


@dataclass
class PlayResult:
    done: bool = False
    failed_entry: int = None          # the Poll that never matched
    mismatches: list = field(default_factory=list)   # (entry, register, value read) of failed Checks
    time_s: float = 0.0


def play_table(table, model, *, start_s=0.0):
    """Apply ``table`` to ``model`` (its ``write_register`` / ``read_register``, with ``model.now`` advanced as
    the table's waits and poll intervals pass). Exceptions from the model (a write it does not understand)
    propagate. Returns a :class:`PlayResult`."""
    r = PlayResult()
    now = max(start_s, getattr(model, "boot_s", 0.0))

    def access(fn, *args):
        nonlocal now
        model.now = now
        value = fn(*args)
        now += TRANSACTION_S
        return value

    for i, e in enumerate(table.entries):
        if isinstance(e, Write):
            access(model.write_register, e.reg, e.value)
        elif isinstance(e, Wait):
            now += e.us * 1e-6
        elif isinstance(e, Barrier):        # one table played alone: nothing to wait for
            continue
        elif isinstance(e, Check):
            value = access(model.read_register, e.reg)
            if value & e.mask != e.value:
                r.mismatches.append((i, e.reg, value))
        else:
            for _ in range(e.attempts):
                if access(model.read_register, e.reg) & e.mask == e.value:
                    break
                now += e.interval_us * 1e-6
            else:
                r.failed_entry = i
                r.time_s = now
                return r
    r.done = True
    r.time_s = now
    return r
