"""The exact delay margin against a scan of the delay (run by hand).

    python benchmarks/bench_delay_margin.py [--runs 7]

At the paper's point of its Fig. 6 (``symstab.PAPER_LOOP``, K = 2 N m/rad,
B = 0.1 N m s/rad) at d = 10, 20 and 40, side by side in one process:

* ``Loop.delay_margin(d=d)``: the certified verdicts on a grid of 1/16
  sample, the first change refined by the root bracketer;
* the obvious alternative: ``Loop.spectral_radius`` on a grid of 1/64 sample
  of the delay until it reaches 1, then bisection to 1e-10 of a sample (what
  a user without the certified count would write).

One warm-up of each (the fractions' plants are derived then: that cost is
paid once per loop and fraction, and is shown apart as the first call's),
then ``--runs`` rounds; medians of the wall time, and the ratio.  Issue 43
asks for a delay margin under 100 ms at d = 40.  Nothing here is a test.

Measured 2026-12-07 (2 CPUs, a quiet machine; medians of 5): delay_margin
64.5, 56.5 and 73.6 ms at d = 10, 20 and 40 (the first call, with the
fractions' plants, 202, 73 and 46 ms: the plants are shared by the three),
the scan 5.11, 3.73 and 2.40 s: 79, 66 and 33 times faster, the same
margins (46.6157437, 36.6157437, 16.6157437 samples) to the 9 digits shown.
"""

import argparse
import math
import pathlib
import statistics
import sys
import time

import symstab

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from _timing import fmt  # noqa: E402  (the benchmarks' shared helpers)

POINT = dict(K=2.0, B=0.1, M=0.0)


def _scan(loop, d, step=1 / 64):
    """The first delay above ``d`` where the spectral radius reaches 1: a scan, then bisection."""
    low = float(d)
    while float(loop.spectral_radius(**POINT, d=low + step)) < 1:
        low += step
    high = low + step
    while high - low > 1e-10:
        middle = (low + high) / 2
        low, high = (middle, high) if float(loop.spectral_radius(**POINT, d=middle)) < 1 else (
            low, middle)
    return (low + high) / 2 - d


def _timed(function):
    start = time.perf_counter()
    value = function()
    return time.perf_counter() - start, value


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    args = parser.parse_args(argv)
    loop = symstab.PAPER_LOOP
    print(f"{'d':>5}  {'first call':>10}  {'delay_margin':>12}  {'scan 1/64':>10}  {'ratio':>6}  "
          f"{'margin':>12}  {'scan margin':>12}")
    for d in (10, 20, 40):
        first, _ = _timed(lambda d=d: loop.delay_margin(**POINT, d=d))
        _timed(lambda d=d: _scan(loop, d))
        ours, theirs = [], []
        for _ in range(args.runs):
            t, found = _timed(lambda d=d: loop.delay_margin(**POINT, d=d))
            ours.append(t)
            t, scanned = _timed(lambda d=d: _scan(loop, d))
            theirs.append(t)
        a, b = statistics.median(ours), statistics.median(theirs)
        margin = math.nan if found.margin is None else found.margin
        print(f"{d:>5}  {fmt(first):>10}  {fmt(a):>12}  {fmt(b):>10}  {b / a:>6.1f}  "
              f"{margin:>12.9g}  {scanned:>12.9g}")


if __name__ == "__main__":
    main()
