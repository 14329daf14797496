"""``symstab figures``: the paper's figures as PNG, one line per figure on what symstab finds."""

import sys

from .options import add_command
from .output import check_outputs

__all__ = ["register", "run"]


def register(subparsers):
    """Add ``symstab figures`` to the sub-commands."""
    p = add_command(
        subparsers, "figures", help="draw the paper's figures as PNG",
        description="Redraw the paper's figures from the derived boundary and the numeric API "
                    "and save them as PNG, one line per figure on what symstab finds.",
        example="symstab figures --out figures", func=run)
    p.add_argument("--out", default="figures", help="output directory (default: figures)")


def run(args):
    """Run ``symstab figures``; return the exit status."""
    from ..figures import make_figures

    def progress(name, seconds):
        print(f"{name}.png ({seconds:.1f} s)", file=sys.stderr, flush=True)

    out = check_outputs([("--out", args.out, "dir")])["--out"]
    results = make_figures(out, progress=progress)
    for r in results:
        print(f"{out / (r.name + '.png')}: {r.symstab}")
    return 0
