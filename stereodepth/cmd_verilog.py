"""``stereodepth verilog``: write the Genesys board build (Verilog, UCF, ISE scripts) -- without running ISE.

Writes to ``--out`` (default build/genesys/) what Amaranth's ``XilinxPlatform`` prepares for ISE, for
:class:`board.top.GenesysTop` on :class:`board.genesys.GenesysPlatform`, the board's design
(:meth:`hdl.config.DesignConfig.full`):

* ``top.v``                 the whole design as one Verilog file (XST input, ``board.export.xst_verilog``)
* ``top.ucf``               pins, IO standards, PERIODs on the clock pads, the TIGs between unrelated clocks,
                            OFFSET IN/OUT; the same text as the checked-in ``constraints/genesys.ucf`` (checked by
                            tests/test_genesys.py)
* ``top.prj``, ``top.xst``  the XST project and script
* ``build_top.sh``/``.bat`` the command-line flow: xst, ngdbuild, map, par, trce, and bitgen only when timing is met
* ``top_ise_project.tcl``   ``xtclsh`` script that creates an ISE project (``top.xise``) for Project Navigator
* ``clocks.txt``            the clock plan (M/D values, frequencies, error)

The FPGA pins behind the Genesys's VHDC connector are not confirmed from a source (docs/board.md): the
connector's map holds placeholders named ``UNCONFIRMED_VHDC_<connector pin>`` that ngdbuild rejects, so no
bitstream can come out with guessed camera pins. Give the real locations with ``--pins FILE`` (lines
``UNCONFIRMED_VHDC_15 AB12``, read by ``board.pin_file``), or use ``--allow-unconfirmed`` to
leave those LOCs out (ISE then places the camera ports itself: for trial synthesis and timing only, never for a
board).
"""

from pathlib import Path

from .errors import UserError, prepare_out_dir


def add_arguments(parser):
    parser.add_argument("--out", default="build/genesys", metavar="DIR", help="output directory (build/genesys)")
    parser.add_argument("--pins", metavar="FILE",
                        help="FPGA pins for the VHDC connector's placeholders: lines 'UNCONFIRMED_VHDC_<n> <pin>'")
    parser.add_argument("--allow-unconfirmed", action="store_true",
                        help="leave the LOC of still-unconfirmed pins out of the UCF (trial builds only)")


def _read_pins(path):
    from board.pin_file import parse_pin_file
    path = Path(path)
    if not path.is_file():
        raise UserError(f"no such pin file: {path}")
    try:
        return parse_pin_file(path.read_text())
    except (OSError, UnicodeDecodeError) as exc:
        raise UserError(f"cannot read pin file {path}: {exc}") from None
    except ValueError as exc:
        raise UserError(f"{path}: {exc}") from None


def write_board_build(out, *, pins=None, allow_unconfirmed=False):
    """Write the build directory; returns ``(platform, list of written paths)``."""
    from board.clocking import PLAN
    from board.top import board_plan
    from hdl.config import DesignConfig
    platform, plan = board_plan(design=DesignConfig.full(), pins=pins, allow_unconfirmed=allow_unconfirmed)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, content in plan.files.items():
        path = out / name
        if isinstance(content, str):
            path.write_text(content)
        else:
            path.write_bytes(content)
        if name.endswith(".sh"):
            path.chmod(0o755)
        written.append(path)
    lines = ["domain  frequency (MHz)  target (MHz)  error (ppm)  source"]
    for domain, how, f, target, ppm in PLAN.table():
        lines.append(f"{domain:6}  {f / 1e6:15.6f}  {target / 1e6:12.6f}  {ppm:11.3f}  {how}")
    (out / "clocks.txt").write_text("\n".join(lines) + "\n")
    written.append(out / "clocks.txt")
    return platform, written


def run(args):
    prepare_out_dir(args.out)                                   # writable, before any work
    pins = _read_pins(args.pins) if args.pins else None
    platform, written = write_board_build(args.out, pins=pins, allow_unconfirmed=args.allow_unconfirmed)
    for path in written:
        print(f"{path}  ({path.stat().st_size:,} bytes)")
    unconfirmed = platform.unconfirmed_in_use
    if unconfirmed:
        how = ("left without LOC (trial builds only: do not program a board)" if args.allow_unconfirmed
               else "placeholders that ngdbuild rejects until you give --pins")
        print(f"warning: {len(unconfirmed)} VmodCAM pins are unconfirmed and {how}; see docs/board.md")
    print(f"ISE 14.7: cd {args.out} && ./build_top.sh   (or: xtclsh top_ise_project.tcl, then open top.xise)")
    return 0
