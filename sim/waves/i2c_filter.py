#!/usr/bin/env python3
"""GTKWave transaction filter: an I2C bus (SCL, SDA) decoded into START, address + R/W, data bytes, ACK/NACK, STOP.

GTKWave runs this program when a save file attaches it to a trace (``^<1 /path/to/sim/waves/i2c_filter.py``
before a combined vector ``#{name} scl sda``, flag ``TR_TTRANSLATED``; see :mod:`sim.waves.gtkw`). For each such trace
GTKWave writes the trace's signals to the program's stdin as a small VCD (``$comment seqn N name $end`` before
each ``$var``, value changes, ``$comment data_end ... $end``) and reads back trace data: ``$name``, ``#time
[?colour?]text`` segments (a time with no text ends the previous segment), ``$next`` for the following trace and
``$finish`` (the GTKWave manual, "Transaction Filters Process"). This program answers with two traces:

* ``<name> bytes``: ``S`` / ``Sr`` at each (repeated) START, ``3C W`` / ``3C R`` for an address byte (7-bit
  address in hex), ``86`` for a data byte, each followed by ``A`` or ``N`` (acknowledged or not; a NACK from
  the target is drawn red, the controller's NACK ending a read is not), ``P`` at each STOP;
* ``<name>``: one segment per transaction, START to STOP, e.g. ``3C W 33 86 05 01`` or
  ``3C W 30 00 Sr 3C R 15 82N`` (a NACKed byte ends in ``N``).

The signals are told apart by name (the one ending in ``scl`` is the clock); failing that, the first is SCL.
Only the standard library is used, so GTKWave can run it with any ``python3``. The decoding itself is
:func:`decode` (bus levels in, :class:`Symbol` list out) and :func:`transactions`, which the tests call directly.
"""

import os
import sys
from dataclasses import dataclass

__all__ = ["Symbol", "decode", "transactions", "transaction_text", "parse_dump", "render", "main"]

#: GTKWave colour names (X11) of the segments.
COLOURS = {"start": "darkgreen", "address": "darkblue", "data": "grey24", "nack": "darkred", "stop": "darkgreen",
           "transaction": "darkslateblue"}


@dataclass(frozen=True)
class Symbol:
    """One decoded element: ``kind`` is ``start``, ``restart``, ``address``, ``data`` or ``stop``; ``start``/``end``
    are dump times; ``value`` the byte (address byte with its R/W bit), ``ack`` whether it was acknowledged,
    ``read`` whether a data byte came from the target (the controller NACKs the last byte of a read: no error)."""
    kind: str
    start: int
    end: int
    value: int = 0
    ack: bool = True
    read: bool = False

    @property
    def error(self):
        """A NACK from the target: an address or written byte not acknowledged."""
        return not self.ack and not self.read

    def text(self):
        if self.kind in ("start", "restart", "stop"):
            return {"start": "S", "restart": "Sr", "stop": "P"}[self.kind]
        ack = "A" if self.ack else "N"
        if self.kind == "address":
            return f"{self.value >> 1:02X} {'R' if self.value & 1 else 'W'} {ack}"
        return f"{self.value:02X} {ack}"


def decode(changes):
    """Decode ``[(time, scl, sda), ...]`` (levels after each change, in time order; the bus is idle-high before
    the first) into :class:`Symbol` objects. A byte is 8 bits sampled at SCL rising edges, MSB first, and an
    acknowledge bit; the first byte after a (repeated) START is an address byte."""
    out = []
    scl = sda = True
    busy = False
    bits, byte_start, after_start, reading = [], None, False, False
    last_fall = None
    for t, new_scl, new_sda in changes:
        new_scl, new_sda = bool(new_scl), bool(new_sda)
        if new_sda != sda and scl and new_scl:           # SDA moves while SCL is high: START or STOP
            if not new_sda:
                out.append(Symbol("restart" if busy else "start", t, t))
                busy, after_start, bits = True, True, []
            elif busy:
                out.append(Symbol("stop", t, t))
                busy, bits = False, []
        elif new_scl and not scl and busy:               # SCL rises: sample SDA
            if not bits:
                byte_start = last_fall if last_fall is not None else t
            bits.append(new_sda)
        if not new_scl and scl:
            last_fall = t
            if busy and len(bits) == 9:
                value = int("".join("1" if b else "0" for b in bits[:8]), 2)
                kind = "address" if after_start else "data"
                out.append(Symbol(kind, byte_start, t, value, not bits[8], reading and kind == "data"))
                if after_start:
                    reading = bool(value & 1)
                bits, after_start = [], False
        scl, sda = new_scl, new_sda
    return _close_conditions(out)


def _close_conditions(symbols):
    """Give START/STOP symbols a width: a START lasts until the next symbol begins, a STOP as long as the gap
    before it (capped by the next symbol)."""
    out = []
    for i, s in enumerate(symbols):
        nxt = symbols[i + 1].start if i + 1 < len(symbols) else None
        if s.kind in ("start", "restart"):
            end = nxt if nxt is not None and nxt > s.start else s.start + 1
        elif s.kind == "stop":
            prev = symbols[i - 1].end if i else s.start - 1
            end = s.start + max(1, s.start - prev)
            if nxt is not None:
                end = min(end, max(nxt, s.start + 1))
        else:
            end = s.end
        out.append(Symbol(s.kind, s.start, end, s.value, s.ack, s.read))
    return out


def transactions(symbols):
    """Group symbols START .. STOP: ``[(start time, end time, [symbol, ...]), ...]``. A transaction cut off by the
    end of the dump (no STOP) is kept, ending at its last symbol."""
    out, cur = [], None
    for s in symbols:
        if s.kind == "start":
            if cur:
                out.append((cur[0].start, cur[-1].end, cur))
            cur = [s]
        elif cur is not None:
            cur.append(s)
            if s.kind == "stop":
                out.append((cur[0].start, s.start, cur))
                cur = None
    if cur:
        out.append((cur[0].start, cur[-1].end, cur))
    return out


def transaction_text(symbols):
    """``3C W 30 00 Sr 3C R 15 82N``: the bytes of one transaction (``N`` after a byte not acknowledged)."""
    parts = []
    for s in symbols:
        if s.kind == "restart":
            parts.append("Sr")
        elif s.kind == "address":
            parts.append(f"{s.value >> 1:02X} {'R' if s.value & 1 else 'W'}{'' if s.ack else 'N'}")
        elif s.kind == "data":
            parts.append(f"{s.value:02X}{'' if s.ack else 'N'}")
    return " ".join(parts)


def parse_dump(lines):
    """Read GTKWave's VCD for one trace up to ``data_end``: ``(trace name, [(time, scl, sda), ...])``, one entry
    per instant at which either line changed. ``x``/``z`` count as high (released)."""
    names, order, changes = {}, [], []
    trace_name, seqn_name, t = "i2c", None, 0
    for line in lines:
        words = line.split()
        if not words:
            continue
        head = words[0]
        if head == "$comment" and len(words) > 2:
            if words[1] == "data_end":
                break
            if words[1] == "name":
                trace_name = words[2]
            elif words[1] == "seqn" and len(words) > 3:
                seqn_name = words[3]
        elif head == "$var" and len(words) >= 5:
            names[words[3]] = seqn_name or words[4]
            order.append(words[3])
        elif head.startswith("#"):
            t = int(head[1:])
        elif head[0] in "01xzXZ" and head[1:] in names:
            changes.append((t, head[1:], head[0] != "0"))
        elif head[0] in "bB" and len(words) > 1 and words[1] in names:
            changes.append((t, words[1], head[-1] != "0"))
    if len(order) < 2:
        return trace_name, []
    leaf = {i: n.lower().rsplit(".", 1)[-1] for i, n in names.items()}
    scl = next((i for i in order if leaf[i].endswith("scl")), order[0])
    sda = next((i for i in order if i != scl and leaf[i].endswith("sda")), next(i for i in order if i != scl))
    return trace_name, _levels(changes, scl, sda)


def _levels(changes, scl, sda):
    level = {scl: True, sda: True}
    out = []
    for n, (t, ident, value) in enumerate(changes):
        if ident in level:
            level[ident] = value
        if n + 1 == len(changes) or changes[n + 1][0] != t:
            if not out or out[-1][1:] != (level[scl], level[sda]):
                out.append((t, level[scl], level[sda]))
    return out


def render(name, symbols):
    """The program's answer for one trace: the byte-level trace, then the transaction trace, then ``$finish``."""
    lines = [f"$name {name} bytes", "#0"]
    for s in symbols:
        colour = COLOURS["nack"] if s.error else COLOURS[s.kind if s.kind != "restart" else "start"]
        lines += [f"#{s.start} ?{colour}?{s.text()}", f"#{s.end}"]
    lines += ["$next", f"$name {name}", "#0"]
    for start, end, group in transactions(symbols):
        colour = COLOURS["nack"] if any(s.error for s in group) else COLOURS["transaction"]
        lines += [f"#{start} ?{colour}?{transaction_text(group)}", f"#{max(end, start + 1)}"]
    lines.append("$finish")
    return lines


def main(stdin=sys.stdin, stdout=sys.stdout):
    """Serve GTKWave: one answer per ``data_end``, until stdin closes. With ``STEREO_I2C_FILTER_LOG`` set, the
    decoded transactions are also appended to that file (one line each, ``time text``) for tests."""
    log = os.environ.get("STEREO_I2C_FILTER_LOG")
    while True:
        lines = []
        for line in stdin:
            lines.append(line)
            if line.startswith("$comment data_end"):
                break
        if not lines:
            return 0
        name, levels = parse_dump(lines)
        symbols = decode(levels)
        stdout.write("\n".join(render(name, symbols)) + "\n")
        stdout.flush()
        if log:
            with open(log, "a") as f:
                for start, _, group in transactions(symbols):
                    f.write(f"{name} {start} {transaction_text(group)}\n")


if __name__ == "__main__":
    sys.exit(main())
