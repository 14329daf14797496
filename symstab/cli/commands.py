"""The ``symstab`` command line: the parser built from the command modules, and ``main``.

Each command is a module of this package with ``register(subparsers)`` and
``run(args)`` (:data:`COMMAND_NAMES`, in the order of ``symstab --help``); the
options, units and output they share are in :mod:`symstab.cli.options`,
:mod:`symstab.cli.loop_options`, :mod:`symstab.cli.units` and
:mod:`symstab.cli.output`.  A command module imports shared modules only,
never another command module.

Every sub-command validates its arguments, and checks its output paths
(:func:`symstab.cli.output.check_outputs`), before any long work; a bad
value prints one line ``symstab <command>: error: ...`` on stderr and exits
with status 2, never a traceback.  Ctrl-C (SIGINT) and SIGTERM print
``symstab <command>: interrupted`` and exit with status 130 and 143; files
are written atomically (:func:`symstab.cli.output.write_output`), so an
interrupted run leaves none behind.
"""

import argparse
import importlib
import sys
import warnings

from .._project import package_version, project_root
from .._signals import (
    Terminated,
    exit_status,
    import_outside_swallowers,
    interruption_behind,
    raising,
)

__all__ = ["main", "build_parser", "package_version", "project_root", "COMMAND_NAMES",
           "command_modules"]

#: The commands, in the order of ``symstab --help``; each is the module of
#: this package of the same name.
COMMAND_NAMES = ("derive", "audit", "figures", "reproduce", "boundary", "limits", "classify",
                 "margins", "design", "simulate", "map", "locus", "sweep")


def command_modules():
    """The command modules, in the order of :data:`COMMAND_NAMES` (imported on first use).

    Not at import time: :func:`main` handles Ctrl-C and SIGTERM before the
    command modules bring in SymPy and NumPy.
    """
    return tuple(importlib.import_module(f"{__package__}.{name}") for name in COMMAND_NAMES)


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        # self.prog is "symstab" or "symstab <command>" for a sub-parser.
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser():
    """Return the argument parser of the ``symstab`` command."""
    parser = _Parser(prog="symstab", description=(
        "Derive, audit and evaluate the stability boundary of a sampled haptic loop "
        "(Mashayekhi et al., IEEE Trans. Haptics 2025)."),
        epilog="Run `symstab <command> --help` for the options of a command.")
    parser.add_argument("--version", action="version", version=f"symstab {package_version()}")
    # Not required: without a command main() prints this help (argparse
    # would print one line naming no command).
    sub = parser.add_subparsers(dest="command", metavar="command", title="commands",
                                parser_class=_Parser)
    for command in command_modules():
        command.register(sub)
    return parser


def _one_line(exc):
    """The message of a last-resort error: one line, saying what to do."""
    if isinstance(exc, MemoryError):
        from .._resources import MEMORY_LIMIT_ENV

        return (f"out of memory{f' ({exc})' if str(exc) else ''}: use a smaller problem; "
                f"{MEMORY_LIMIT_ENV} sets the limit symstab checks against")
    if isinstance(exc, ArithmeticError):
        return (f"numeric {type(exc).__name__} ({exc}): an input is outside the range "
                "floating point can represent")
    text = str(exc) or type(exc).__name__
    return " ".join(text.split())


def main(argv=None):
    """Run the command line; return the exit status.

    0 on success; 1 when a check finds drift or a failure; 2 on bad input
    (one line on stderr); 130 on Ctrl-C and 143 on SIGTERM (one line
    ``symstab <command>: interrupted``), wherever the signal lands, the
    first imports included.
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        try:
            with raising():
                return _main(argv)
        except Exception as exc:
            # An interruption Python wrapped (a class's __set_name__, 3.11).
            interruption = interruption_behind(exc)
            if interruption is None:
                raise
            raise interruption from None
    except (KeyboardInterrupt, Terminated) as exc:
        # On a terminal a progress bar may hold the line: start a new one.
        print(f"{chr(10) if sys.stderr.isatty() else ''}{_prog(argv)}: interrupted",
              file=sys.stderr)
        return exit_status(exc)


def _prog(argv):
    """``symstab <command>`` as far as ``argv`` names one (the parser may not have run yet)."""
    command = next((word for word in argv if word in COMMAND_NAMES), None)
    return "symstab" if command is None else f"symstab {command}"


def _main(argv):
    parser = build_parser()
    try:
        args, extra = parser.parse_known_args(argv)
    except SystemExit as exc:  # --help, or a usage error already printed
        return exc.code
    if args.command is None:
        if extra:
            print(f"symstab: error: unrecognized arguments: {' '.join(extra)}", file=sys.stderr)
        else:
            # The usage and the list of commands, then the one error line.
            parser.print_help(sys.stderr)
            print("\nsymstab: error: no command given: choose one of the commands above",
                  file=sys.stderr)
        return 2
    prog = f"symstab {args.command}"
    if extra:  # argparse would blame "symstab", not the command
        print(f"{prog}: error: unrecognized arguments: {' '.join(extra)}", file=sys.stderr)
        return 2
    # Before any numerics (mpmath would import gmpy2 where a signal is dropped).
    import_outside_swallowers()
    try:
        with warnings.catch_warnings():
            # NumPy's floating-point RuntimeWarnings (overflow in an
            # intermediate that the result does not depend on) are not for
            # the user: results are validated, and what cannot be computed
            # raises an error naming the parameter.
            warnings.simplefilter("ignore", RuntimeWarning)
            return args.func(args)
    except (ValueError, TypeError, ArithmeticError, MemoryError, OSError) as exc:
        print(f"{prog}: error: {_one_line(exc)}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
