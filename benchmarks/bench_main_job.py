"""Time the main job, `symstab audit` and `symstab reproduce` (run by hand).

    python benchmarks/bench_main_job.py [--runs 3] [--only audit|reproduce] [--no-serial]
                                        [--baseline REV]

Each command runs in a fresh process (no cache carries over), side by side
with its plain serial path in the same session:

* ``symstab audit`` (its checks on two worker processes, shared results
  computed once) against ``run_audit(workers=1)`` in one process, every
  check in report order, as before the pool;
* ``symstab reproduce`` (two workers) against ``symstab reproduce --workers 1``;
* with ``--baseline REV``, also ``symstab audit`` as it was at the git
  revision REV (its ``symstab`` and ``paper_checks`` exported to a temporary
  folder put first on ``PYTHONPATH``): before and after a change, side by side.

The commands take turns, run after run, so that a change in the machine's
load falls on all of them alike.

For each: the median wall time, the median CPU time (user + sys of the
process and every worker it waited for), the ratio serial/parallel, and the
target of issue 10 (audit < 20 s, reproduce < 60 s on two quiet cores).  The
load average is printed with the numbers: on a shared machine the wall times
are noisy, the CPU times much less so.  The audit's two reports and the
committed ``paper_checks/REPORT.md`` are compared byte for byte.
"""

import argparse
import os
import pathlib
import resource
import statistics
import subprocess
import sys
import tempfile
import time

REPO = pathlib.Path(__file__).resolve().parents[1]

TARGETS = {"audit": 20.0, "reproduce": 60.0}

_SERIAL_AUDIT = """
import pathlib, sys
from symstab.paper_checks import audit
pathlib.Path(sys.argv[1]).write_text(audit.render_report(audit.run_audit(workers=1)), encoding="utf-8")
"""


def _timed(argv, cwd, env=None):
    """Run ``argv``; return (wall seconds, CPU seconds of it and its waited-for children)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(argv, cwd=cwd, env=env, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.PIPE)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def _commands(job, folder):
    """``{label: (argv, cwd, env)}``: the parallel and the serial path of ``job``, writing into ``folder``."""
    python = sys.executable
    if job == "audit":
        return {
            "symstab audit (2 workers)": ([python, "-m", "symstab", "audit",
                                           "--report", str(folder / "REPORT.parallel.md")], REPO, None),
            "serial run_audit(workers=1)": ([python, "-c", _SERIAL_AUDIT,
                                             str(folder / "REPORT.serial.md")], REPO, None),
        }
    return {
        "symstab reproduce (2 workers)": ([python, "-m", "symstab", "reproduce",
                                           "--out", str(folder / "parallel")], REPO, None),
        "symstab reproduce --workers 1": ([python, "-m", "symstab", "reproduce", "--workers", "1",
                                           "--out", str(folder / "serial")], REPO, None),
    }


def _baseline_audit(rev, folder):
    """``(label, (argv, cwd, env))`` of ``symstab audit`` at git revision ``rev``."""
    tree = folder / "baseline"
    tree.mkdir()
    archive = subprocess.run(["git", "archive", rev, "symstab", "paper_checks"], cwd=REPO,
                             check=True, capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(tree)], input=archive, check=True)
    env = dict(os.environ, PYTHONPATH=str(tree))
    argv = [sys.executable, "-m", "symstab", "audit", "--report", str(folder / "REPORT.baseline.md")]
    return f"symstab audit at {rev}", (argv, tree, env)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3, help="runs of each command (default 3)")
    parser.add_argument("--only", choices=("audit", "reproduce"), help="time one job only")
    parser.add_argument("--no-serial", action="store_true", help="skip the serial paths")
    parser.add_argument("--baseline", metavar="REV",
                        help="also time symstab audit at this git revision (audit only)")
    args = parser.parse_args()
    if args.runs < 1:
        parser.error("--runs must be >= 1")
    if args.baseline is not None:
        if args.only == "reproduce":
            parser.error("--baseline times the audit only")
        found = subprocess.run(["git", "rev-parse", "--verify", "--quiet", args.baseline + "^{commit}"],
                               cwd=REPO, capture_output=True)
        if found.returncode != 0:
            parser.error(f"--baseline: no such git revision: {args.baseline}")
    jobs = [args.only] if args.only else ["audit", "reproduce"]
    print(f"{os.cpu_count()} cores; load average before: "
          + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    for job in jobs:
        with tempfile.TemporaryDirectory() as tmp:
            folder = pathlib.Path(tmp)
            commands = _commands(job, folder)
            if args.no_serial:
                commands = dict(list(commands.items())[:1])
            if job == "audit" and args.baseline is not None:
                label, command = _baseline_audit(args.baseline, folder)
                commands[label] = command
            times = {label: [] for label in commands}
            for _ in range(args.runs):
                for label, (argv, cwd, env) in commands.items():
                    times[label].append(_timed(argv, cwd, env))
            medians = {}
            for label, runs in times.items():
                wall = statistics.median(r[0] for r in runs)
                cpu = statistics.median(r[1] for r in runs)
                medians[label] = (wall, cpu)
                print(f"{label:34s} wall median {wall:6.1f} s (min {min(r[0] for r in runs):.1f}, "
                      f"max {max(r[0] for r in runs):.1f}), CPU median {cpu:6.1f} s, "
                      f"{args.runs} runs")
            fast_wall, fast_cpu = next(iter(medians.values()))
            print(f"  target {TARGETS[job]:.0f} s: the parallel median is "
                  f"{fast_wall / TARGETS[job]:.2f} of it")
            for label, (slow_wall, slow_cpu) in list(medians.items())[1:]:
                print(f"  {label} / parallel: wall {slow_wall / fast_wall:.2f}x, "
                      f"CPU {slow_cpu / fast_cpu:.2f}x")
            if job == "audit":
                committed = (REPO / "paper_checks" / "REPORT.md").read_bytes()
                for name in ("REPORT.parallel.md", "REPORT.serial.md", "REPORT.baseline.md"):
                    path = folder / name
                    if path.exists():
                        print(f"  {name} {'equals' if path.read_bytes() == committed else 'DIFFERS FROM'}"
                              " paper_checks/REPORT.md")
    print("load average after: " + " ".join(f"{x:.2f}" for x in os.getloadavg()))
    return 0


if __name__ == "__main__":
    sys.exit(main())
