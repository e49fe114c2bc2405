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
* ``mig/*.v``               with ``--mig DIR``: the user's MIG core's RTL (``DIR/user_design/rtl``), listed in
                            ``top.prj`` and the TCL script; ``top.ucf`` then ends with the core's UCF merged
                            (``board.mig_ucf``)

``--memory ddr2 --mig DIR`` builds the design with its camera frames in the board's DDR2 (the system's frame store,
``StereoDepthSystem(memory="ddr2")``, its ``mig`` port on the user interface of the MIG core the user generated in
ISE CoreGen: docs/board.md, "Generating the MIG core for the Genesys"; ``--mig-name`` if its component name is not
``mig_ddr2``); ``--mig DIR`` alone implies ``--memory ddr2``. ``--memory ddr2`` without ``--mig`` stops here with
one line saying what is missing; so does a core folder that lacks a file or port (``board.mig_core``), and so does
``--mig`` with ``--memory bram``. Without either, the build is the thesis's, its frames in block RAM.
``--mig-pinout FILE`` only writes the board's DDR2 pinout in MIG's port names, for CoreGen.

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
    parser.add_argument("--mig", metavar="DIR",
                        help="the MIG DDR2 core generated in ISE CoreGen (its folder: user_design/rtl/*.v, "
                             "user_design/par/*.ucf; docs/board.md): the board gets the DDR2")
    parser.add_argument("--mig-name", metavar="NAME", default=None,
                        help="the core's component name in CoreGen (mig_ddr2)")
    parser.add_argument("--memory", choices=("bram", "ddr2"), default=None,
                        help="where the camera frames are: bram (block RAM, the default) or ddr2 (the frame store "
                             "in the board's DDR2; needs --mig, which implies it)")
    parser.add_argument("--mig-pinout", metavar="FILE",
                        help="only write the board's DDR2 pinout in MIG's port names (a UCF) to FILE, for "
                             "generating the core in CoreGen (docs/board.md), and stop")


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


def _read_mig(folder, name):
    from board.mig import DEFAULT_CORE_NAME
    from board.mig_core import MIGCoreError, read_mig_core
    try:
        return read_mig_core(folder, name or DEFAULT_CORE_NAME)
    except MIGCoreError as exc:
        raise UserError(f"--mig {folder}: {exc}") from None


def write_board_build(out, *, pins=None, allow_unconfirmed=False, mig=None, memory=None):
    """Write the build directory; returns ``(platform, list of written paths)``. ``mig``: the user's MIG core
    (:func:`board.mig_core.read_mig_core`, implies ``memory="ddr2"``); ``memory``: the design's ``memory``
    (``None``: the board design's, ``"bram"``; ``"ddr2"`` needs ``mig``).

    Raises
    ------
    UserError
        The design has the DDR2 and no ``mig`` is given; the core's UCF contradicts the board.
    """
    from board.clocking import MIG_PLAN, PLAN
    from board.mig_ucf import MIGUCFError
    from board.top import MIGCoreMissing, board_plan
    from hdl.config import DesignConfig
    design = DesignConfig.full() if memory is None else DesignConfig.full(memory=memory)
    try:
        platform, plan = board_plan(design=design, pins=pins, allow_unconfirmed=allow_unconfirmed, mig=mig)
    except (MIGCoreMissing, MIGUCFError) as exc:
        raise UserError(str(exc)) from None
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, content in plan.files.items():
        path = out / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(content, str):
            path.write_text(content)
        else:
            path.write_bytes(content)
        if name.endswith(".sh"):
            path.chmod(0o755)
        written.append(path)
    lines = ["domain  frequency (MHz)  target (MHz)  error (ppm)  source"]
    rows = PLAN.table() + (MIG_PLAN.table() if platform.mig is not None else [])
    for domain, how, f, target, ppm in rows:
        lines.append(f"{domain:6}  {f / 1e6:15.6f}  {target / 1e6:12.6f}  {ppm:11.3f}  {how}")
    (out / "clocks.txt").write_text("\n".join(lines) + "\n")
    written.append(out / "clocks.txt")
    return platform, written


def _write_mig_pinout(path):
    from board.mig_ucf import pinout_ucf
    try:
        Path(path).write_text(pinout_ucf())
    except OSError as exc:
        raise UserError(f"cannot write {path}: {exc.strerror or exc}") from None
    print(f"{path}: the DDR2 pinout in MIG's port names (docs/board.md, \"Generating the MIG core for the Genesys\")")
    return 0


def run(args):
    if args.mig_pinout:
        return _write_mig_pinout(args.mig_pinout)
    prepare_out_dir(args.out)                                   # writable, before any work
    pins = _read_pins(args.pins) if args.pins else None
    if args.mig_name is not None and args.mig is None:
        raise UserError("--mig-name names the core of --mig DIR: give --mig too")
    if args.mig is not None and args.memory == "bram":
        raise UserError("--mig gives the board the DDR2 frame store: it contradicts --memory bram")
    mig = _read_mig(args.mig, args.mig_name) if args.mig else None
    platform, written = write_board_build(args.out, pins=pins, allow_unconfirmed=args.allow_unconfirmed, mig=mig,
                                          memory=args.memory)
    for path in written:
        print(f"{path}  ({path.stat().st_size:,} bytes)")
    unconfirmed = platform.unconfirmed_in_use
    if unconfirmed:
        how = ("left without LOC (trial builds only: do not program a board)" if args.allow_unconfirmed
               else "placeholders that ngdbuild rejects until you give --pins")
        print(f"warning: {len(unconfirmed)} VmodCAM pins are unconfirmed and {how}; see docs/board.md")
    print(f"ISE 14.7: cd {args.out} && ./build_top.sh   (or: xtclsh top_ise_project.tcl, then open top.xise)")
    return 0
