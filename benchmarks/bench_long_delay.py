"""Long delays: boundary_curve and limits against a brute-force classified grid (run by hand).

    python benchmarks/bench_long_delay.py [--runs 3] [--delays 10,200,1000] [--columns 4]

For each delay d (gamma = 0.5, delta = 1e-4):

1. ``symstab.boundary_curve(n=64)`` with its default segments, and
   ``symstab.limits`` (the D-decomposition of the paper's loop,
   :meth:`symstab.Loop.limits`): median wall time of ``--runs``.
2. The obvious alternative, side by side in the same run: classify a
   beta x alpha grid with ``symstab.classify`` at the resolution that gives
   alpha_max and the beta range to 1e-3 (1e-3 of alpha_max and of the beta
   range per cell: 1101 x 1101 points over the region's bounding box, padded
   by 5 %).  At d = 10 the whole grid is classified and its limits are
   compared with ours; at larger d only ``--columns`` columns of it (1101
   points each) are timed and the time is scaled to the full grid, since
   classification costs the same per point (it says so in the table).

Prints a table with both times and their ratio (targets: boundary_curve and
limits under 1 s at d = 200 and under 10 s at d = 1000).  Timings on a
shared machine are noisy: read the medians.
"""

import argparse
import os
import statistics
import time

import numpy as np

import symstab
from symstab._resources import chunk_slices

GAMMA, DELTA = 0.5, 1e-4
#: Cells per unit of alpha_max and of the beta range: limits to 1e-3.
CELLS = 1000


def _median_time(function, runs):
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def _grid(lim):
    """The brute-force grid's axes over the padded bounding box of the region."""
    b_lo, b_hi = lim.beta_min, lim.beta_max
    pad_b, pad_a = 0.05 * (b_hi - b_lo), 0.05 * lim.alpha_max
    betas = np.linspace(b_lo - pad_b, b_hi + pad_b, int(1.1 * CELLS) + 1)
    alphas = np.linspace(-pad_a, lim.alpha_max + pad_a, int(1.1 * CELLS) + 1)
    return betas, alphas


def _brute_force(d, lim, columns, rng):
    """(seconds for the full grid, measured or scaled; note; grid limits or None)."""
    betas, alphas = _grid(lim)
    if columns is None:
        start = time.perf_counter()
        B, A = np.meshgrid(betas, alphas)
        stable = np.zeros(A.shape, dtype=bool)
        for part in chunk_slices(len(betas), 8 * len(alphas) * (d + 5) * 4):
            stable[:, part] = np.asarray(symstab.classify(
                alpha=A[:, part], beta=B[:, part], gamma=GAMMA, d=d, delta=DELTA)) == symstab.STABLE
        seconds = time.perf_counter() - start
        if not stable.any():
            return seconds, "full grid", None
        found = (A[stable].max(), B[stable].min(), B[stable].max())
        return seconds, "full grid", found
    pick = rng.choice(len(betas), size=columns, replace=False)
    start = time.perf_counter()
    for k in pick:
        symstab.classify(alpha=alphas, beta=betas[k], gamma=GAMMA, d=d, delta=DELTA)
    seconds = (time.perf_counter() - start) * len(betas) / columns
    return seconds, f"scaled from {columns} columns", None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--delays", default="10,200,1000")
    parser.add_argument("--columns", type=int, default=4)
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    print(f"numpy {np.__version__}, {os.cpu_count()} CPUs; gamma = {GAMMA}, delta = {DELTA}; "
          f"median of {args.runs} runs")
    rows = []
    for d in (int(x) for x in args.delays.split(",")):
        runs = args.runs if d <= 200 else 1
        t_curve, curve = _median_time(lambda d=d: symstab.boundary_curve(
            gamma=GAMMA, d=d, delta=DELTA, n=64), runs)
        t_limits, lim = _median_time(lambda d=d: symstab.limits(gamma=GAMMA, d=d, delta=DELTA),
                                     runs)
        t_grid, note, found = _brute_force(d, lim, None if d <= 10 else args.columns, rng)
        rows.append((d, t_curve, t_limits, t_grid, note))
        print(f"d = {d}: alpha_max {lim.alpha_max:.9g} at beta {lim.beta_at_alpha_max:.6g}, "
              f"beta in [{lim.beta_min:.6g}, {lim.beta_max:.6g}], z_width {lim.z_width:.6g}; "
              f"{len(curve.segments)} segment(s)")
        if found is not None:
            gap = abs(found[0] - lim.alpha_max) / lim.alpha_max
            print(f"        grid: alpha_max {found[0]:.6g} ({gap:.1e} rel.), "
                  f"beta in [{found[1]:.6g}, {found[2]:.6g}]")
    print()
    print(f"{'d':>6} {'boundary_curve':>15} {'limits':>9} {'grid classify':>14} {'ratio':>8}  grid")
    for d, t_curve, t_limits, t_grid, note in rows:
        print(f"{d:>6} {t_curve:>13.3f} s {t_limits:>7.3f} s {t_grid:>12.2f} s "
              f"{t_grid / t_limits:>7.0f}x  {note}")
    print("targets: boundary_curve and limits < 1 s at d = 200, < 10 s at d = 1000")


if __name__ == "__main__":
    main()
