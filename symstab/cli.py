"""The ``symstab`` command line.

Every sub-command validates its arguments first; a bad value prints one line
on stderr and exits with status 2, never a traceback.
"""

import argparse
import pathlib
import sys
import time

__all__ = ["main"]

#: Where ``symstab derive`` writes without ``--out``.
DEFAULT_DERIVATIONS = pathlib.Path("derivations") / "generated"


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.exit(2, f"symstab: error: {message}\n")


def _cmd_derive(args):
    from . import derive

    start = time.perf_counter()
    out = pathlib.Path(args.out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out must be a directory, got file {out}")
    print("deriving: ZOH, characteristic polynomial, unit circle, boundary, limits, "
          "theta_max, proofs ...", file=sys.stderr)
    files = derive.render(derive.derivation_steps())
    if args.check:
        stale = derive.check(out, files)
        for path in stale:
            print(f"drift: {path} differs from a fresh derivation; run `symstab derive"
                  f"{'' if out == DEFAULT_DERIVATIONS else ' --out ' + str(out)}`")
        if stale:
            return 1
        print(f"{len(files)} files in {out} match a fresh derivation "
              f"({time.perf_counter() - start:.1f} s)")
        return 0
    written = derive.write(out, files)
    print(f"wrote {len(written)} files to {out} ({time.perf_counter() - start:.1f} s)")
    return 0


def build_parser():
    """Return the argument parser of the ``symstab`` command."""
    parser = _Parser(prog="symstab", description=(
        "Derive, audit and evaluate the stability boundary of a sampled haptic loop "
        "(Mashayekhi et al., IEEE Trans. Haptics 2025)."))
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    p = sub.add_parser("derive", help="regenerate every derived object as LaTeX and srepr JSON")
    p.add_argument("--out", default=str(DEFAULT_DERIVATIONS),
                   help=f"output directory (default: {DEFAULT_DERIVATIONS})")
    p.add_argument("--check", action="store_true",
                   help="compare the files in --out with a fresh derivation; exit 1 on drift")
    p.set_defaults(func=_cmd_derive)
    return parser


def main(argv=None):
    """Run the command line; return the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, TypeError, OSError) as exc:
        print(f"symstab: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
