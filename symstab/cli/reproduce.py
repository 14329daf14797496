"""``symstab reproduce``: derive (with the drift check), audit and draw every figure; index.md."""

from .options import add_command
from .output import check_outputs

__all__ = ["register", "run"]


def register(subparsers):
    """Add ``symstab reproduce`` to the sub-commands."""
    p = add_command(
        subparsers, "reproduce", help="derive (with the drift check), audit and draw every figure; "
                                      "write index.md",
        description="Run the derivation (with the drift check), the audit and every figure in "
                    "one go and write an index.md that links the report and the figures.",
        example="symstab reproduce --out reproduction --workers 2", func=run)
    p.add_argument("--out", default="reproduction", help="output directory (default: reproduction)")
    p.add_argument("--workers", type=int, default=2, help="worker processes, >= 1 (default 2)")


def run(args):
    """Run ``symstab reproduce``; return the exit status (1 on drift)."""
    from ..reproduce import reproduce

    check_outputs([("--out", args.out, "dir")])
    _, drift = reproduce(args.out, workers=args.workers)
    return 1 if drift else 0
