"""The ``symstab`` command line.

Every sub-command validates its arguments, and checks its output paths
(:func:`check_outputs`), before any long work; a bad value prints one line
``symstab <command>: error: ...`` on stderr and exits with status 2, never a
traceback.  Ctrl-C (SIGINT) and SIGTERM print ``symstab <command>:
interrupted`` and exit with status 130 and 143; files are written
atomically (:func:`write_output`), so an interrupted run leaves none behind.

Default output paths of ``derive`` and ``audit`` are resolved from the
source checkout that holds the package (:func:`project_root`), never from
the current folder; an installed copy has none, and ``derive`` then checks
the installed kernels (``--check``) or asks for ``--out``.
"""

import argparse
import importlib.metadata
import os
import pathlib
import shlex
import signal
import sys
import tempfile
import textwrap
import time
import warnings

__all__ = ["main", "check_outputs", "write_output", "project_root", "package_version",
           "add_command"]

#: Where ``symstab derive`` writes without ``--out``, relative to the project root.
DEFAULT_DERIVATIONS = pathlib.Path("derivations") / "generated"
#: Where ``symstab derive`` writes the generated kernels without ``--codegen-out``,
#: relative to the project root.
DEFAULT_CODEGEN = pathlib.Path("symstab") / "_generated"
#: Where ``symstab audit`` writes its report without ``--report``, relative to
#: the project root (outside a checkout: ``REPORT.md`` in the current folder).
DEFAULT_REPORT = pathlib.Path("paper_checks") / "REPORT.md"
#: The folder of the installed package, and of its generated kernels.
from .._project import PACKAGE_DIR, project_root  # noqa: E402  (re-exported)

INSTALLED_CODEGEN = PACKAGE_DIR / "_generated"


def package_version():
    """The installed version of symstab (package metadata), else the checkout's, else "unknown".

    A checkout run without ``pip install`` has no metadata: its
    ``pyproject.toml`` gives the version, marked "not installed".
    """
    try:
        return importlib.metadata.version("symstab")
    except importlib.metadata.PackageNotFoundError:
        pass
    root = project_root()
    if root is not None:
        try:
            import tomllib
        except ImportError:   # Python 3.10: no TOML reader in the standard library
            tomllib = None
        if tomllib is not None:
            with open(root / "pyproject.toml", "rb") as fh:
                version = tomllib.load(fh).get("project", {}).get("version")
            if version:
                return f"{version} (source checkout {root}, not installed)"
    return "unknown (not installed: no package metadata)"


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        # self.prog is "symstab" or "symstab <command>" for a sub-parser.
        self.exit(2, f"{self.prog}: error: {message}\n")


def add_command(sub, name, *, help, description, example, func):
    """Add the sub-command ``name``: a one-sentence ``description`` and an ``example`` in --help.

    ``help`` is the short line of the command list of ``symstab --help``;
    ``example`` is the command line printed (indented) under "example:".
    """
    parser = sub.add_parser(name, help=help, description=textwrap.fill(description, 79),
                            epilog=f"example:\n  {example}",
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.set_defaults(func=func)
    return parser


# --------------------------------------------------------------------------
# Output paths: one check for every command, before the work starts


def _probe_folder(folder):
    """Raise OSError unless a file can be created in the existing ``folder``.

    An anonymous temporary file, gone when closed: the only test that also
    holds for root and for read-only file systems (``os.access`` does not).
    """
    with tempfile.TemporaryFile(dir=folder):
        pass


def check_outputs(outputs):
    """Check the output paths of a command before it runs; return them as Paths.

    Parameters
    ----------
    outputs : iterable of (str, path-like or None, str)
        ``(flag, path, kind)`` with ``kind`` ``"file"`` (written atomically
        into an existing folder) or ``"dir"`` (created with its parents if
        missing).  Entries whose path is None are skipped.

    Returns
    -------
    dict
        ``{flag: pathlib.Path}`` of the checked entries.

    Raises
    ------
    ValueError
        Naming the flag and the user's path: a file that is a directory, a
        directory that is a file, a missing or unwritable folder, or two
        outputs that name the same file (after resolving ``..`` and links).
    """
    checked, seen = {}, {}
    for flag, path, kind in outputs:
        if path is None:
            continue
        if kind not in ("file", "dir"):
            raise ValueError(f"kind must be 'file' or 'dir', got {kind!r}")
        path = pathlib.Path(path)
        if kind == "file":
            if path.is_dir():
                raise ValueError(f"{flag} {path} is a directory, expected a file name")
            folder = path.parent
            if not folder.exists():
                raise ValueError(f"{flag} {path}: folder {folder} does not exist")
            if not folder.is_dir():
                raise ValueError(f"{flag} {path}: {folder} is not a folder")
        else:
            if path.exists() and not path.is_dir():
                raise ValueError(f"{flag} must be a directory, got file {path}")
            folder = path
            while not folder.exists():   # created at the first write
                folder = folder.parent
            if not folder.is_dir():
                raise ValueError(f"{flag} {path}: {folder} is a file, not a folder")
        try:
            _probe_folder(folder)
        except OSError as exc:
            raise ValueError(f"{flag} {path}: cannot write in folder {folder} "
                             f"({exc.strerror or exc})") from None
        key = os.path.realpath(path)
        if key in seen and "file" in (kind, seen[key][1]):
            raise ValueError(f"{seen[key][0]} and {flag} name the same file {path}; "
                             "give them different paths")
        seen.setdefault(key, (flag, kind))
        checked[flag] = path
    return checked


def write_output(path, data, flag):
    """Write ``data`` (bytes or str) to ``path`` atomically; errors name ``flag`` and ``path``.

    The bytes go to a temporary file in the same folder, renamed into place
    (:func:`symstab.proof.derive.write_bytes`), which is removed on any failure,
    Ctrl-C and SIGTERM included.
    """
    from ..proof.derive import write_bytes

    if isinstance(data, str):
        data = data.encode("utf-8")
    try:
        return write_bytes(path, data)
    except OSError as exc:
        raise OSError(f"cannot write {flag} {path}: {exc.strerror or exc}") from None


# --------------------------------------------------------------------------
# Commands


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
    from ..proof import derive
    from ..proof import loop_derive
    from ..numeric.loop_files import load_loop

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


def _cmd_derive(args):
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


def _report_path(args):
    if args.report is not None:
        return args.report
    root = project_root()
    return root / DEFAULT_REPORT if root is not None else pathlib.Path("REPORT.md")


def _cmd_audit(args):
    try:
        from paper_checks import audit
    except ImportError as exc:  # pragma: no cover - packaging problem
        raise ValueError(f"the paper_checks package is not installed ({exc})") from exc
    paths = check_outputs([("--report", _report_path(args), "file"), ("--json", args.json, "file")])
    start = time.perf_counter()

    def progress(n, total, cid):
        print(f"[{n:3d}/{total}] {cid}", file=sys.stderr, flush=True)

    try:
        findings = audit.run_audit(progress=progress if args.verbose else None)
    except (AssertionError, RuntimeError, ArithmeticError) as exc:
        print(f"symstab audit: audit failed inside a check: {type(exc).__name__}: {exc}",
              file=sys.stderr)
        return 1
    outputs = {paths["--report"]: ("--report", audit.render_report(findings))}
    if args.json:
        outputs[paths["--json"]] = ("--json", audit.to_json(findings))
    for path, (flag, text) in outputs.items():
        write_output(path, text, flag)
    counts = {}
    for f in findings:
        counts[f.verdict] = counts.get(f.verdict, 0) + 1
    summary = ", ".join(f"{counts[v]} {v}" for v in audit.VERDICTS if v in counts)
    print(f"audited {len(findings)} checks: {summary}; wrote "
          f"{', '.join(str(p) for p in outputs)} ({time.perf_counter() - start:.0f} s)")
    return 0


def _cmd_reproduce(args):
    from ..reproduce import reproduce

    check_outputs([("--out", args.out, "dir")])
    _, drift = reproduce(args.out, workers=args.workers)
    return 1 if drift else 0


def _cmd_figures(args):
    from ..figures import make_figures

    def progress(name, seconds):
        print(f"{name}.png ({seconds:.1f} s)", file=sys.stderr, flush=True)

    out = check_outputs([("--out", args.out, "dir")])["--out"]
    results = make_figures(out, progress=progress)
    for r in results:
        print(f"{out / (r.name + '.png')}: {r.symstab}")
    return 0


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
    p = add_command(
        sub, "derive", help="regenerate every derived object as LaTeX and srepr JSON, "
                            "and the NumPy and C kernels",
        description="Re-derive with SymPy every object of the paper's loop (ZOH, characteristic "
                    "polynomial, unit-circle split, boundary, limits, theta_max), prove the "
                    "rewritten forms equal, and write them as LaTeX and srepr JSON together with "
                    "the generated NumPy and C kernels; with --loop FILE, the same for the loop "
                    "of a loop file.",
        example="symstab derive --check", func=_cmd_derive)
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
    p = add_command(
        sub, "audit", help="check every equation and claim of the paper; write REPORT.md",
        description="Check every printed equation and claim of the paper against the "
                    "derivation and write the verdicts as a Markdown report (and JSON).",
        example="symstab audit --report REPORT.md --json audit.json", func=_cmd_audit)
    p.add_argument("--report", help=f"Markdown report (default: {DEFAULT_REPORT} in the source "
                                    "checkout, REPORT.md outside one)")
    p.add_argument("--json", metavar="PATH", help="also write the verdicts as JSON")
    p.add_argument("-v", "--verbose", action="store_true", help="print each check as it runs")
    p = add_command(
        sub, "figures", help="draw the paper's figures as PNG",
        description="Redraw the paper's figures from the derived boundary and the numeric API "
                    "and save them as PNG, one line per figure on what symstab finds.",
        example="symstab figures --out figures", func=_cmd_figures)
    p.add_argument("--out", default="figures", help="output directory (default: figures)")
    p = add_command(
        sub, "reproduce", help="derive (with the drift check), audit and draw every figure; "
                               "write index.md",
        description="Run the derivation (with the drift check), the audit and every figure in "
                    "one go and write an index.md that links the report and the figures.",
        example="symstab reproduce --out reproduction --workers 2", func=_cmd_reproduce)
    p.add_argument("--out", default="reproduction", help="output directory (default: reproduction)")
    p.add_argument("--workers", type=int, default=2, help="worker processes, >= 1 (default 2)")
    from . import locus as cli_locus
    from . import numeric as cli_numeric
    from . import simulate as cli_simulate

    cli_numeric.add_commands(sub)
    cli_simulate.add_commands(sub)
    cli_locus.add_commands(sub)
    return parser


class _Terminated(BaseException):
    """SIGTERM, raised in the main thread so that cleanup (temporary files) runs.

    A BaseException, like KeyboardInterrupt, so that no ``except Exception``
    on the way swallows it.
    """


def _raise_terminated(signum, frame):
    raise _Terminated


#: Exit statuses of a command stopped by a signal (128 + the signal number).
EXIT_SIGINT = 128 + signal.SIGINT
EXIT_SIGTERM = 128 + signal.SIGTERM


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
    ``symstab <command>: interrupted``).
    """
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
    # `symstab reproduce` stops its worker processes on SIGTERM itself.
    previous = None
    if args.command != "reproduce":
        try:
            previous = signal.signal(signal.SIGTERM, _raise_terminated)
        except ValueError:  # not the main thread: leave signals alone
            previous = None
    try:
        with warnings.catch_warnings():
            # NumPy's floating-point RuntimeWarnings (overflow in an
            # intermediate that the result does not depend on) are not for
            # the user: results are validated, and what cannot be computed
            # raises an error naming the parameter.
            warnings.simplefilter("ignore", RuntimeWarning)
            return args.func(args)
    except (KeyboardInterrupt, _Terminated) as exc:
        # On a terminal a progress bar may hold the line: start a new one.
        print(f"{chr(10) if sys.stderr.isatty() else ''}{prog}: interrupted", file=sys.stderr)
        return EXIT_SIGINT if isinstance(exc, KeyboardInterrupt) else EXIT_SIGTERM
    except (ValueError, TypeError, ArithmeticError, MemoryError, OSError) as exc:
        print(f"{prog}: error: {_one_line(exc)}", file=sys.stderr)
        return 2
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
