"""Every example loop's ``Loop.region`` here against an earlier revision, side by side (run by hand).

    python benchmarks/bench_regions.py [--against d0d1e0a] [--runs 10] [--delays 0,10,100]

For each loop file in ``examples/loops`` and each delay of ``--delays``
(``d`` set on the file's defaults), ``Loop.region()`` in its default plane
is timed in this checkout and in ``--against`` (default ``d0d1e0a``, main
on the day issue 19 was filed: the target is "every example loop's region
no slower than today"), each in its own Python process with its own empty
kernel cache and one BLAS thread, one warm-up run (the loop's kernels are
generated then) and the median of ``--runs`` of the process's CPU time
(less disturbed by other work on the machine than the wall time).  The earlier revision is checked out with ``git
worktree`` into a temporary folder, removed at the end.  Rows alternate
between the two revisions loop by loop, so a load on the machine hits both.

Printed per row: both medians, their ratio (earlier / here: above 1 is
faster here), and the stable set's number of cells and area from both (the
same decomposition, so the areas agree to the chords of the sampled arc).
Nothing here is a test.
"""

import argparse
import json
import os
import pathlib
import subprocess
import sys
import tempfile

REPO = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
from _timing import fmt  # noqa: E402  (the benchmarks' shared helpers)

#: Run in a fresh process with the checkout to time first on sys.path: the
#: medians of Loop.region() over the runs, and what it found.
_PROBE = r"""
import json, statistics, sys, time
sys.path.insert(0, sys.argv[1])
import symstab
loop = symstab.load_loop(sys.argv[2])
d, runs = int(sys.argv[3]), int(sys.argv[4])
found = loop.region(d=d)
times = []
for _ in range(runs):
    start = time.process_time()
    found = loop.region(d=d)
    times.append(time.process_time() - start)
print(json.dumps({"time": statistics.median(times), "cells": len(found.stable),
                  "area": float(found.area)}))
"""


def _probe(root, path, d, runs):
    with tempfile.TemporaryDirectory() as cache:
        env = dict(os.environ, SYMSTAB_CACHE_DIR=cache, OPENBLAS_NUM_THREADS="1")
        done = subprocess.run([sys.executable, "-c", _PROBE, str(root), str(path), str(d),
                               str(runs)], capture_output=True, text=True, env=env, cwd=root)
    if done.returncode:
        return {"error": (done.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--against", default="d0d1e0a", help="the earlier revision (default d0d1e0a)")
    parser.add_argument("--runs", type=int, default=10)
    parser.add_argument("--delays", default="0,10,100")
    args = parser.parse_args(argv)
    delays = [int(v) for v in args.delays.split(",")]
    loops = sorted((REPO / "examples" / "loops").glob("*.toml"))
    print(f"load average at start: {os.getloadavg()[0]:.2f}")
    with tempfile.TemporaryDirectory() as scratch:
        earlier = pathlib.Path(scratch) / "earlier"
        subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", "-q", str(earlier),
                        args.against], check=True)
        try:
            print(f"{'loop':<22} {'d':>4} {'here':>9} {args.against:>9} {'ratio':>6}  "
                  f"cells here/earlier  area here, earlier")
            for path in loops:
                for d in delays:
                    here = _probe(REPO, path, d, args.runs)
                    then = _probe(earlier, earlier / "examples" / "loops" / path.name, d, args.runs)
                    if "error" in here or "error" in then:
                        print(f"{path.stem:<22} {d:>4}  here: {here.get('error', 'ok')}; "
                              f"earlier: {then.get('error', 'ok')}")
                        continue
                    print(f"{path.stem:<22} {d:>4} {fmt(here['time']):>9} {fmt(then['time']):>9} "
                          f"{then['time'] / here['time']:>6.2f}  {here['cells']}/{then['cells']}"
                          f"{'':>14}{here['area']:.6g}, {then['area']:.6g}")
        finally:
            subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(earlier)],
                           check=False)
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
