"""The design a board command builds (``resources``, ``timing``): ``--small``, ``--build``, ``--memory``, ``--maps``,
resolved into a :class:`hdl.config.DesignConfig` with a one-line :class:`~stereodepth.errors.UserError` for a
combination no design has."""

from .errors import UserError

__all__ = ["add_build_argument", "add_design_arguments", "design_of", "check_build_800", "preset_of"]

#: ``--build``: the thesis's design (``DesignConfig.full``) or the 800 x 600 build (``DesignConfig.full_800``);
#: with ``--small`` each at the small size (``DesignConfig.small``, ``DesignConfig.small_800``).
BUILDS = ("thesis", "800")


def add_build_argument(parser):
    """``--build thesis|800`` (:data:`BUILDS`), the one definition every command that takes it shares."""
    parser.add_argument("--build", choices=BUILDS, default="thesis",
                        help="thesis (400 x 300 buffers, D = 64; the default) or 800 (8-bit 800 x 600 buffers, "
                             "D = 128, maps 1:1 on the screen, the frames and the depth maps in the DDR2: --memory "
                             "ddr2 --maps store)")


def add_design_arguments(parser, what="estimate"):
    """The four options; ``what`` names the command's action in their help."""
    parser.add_argument("--small", action="store_true",
                        help=f"{what} the small design of the default test run instead of the board's (quick "
                             "check); with --build 800 the 800 x 600 build's structure at that size (8-bit 32 x 24 "
                             "buffers, D = 16)")
    add_build_argument(parser)
    parser.add_argument("--memory", choices=("bram", "ddr2"), default=None,
                        help="where the camera frames are: bram (block RAM, the thesis build's default) or ddr2 "
                             "(the frame store in the board's DDR2 behind MIG: adds the mem domain)")
    parser.add_argument("--maps", choices=("ring", "store"), default=None,
                        help="where the depth maps are: ring (the engine's ring, the thesis build's default) or "
                             "store (with --memory ddr2: whole maps in the frame store)")


def check_build_800(memory, maps):
    """``--build 800`` with ``--memory`` and ``--maps`` as given (``None``: not given): a one-line
    :class:`UserError` for one the 800 x 600 build contradicts."""
    for option, value, needed in (("memory", memory, "ddr2"), ("maps", maps, "store")):
        if value not in (None, needed):
            raise UserError(f"--build 800 keeps its frames and maps in the DDR2: drop --{option} {value}")


def preset_of(build, small):
    """The preset ``--build`` and ``--small`` name: a name of ``hdl.config.DesignConfig``'s presets and of
    ``sim.testbench.system.setup.SystemSetup``'s (``"full"``, ``"small"``, ``"full_800"``, ``"small_800"``)."""
    return ("small" if small else "full") + ("_800" if build == "800" else "")


def design_of(args):
    """The :class:`hdl.config.DesignConfig` the options name; sets ``args.memory`` and ``args.maps`` to the
    design's."""
    from hdl.config import DesignConfig
    if args.build == "800":
        check_build_800(args.memory, args.maps)
        design = getattr(DesignConfig, preset_of(args.build, args.small))()
    else:
        memory, maps = args.memory or "bram", args.maps or "ring"
        if maps == "store" and memory != "ddr2":
            raise UserError("--maps store keeps the depth maps in the frame store: it needs --memory ddr2")
        design = (DesignConfig.small if args.small else DesignConfig.full)(memory=memory, maps=maps)
    args.memory, args.maps = design.memory, design.maps
    return design
