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
#: Where ``symstab derive`` writes the generated kernels without ``--codegen-out``.
DEFAULT_CODEGEN = pathlib.Path("symstab") / "_generated"
#: Where ``symstab audit`` writes its report without ``--report``.
DEFAULT_REPORT = pathlib.Path("paper_checks") / "REPORT.md"


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        self.exit(2, f"symstab: error: {message}\n")


def _cmd_derive(args):
    from . import codegen, derive

    start = time.perf_counter()
    out, code_out = pathlib.Path(args.out), pathlib.Path(args.codegen_out)
    for flag, path in (("--out", out), ("--codegen-out", code_out)):
        if path.exists() and not path.is_dir():
            raise ValueError(f"{flag} must be a directory, got file {path}")
    print("deriving: ZOH, characteristic polynomial, unit circle, boundary, limits, "
          "theta_max, proofs, code generation ...", file=sys.stderr)
    outputs = [(out, derive.render(derive.derivation_steps()), derive.OWNED),
               (code_out, codegen.generated_files(), codegen.OWNED)]
    if args.check:
        command = "symstab derive"
        if out != DEFAULT_DERIVATIONS:
            command += f" --out {out}"
        if code_out != DEFAULT_CODEGEN:
            command += f" --codegen-out {code_out}"
        stale = [path for folder, files, owned in outputs
                 for path in derive.check(folder, files, owned=owned)]
        for path in stale:
            print(f"drift: {path} differs from a fresh derivation; run `{command}`")
        if stale:
            return 1
        print(f"{sum(len(files) for _, files, _ in outputs)} files in {out} and {code_out} "
              f"match a fresh derivation ({time.perf_counter() - start:.1f} s)")
        return 0
    written = [derive.write(folder, files) for folder, files, _ in outputs]
    print(f"wrote {len(written[0])} files to {out} and {len(written[1])} to {code_out} "
          f"({time.perf_counter() - start:.1f} s)")
    return 0


def _cmd_audit(args):
    try:
        from paper_checks import audit
    except ImportError as exc:  # pragma: no cover - packaging problem
        raise ValueError(f"the paper_checks package is not installed ({exc})") from exc
    from .derive import write

    start = time.perf_counter()

    def progress(n, total, cid):
        print(f"[{n:3d}/{total}] {cid}", file=sys.stderr, flush=True)

    try:
        findings = audit.run_audit(progress=progress if args.verbose else None)
    except (AssertionError, RuntimeError, ArithmeticError) as exc:
        print(f"symstab: audit failed inside a check: {type(exc).__name__}: {exc}", file=sys.stderr)
        return 1
    outputs = {pathlib.Path(args.report): audit.render_report(findings)}
    if args.json:
        outputs[pathlib.Path(args.json)] = audit.to_json(findings)
    for path, text in outputs.items():
        write(path.parent if str(path.parent) else ".", {path.name: text})
    counts = {}
    for f in findings:
        counts[f.verdict] = counts.get(f.verdict, 0) + 1
    summary = ", ".join(f"{counts[v]} {v}" for v in audit.VERDICTS if v in counts)
    print(f"audited {len(findings)} checks: {summary}; wrote "
          f"{', '.join(str(p) for p in outputs)} ({time.perf_counter() - start:.0f} s)")
    return 0


def _cmd_reproduce(args):
    from .reproduce import reproduce

    _, drift = reproduce(args.out, workers=args.workers)
    return 1 if drift else 0


def _cmd_figures(args):
    from .figures import make_figures

    def progress(name, seconds):
        print(f"{name}.png ({seconds:.1f} s)", file=sys.stderr, flush=True)

    out = pathlib.Path(args.out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out must be a directory, got file {out}")
    results = make_figures(out, progress=progress)
    for r in results:
        print(f"{out / (r.name + '.png')}: {r.symstab}")
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
    p.add_argument("--codegen-out", default=str(DEFAULT_CODEGEN),
                   help=f"output directory of the generated NumPy and C kernels (default: {DEFAULT_CODEGEN})")
    p.add_argument("--check", action="store_true",
                   help="compare both output directories with a fresh run; exit 1 on drift")
    p.set_defaults(func=_cmd_derive)
    p = sub.add_parser("audit", help="check every equation and claim of the paper; write REPORT.md")
    p.add_argument("--report", default=str(DEFAULT_REPORT),
                   help=f"Markdown report (default: {DEFAULT_REPORT})")
    p.add_argument("--json", metavar="PATH", help="also write the verdicts as JSON")
    p.add_argument("-v", "--verbose", action="store_true", help="print each check as it runs")
    p.set_defaults(func=_cmd_audit)
    p = sub.add_parser("figures", help="draw the paper's figures as PNG")
    p.add_argument("--out", default="figures", help="output directory (default: figures)")
    p.set_defaults(func=_cmd_figures)
    p = sub.add_parser("reproduce", help="derive (with the drift check), audit and draw every "
                                         "figure; write index.md")
    p.add_argument("--out", default="reproduction", help="output directory (default: reproduction)")
    p.add_argument("--workers", type=int, default=2, help="worker processes, >= 1 (default 2)")
    p.set_defaults(func=_cmd_reproduce)
    from . import cli_numeric, cli_simulate

    cli_numeric.add_commands(sub)
    cli_simulate.add_commands(sub)
    return parser


def main(argv=None):
    """Run the command line; return the exit status."""
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, or a usage error already printed
        return exc.code
    try:
        return args.func(args)
    except (ValueError, TypeError, OSError) as exc:
        print(f"symstab: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
