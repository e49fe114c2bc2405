"""``stereodepth``: one command-line tool for the whole project.

Each subcommand lives in its own module ``stereodepth/cmd_<name>.py`` exposing ``add_arguments(parser)`` and
``run(args) -> int``; its one-line help is in :data:`COMMANDS`. Modules are imported only when their subcommand
runs, so ``--help`` stays fast. The library code they call lives in ``sim/``, ``golden/`` and ``hdl/``. Bad
input raises :class:`stereodepth.errors.UserError`, printed as one line.
"""

import argparse
import importlib
import sys
import warnings

from .errors import UserError

#: subcommand name -> (module, one-line help). The order is the order ``--help`` lists them in.
COMMANDS = {
    "demo": ("cmd_demo", "run the whole simulated system on the bundled stereo pair -> build/demo/"),
    "run": ("cmd_run", "run the simulated system end to end on your own stereo pair"),
    "display": ("cmd_display", "simulate the display path alone (test pattern -> CH7301C bus -> PNG)"),
    "waves": ("cmd_waves", "write a VCD and a GTKWave save file of the display path"),
    "depth": ("cmd_depth", "software pipeline: disparity map, distance map and vertical shift of a pair"),
    "testbed": ("cmd_testbed", "reproduce the thesis's test bed (table 4.2, figure 4.35) in simulation"),
    "verilog": ("cmd_verilog", "write the Genesys board build (Verilog, UCF, ISE scripts) to build/genesys/"),
    "resources": ("cmd_resources", "Yosys synth_xilinx resource estimate of the top level"),
    "timing": ("cmd_timing", "static timing estimate of the board design (Yosys netlist, Virtex-5 -1 delays)"),
}


class _OneLineParser(argparse.ArgumentParser):
    """argparse, but a usage error is one line on stderr (``--help`` still prints the full usage)."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")


def _load(name):
    module_name, _ = COMMANDS[name]
    return importlib.import_module(f"{__package__}.{module_name}")


def build_parser():
    parser = argparse.ArgumentParser(
        prog="stereodepth",
        description="FPGA stereo-camera depth system: simulation, golden model and board build.",
    )
    parser.add_argument("--version", action="store_true", help="print the version (and git commit) and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, (_, help_text) in COMMANDS.items():
        sub.add_parser(name, help=help_text, add_help=False)
    return parser, sub


def _quiet_unused():
    """A command that stops on an error leaves the blocks it had built unelaborated: no Amaranth "created but never
    used" warning after the one-line error."""
    from amaranth.hdl import UnusedElaboratable
    warnings.filterwarnings("ignore", category=UnusedElaboratable)


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    parser, _ = build_parser()
    if argv and argv[0] in ("-h", "--help"):
        parser.print_help()
        return 0
    if argv and argv[0] == "--version":
        from stereodepth.provenance import project_version
        print(f"stereodepth {project_version()}")
        return 0
    if not argv or argv[0] not in COMMANDS:
        parser.print_usage(sys.stderr)
        what = ("a command is required" if not argv else
                f"unrecognized option {argv[0]!r}" if argv[0].startswith("-") else f"unknown command {argv[0]!r}")
        print(f"stereodepth: error: {what} (see --help)", file=sys.stderr)
        return 2
    name = argv[0]
    try:
        module = _load(name)
    except ModuleNotFoundError as exc:
        if exc.name and exc.name.endswith(COMMANDS[name][0]):
            print(f"stereodepth: error: command {name!r} is not built yet", file=sys.stderr)
            return 2
        raise
    sub_parser = _OneLineParser(prog=f"stereodepth {name}", description=COMMANDS[name][1])
    module.add_arguments(sub_parser)
    args = sub_parser.parse_args(argv[1:])
    try:
        return int(module.run(args) or 0)
    except UserError as exc:
        _quiet_unused()
        print(f"stereodepth {name}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        _quiet_unused()
        print(f"stereodepth {name}: interrupted; files named *.partial.* are incomplete", file=sys.stderr)
        return 130
