"""A fractional loop delay against the whole one: the paper's region, limits and classify (run by hand).

    python benchmarks/bench_fractional_region.py [--runs 7] [--delays 10,100,1000] [--fraction 0.5]

For each delay ``d`` of ``--delays``, :data:`symstab.PAPER_LOOP` in its
``(B, K)`` plane at the loop's other defaults, side by side in one process:

* ``Loop.region("B", "K")`` and ``Loop.limits("B", "K")`` at ``d`` and at
  ``d + fraction`` (issue 43: a fractional delay costs at most 1.5 times the
  whole one);
* ``Loop.classify`` at the default point (K = 2, B = 0.1), one call, and on
  a 100 x 100 grid over the stable set's bounding box (one call).

One warm-up of each (the loop's kernels and the fraction's plant are made
then), then ``--runs`` rounds, each timing the whole and the fractional
delay one after the other, so that a load on the machine hits both; the
medians of the process's CPU time (less disturbed by other work than the
wall time).  d = 1000 is within the default ``SYMSTAB_MAX_DELAY`` (10 000).
The default run takes about 6 minutes, most of it the grid's classify at
d = 1000 (16 s a call).  Nothing here is a test.

Measured 2026-12-07 (2 CPUs, load average 4 from other work; CPU-time
medians of 5 runs), fractional / whole: region 0.94, 0.96, 1.11 and limits
0.86, 0.93, 1.18 at d = 10, 100, 1000; classify one point 1.06, 0.92, 1.11,
10 000 points 1.19, 1.03, 1.08.  Worst 1.19, within the accepted 1.5.
"""

import argparse
import os
import pathlib
import statistics
import sys
import time

import numpy as np

import symstab

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from _timing import fmt  # noqa: E402  (the benchmarks' shared helpers)

#: A fractional delay may cost this many times the whole one (issue 43).
ACCEPTED_RATIO = 1.5
#: Calls of a single-point classify per timed run (one is tens of microseconds).
POINT_CALLS = 20


def _cpu(function):
    start = time.process_time()
    function()
    return time.process_time() - start


def _questions(loop, grid):
    """``{name: function of the delay}``: the questions timed at each delay."""
    B, K = grid

    def point(d):
        for _ in range(POINT_CALLS):
            loop.classify(d=d)

    return {
        "region": lambda d: loop.region("B", "K", d=d),
        "limits": lambda d: loop.limits("B", "K", d=d),
        f"classify x{POINT_CALLS}": point,
        f"classify {B.size} pts": lambda d: loop.classify(B=B, K=K, d=d),
    }


def _grid(limits):
    """A 100 x 100 grid over the stable set's bounding box (padded by 10 %)."""
    pad_x, pad_y = 0.1 * (limits.x_max - limits.x_min), 0.1 * limits.y_max
    return np.meshgrid(np.linspace(limits.x_min - pad_x, limits.x_max + pad_x, 100),
                       np.linspace(-pad_y, limits.y_max + pad_y, 100))


def _time_delay(loop, d, fraction, runs):
    """``[(question, whole median, fractional median)]`` and the limits at both delays."""
    found = {delay: loop.limits("B", "K", d=delay) for delay in (d, d + fraction)}
    questions = _questions(loop, _grid(found[d]))
    rows = []
    for name, question in questions.items():
        times = {d: [], d + fraction: []}
        for delay in times:
            question(delay)     # warm-up
        for _ in range(runs):
            for delay in times:
                times[delay].append(_cpu(lambda q=question, x=delay: q(x)))
        rows.append((name, statistics.median(times[d]), statistics.median(times[d + fraction])))
    return rows, found


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--delays", default="10,100,1000")
    parser.add_argument("--fraction", type=float, default=0.5)
    args = parser.parse_args(argv)
    loop = symstab.PAPER_LOOP
    print(f"numpy {np.__version__}, {os.cpu_count()} CPUs, load average "
          f"{os.getloadavg()[0]:.2f}; PAPER_LOOP (B, K); median CPU time of {args.runs} runs")
    print(f"{'d':>6} {'question':<18} {'whole':>10} {'+' + str(args.fraction):>10} "
          f"{'ratio':>6}  (accepted <= {ACCEPTED_RATIO})")
    worst = 0.0
    for d in (int(v) for v in args.delays.split(",")):
        rows, found = _time_delay(loop, d, args.fraction, args.runs)
        for name, whole, fractional in rows:
            ratio = fractional / whole
            worst = max(worst, ratio)
            flag = "" if ratio <= ACCEPTED_RATIO else "  SLOW"
            print(f"{d:>6} {name:<18} {fmt(whole):>10} {fmt(fractional):>10} {ratio:>6.2f}{flag}")
        for delay, limits in found.items():
            print(f"{'':>6} K_max {limits.y_max:.6g} at B = {limits.x_at_y_max:.6g}, "
                  f"B in [{limits.x_min:.6g}, {limits.x_max:.6g}] at d = {delay}")
    print(f"worst ratio {worst:.2f} (accepted <= {ACCEPTED_RATIO})")


if __name__ == "__main__":
    main()
