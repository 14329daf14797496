"""``symstab derive``: every derived object as LaTeX and srepr JSON, and the kernels.

Default output paths are resolved from the source checkout that holds the
package (:func:`symstab._project.project_root`), never from the current
folder; an installed copy has none, and ``derive`` then checks the
installed kernels (``--check``) or asks for ``--out``.  With ``--loop
FILE``, the derivation and kernels of one loop file, in one folder.
"""

import pathlib
import shlex
import sys
import time

from .._project import PACKAGE_DIR, project_root
from .options import add_command
from .output import check_outputs

__all__ = ["register", "run", "DEFAULT_DERIVATIONS", "DEFAULT_CODEGEN", "INSTALLED_CODEGEN"]


#: Where ``symstab derive`` writes without ``--out``, relative to the project root.
DEFAULT_DERIVATIONS = pathlib.Path("derivations") / "generated"
#: Where ``symstab derive`` writes the generated kernels without ``--codegen-out``,
#: relative to the project root.
DEFAULT_CODEGEN = pathlib.Path("symstab") / "_generated"
#: The folder of the installed package's generated kernels.
INSTALLED_CODEGEN = PACKAGE_DIR / "_generated"


def register(subparsers):
    """Add ``symstab derive`` to the sub-commands."""
    p = add_command(
        subparsers, "derive", help="regenerate every derived object as LaTeX and srepr JSON, "
                                   "and the NumPy and C kernels",
        description="Re-derive with SymPy every object of the paper's loop (ZOH, characteristic "
                    "polynomial, unit-circle split, boundary, limits, theta_max), prove the "
                    "rewritten forms equal, and write them as LaTeX and srepr JSON together with "
                    "the generated NumPy and C kernels; with --loop FILE, the same for the loop "
                    "of a loop file.",
        example="symstab derive --check", func=run)
    p.add_argument("--out", help=f"output directory (default: {DEFAULT_DERIVATIONS} in the "
                                 "source checkout; outside one, --check skips it and writing "
                                 "needs --out; with --loop: <loop name>_derivation)")
    p.add_argument("--codegen-out",
                   help=f"output directory of the generated NumPy and C kernels (default: "
                        f"{DEFAULT_CODEGEN} in the source checkout; outside one, --check checks "
                        "the installed package's kernels and writing needs --codegen-out)")
    p.add_argument("--check", action="store_true",
                   help="compare both output directories with a fresh run; exit 1 on drift")
    p.add_argument("--loop", metavar="FILE",
                   help="derive the loop of a TOML loop file (see examples/loops/) instead of the "
                        "paper's: its derivation (JSON, LaTeX) and its NumPy and C kernels go to "
                        "--out (default: <loop name>_derivation in the current folder)")


def _derive_paths(args):
    """``(out, code_out, root)`` of ``symstab derive``: the defaults come from the checkout.

    ``out`` is None when ``--check`` has no derivations to compare with (no
    ``--out`` and no ``derivations/generated`` in a checkout).  Without
    ``--check``, outside a checkout, a missing ``--out``/``--codegen-out``
    is an error: nothing is written into the current folder, nor into the
    installed package.
    """
    root = project_root()
    out = None if args.out is None else pathlib.Path(args.out)
    code_out = None if args.codegen_out is None else pathlib.Path(args.codegen_out)
    if args.check:
        if out is None and root is not None and (root / DEFAULT_DERIVATIONS).is_dir():
            out = root / DEFAULT_DERIVATIONS
        # In a checkout the installed package is the checkout's symstab/.
        return out, code_out or INSTALLED_CODEGEN, root
    if root is None and (out is None or code_out is None):
        # What the user did give is checked first: its error is the one to fix.
        check_outputs([("--out", out, "dir"), ("--codegen-out", code_out, "dir")])
        missing = " and ".join(flag for flag, path in (("--out", out), ("--codegen-out", code_out))
                               if path is None)
        raise ValueError(f"not in a source checkout of symstab (no pyproject.toml above "
                         f"{PACKAGE_DIR}): give {missing} for the files to write")
    return (out or root / DEFAULT_DERIVATIONS, code_out or root / DEFAULT_CODEGEN, root)


def _derive_loop(args):
    """``symstab derive --loop FILE``: the derivation and kernels of one loop, in one folder.

    Everything that can be refused is refused before the derivation starts:
    the loop file, ``--out`` (default ``<loop name>_derivation`` in the
    current folder), and a file of the user's in ``--out`` under a name the
    derivation would write (never overwritten).
    """
    from ..numeric.loop.files import load_loop
    from ..proof import derive, loop_derive

    start = time.perf_counter()
    if args.codegen_out is not None:
        raise ValueError("--codegen-out is for the paper's kernels; with --loop the kernels "
                         "are written to --out with the derivation")
    loop = load_loop(args.loop)
    out = pathlib.Path(args.out if args.out is not None
                       else f"{loop_derive.c_name(loop)}_derivation")
    names = loop_derive.file_names(loop)
    if args.check:   # reads only
        if out.exists() and not out.is_dir():
            raise ValueError(f"--out must be a directory, got file {out}")
    else:
        check_outputs([("--out", out, "dir")])
        for name in names:
            path = out / name
            if path.exists() and not (path.is_file() and loop_derive.is_generated(path)):
                raise ValueError(f"--out {out}: {path} exists and was not written by "
                                 f"`{loop_derive.COMMAND}`; move it away or choose another --out")
    print(f"deriving the loop {loop.name} ({loop.zoh_method}): ZOH, characteristic polynomial, "
          "affine parameters, NumPy and C kernels ...", file=sys.stderr)
    files = loop_derive.loop_files(loop)
    if args.check:
        stale = derive.check(out, files, owned=loop_derive.OWNED)
        # Quoted for a shell: the path is the user's and may hold anything.
        command = shlex.join(["symstab", "derive", "--loop", str(args.loop)]
                             + (["--out", str(args.out)] if args.out is not None else []))
        for path in stale:
            print(f"drift: {path} differs from a fresh derivation; run `{command}`")
        if stale:
            return 1
        print(f"{len(files)} files in {out} match a fresh derivation of the loop {loop.name} "
              f"({time.perf_counter() - start:.1f} s)")
        return 0
    written = derive.write(out, files)
    print(f"wrote {len(written)} files to {out} ({time.perf_counter() - start:.1f} s)")
    return 0


def run(args):
    """Run ``symstab derive``; return the exit status (1 on drift with --check)."""
    from ..codegen import generator as codegen
    from ..proof import derive

    if args.loop is not None:
        return _derive_loop(args)
    start = time.perf_counter()
    out, code_out, root = _derive_paths(args)
    if args.check:   # reads only
        for flag, path in (("--out", out), ("--codegen-out", code_out)):
            if path is not None and path.exists() and not path.is_dir():
                raise ValueError(f"{flag} must be a directory, got file {path}")
    else:
        check_outputs([("--out", out, "dir"), ("--codegen-out", code_out, "dir")])
    if out is None:
        # Installed without a checkout (or a checkout without derivations/):
        # the kernels are what the package runs on, and all there is to check.
        where = (f"no source checkout above {PACKAGE_DIR}" if root is None
                 else f"no {root / DEFAULT_DERIVATIONS}")
        print(f"{where} to compare the derivations with: checking the kernels in "
              f"{code_out} against a fresh generation")
        print("generating the NumPy and C kernels ...", file=sys.stderr)
        outputs = [(code_out, codegen.generated_files(), codegen.OWNED)]
    else:
        print("deriving: ZOH, characteristic polynomial, unit circle, boundary, limits, "
              "theta_max, proofs, code generation ...", file=sys.stderr)
        outputs = [(out, derive.render(derive.derivation_steps()), derive.OWNED),
                   (code_out, codegen.generated_files(), codegen.OWNED)]
    if args.check:
        command = "run `symstab derive" + "".join(
            f" {flag} {path}" for flag, path in (("--out", args.out),
                                                 ("--codegen-out", args.codegen_out))
            if path is not None) + "`"
        stale = []
        for folder, files, owned in outputs:
            # `symstab derive` cannot mend an installed package (and outside
            # a checkout refuses to write without --out and --codegen-out).
            advice = ("reinstall symstab" if root is None and folder == INSTALLED_CODEGEN
                      else command)
            stale += [(path, advice) for path in derive.check(folder, files, owned=owned)]
        for path, advice in stale:
            print(f"drift: {path} differs from a fresh derivation; {advice}")
        if stale:
            return 1
        print(f"{sum(len(files) for _, files, _ in outputs)} files in "
              f"{' and '.join(str(folder) for folder, _, _ in outputs)} "
              f"match a fresh derivation ({time.perf_counter() - start:.1f} s)")
        return 0
    written = [derive.write(folder, files) for folder, files, _ in outputs]
    print(f"wrote {len(written[0])} files to {out} and {len(written[1])} to {code_out} "
          f"({time.perf_counter() - start:.1f} s)")
    return 0
