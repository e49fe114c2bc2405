"""The pin file of ``stereodepth verilog --pins``: FPGA pins for the Genesys VHDC connector's placeholder pins.

One ``PLACEHOLDER LOC`` (or ``PLACEHOLDER = LOC``) per line, ``#`` comments, case-insensitive, e.g.
``UNCONFIRMED_VHDC_12 AB12`` (VHDC connector pin 12 on FPGA pin AB12). The placeholder names are
:data:`board.genesys.UNCONFIRMED`; :class:`board.genesys.GenesysPlatform` takes the result as ``pins``.
"""

import re

from board.genesys import UNCONFIRMED

__all__ = ["parse_pin_file"]

_PIN_LINE = re.compile(r"^\s*(UNCONFIRMED_[A-Z0-9_]+)\s*[=:\s]\s*([A-Z]{1,2}[0-9]{1,2})\s*(#.*)?$")


def parse_pin_file(text):
    """``{placeholder: loc}`` from the pin file's text.

    Raises
    ------
    ValueError
        Naming the first bad line (not ``placeholder pin``, an FF1136 pin name that cannot be one, or a name that
        is not one of this platform's placeholders): one line, for the command line's error message.
    """
    pins = {}
    for number, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        match = _PIN_LINE.match(line.upper())
        if not match:
            raise ValueError(f"line {number}: expected 'UNCONFIRMED_<name> <FF1136 pin>', got {raw.strip()!r}")
        name, loc = match.group(1), match.group(2)
        if name not in UNCONFIRMED:
            raise ValueError(f"line {number}: {name} is not a placeholder pin of this platform")
        pins[name] = loc
    return pins
