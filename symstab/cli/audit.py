"""``symstab audit``: check every equation and claim of the paper; write REPORT.md (and JSON)."""

import pathlib
import sys
import time

from .._project import project_root
from .options import add_command
from .output import check_outputs, write_output

__all__ = ["register", "run", "DEFAULT_REPORT"]


#: Where ``symstab audit`` writes its report without ``--report``, relative to
#: the project root (outside a checkout: ``REPORT.md`` in the current folder).
DEFAULT_REPORT = pathlib.Path("paper_checks") / "REPORT.md"


def register(subparsers):
    """Add ``symstab audit`` to the sub-commands."""
    p = add_command(
        subparsers, "audit", help="check every equation and claim of the paper; write REPORT.md",
        description="Check every printed equation and claim of the paper against the "
                    "derivation and write the verdicts as a Markdown report (and JSON).",
        example="symstab audit --report REPORT.md --json audit.json", func=run)
    p.add_argument("--report", help=f"Markdown report (default: {DEFAULT_REPORT} in the source "
                                    "checkout, REPORT.md outside one)")
    p.add_argument("--json", metavar="PATH", help="also write the verdicts as JSON")
    p.add_argument("-v", "--verbose", action="store_true", help="print each check as it runs")


def _report_path(args):
    if args.report is not None:
        return args.report
    root = project_root()
    return root / DEFAULT_REPORT if root is not None else pathlib.Path("REPORT.md")


def run(args):
    """Run ``symstab audit``; return the exit status (1 when a check fails inside)."""
    try:
        from ..paper_checks import audit
    except ImportError as exc:  # pragma: no cover - packaging problem
        raise ValueError(f"symstab.paper_checks is not installed ({exc})") from exc
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
